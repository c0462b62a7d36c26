#version 450
// Unlit: the model's colouring (its emission added) is the projection content. Texture texels are sampled
// from a UNORM image and written to a UNORM target, so stored values reach the projector unchanged; with compensation
// (issue 43) the output is what makes the target's surface show them (engine/photometry.hpp, whose
// compensated_input is this pass on the CPU).

layout(location = 0) in vec2 in_uv;
layout(location = 1) in vec4 in_color;
layout(location = 2) in vec3 in_q;
layout(location = 0, component = 2) in vec2 in_base_uv;  // the base colour texture's placement of in_uv (mesh.vert)
layout(location = 3) in vec2 in_emissive_uv;  // the emissive texture's

layout(set = 0, binding = 0) uniform sampler2D base_color_texture;
// The target's physical surface over the same UVs (Renderer::set_surface): linear reflectance, which
// compensation divides by besides compensate.rgb's per-channel albedo; white unless the scene gives one.
layout(set = 0, binding = 1) uniform sampler2D surface_texture;

// The material's emission (white where it has no emissive texture; its factor is 0 where it emits nothing).
layout(set = 0, binding = 2) uniform sampler2D emissive_texture;

// The projector's response, per frame (renderer.cpp's FrameUniform).
layout(set = 1, binding = 0) uniform Frame {
  vec4 unmix[3];  // rows of the mixing matrix's inverse: the channels' drives from the light wanted in R, G, B
  vec4 response;  // xyz: 1 / each channel's gamma; w: the black level
} frame;

// This draw's material as it is now (renderer_impl.hpp's DrawUniform, issue 44): its emission here, its
// textures' placements in mesh.vert.
layout(set = 1, binding = 1) uniform Material {
  vec4 emissive;  // rgb: emissive factor x strength, added as stored
  vec4 base_uv[2];
  vec4 emissive_uv[2];
} material;

// glTF alphaMode, fixed per pipeline so OPAQUE and BLEND carry no discard (which would stop early depth
// testing) and no per-fragment branch: 0 opaque, 1 mask, 2 blend.
layout(constant_id = 0) const int kAlphaMode = 0;
// renderer_impl.hpp's Shading: the textures placed other than over in_uv as it is (mesh.vert), an emission.
layout(constant_id = 1) const bool kPlaced = false;
layout(constant_id = 2) const bool kEmissive = false;

layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  vec4 compensate;  // rgb: the lux content 1 needs (k kReferenceLux / albedo; 0: off); a: the room's lux
  vec4 projector;   // x: full white's lux at 1 m facing the lens, w: MASK alpha cutoff
  vec4 ray;         // see mesh.vert
} draw;

layout(location = 0) out vec4 out_color;

vec3 srgb_to_linear(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
}

// Full white's lux here, from the triangle's own normal (its incidence) and the distance. Taken before
// MASK's discard, under a branch on a push constant: derivatives stay in uniform control flow.
float white_lux() {
  vec3 n = cross(dFdx(in_q), dFdy(in_q));
  float nn = length(n);
  float z = in_q.z;
  return (nn > 0.0 && z > 0.0) ? draw.projector.x * abs(dot(in_q, n)) / (nn * z * z * z) : 0.0;
}

// The input that adds what the surface lacks: the lux needed less the room's, as a share of full white
// here, unmixed into the channels' drives, through the inverse response.
vec3 compensated(vec3 c, float white) {
  vec3 rho = max(textureLod(surface_texture, in_uv, 0.0).rgb, vec3(1e-3));  // no mipmaps: no derivatives needed
  vec3 needed = draw.compensate.rgb * srgb_to_linear(c) / rho - draw.compensate.a;
  vec3 light = white > 0.0 ? needed / white : mix(vec3(0.0), vec3(2.0), greaterThan(needed, vec3(0.0)));
  vec3 d = vec3(dot(frame.unmix[0].xyz, light), dot(frame.unmix[1].xyz, light), dot(frame.unmix[2].xyz, light));
  float black = frame.response.w;
  vec3 x = (d - black) / (1.0 - black);
  return pow(clamp(x, 0.0, 1.0), frame.response.xyz);
}

void main() {
  float white = draw.compensate.r > 0.0 ? white_lux() : 0.0;
  vec4 c = texture(base_color_texture, kPlaced ? in_base_uv : in_uv) * draw.base_color_factor * in_color;
  if (kEmissive) c.rgb += material.emissive.rgb * texture(emissive_texture, kPlaced ? in_emissive_uv : in_uv).rgb;
  if (kAlphaMode == 1) {
    if (c.a < draw.projector.w) discard;
    c.a = 1.0;
  } else if (kAlphaMode == 0) {
    c.a = 1.0;
  }
  if (draw.compensate.r > 0.0) c.rgb = compensated(c.rgb, white);
  out_color = c;
}
