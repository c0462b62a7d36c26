#version 450
// The projector pass (Eq. 3): clip_from_model = P(A_p) * T_projector_target, computed on the host in
// double precision. Unlit: texture coordinates and vertex colours travel to the fragment stage, and the
// projector-frame position for compensation (issue 43).

layout(location = 0) in vec3 in_position;  // model frame, metres
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec4 in_color;     // UNORM8 in the vertex buffer

// The same block as mesh.frag's (128 bytes, Vulkan's guaranteed push-constant size).
layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  vec4 compensate;  // rgb: the lux content 1 needs (0: off); a: the room's lux
  vec4 projector;   // x: full white's lux at 1 m, w: MASK alpha cutoff
  vec4 ray;         // projector-frame x = clip.x ray.x + clip.w ray.y, y = clip.y ray.z + clip.w ray.w, z = clip.w
} draw;

// The draw's material (renderer_impl.hpp's DrawUniform, issue 44): where its base colour and emissive
// textures lie over the model's texture coordinates, rows of 2x3 matrices. Affine, so placed here per
// vertex it interpolates as placed per fragment (placed per fragment, lavapipe drew the 100k-triangle
// sphere's 1080p frame in 35 ms instead of 28); only where kPlaced (renderer_impl.hpp's Shading).
layout(set = 1, binding = 1) uniform Material {
  vec4 emissive;
  vec4 base_uv[2];
  vec4 emissive_uv[2];
} material;

layout(constant_id = 1) const bool kPlaced = false;

layout(location = 0) out vec2 out_uv;
layout(location = 1) out vec4 out_color;
layout(location = 2) out vec3 out_q;  // projector frame, metres: linear in clip, so interpolated exactly
layout(location = 0, component = 2) out vec2 out_base_uv;  // beside out_uv: one slot fewer to interpolate
layout(location = 3) out vec2 out_emissive_uv;

vec2 placed(vec4 rows[2]) {
  vec3 uv1 = vec3(in_uv, 1.0);
  return vec2(dot(rows[0].xyz, uv1), dot(rows[1].xyz, uv1));
}

void main() {
  vec4 clip = draw.clip_from_model * vec4(in_position, 1.0);
  gl_Position = clip;
  out_uv = in_uv;
  out_base_uv = kPlaced ? placed(material.base_uv) : in_uv;
  out_emissive_uv = kPlaced ? placed(material.emissive_uv) : in_uv;
  out_color = in_color;
  out_q = vec3(clip.x * draw.ray.x + clip.w * draw.ray.y, clip.y * draw.ray.z + clip.w * draw.ray.w, clip.w);
}
