#version 450
// Unlit: the model's colouring is the projection content. Texture texels are sampled from a UNORM
// image and written to a UNORM target, so stored values reach the projector unchanged.

layout(location = 0) in vec2 in_uv;
layout(location = 1) in vec4 in_color;

layout(set = 0, binding = 0) uniform sampler2D base_color_texture;

// glTF alphaMode, fixed per pipeline so OPAQUE and BLEND carry no discard (which would stop early depth
// testing) and no per-fragment branch: 0 opaque, 1 mask, 2 blend.
layout(constant_id = 0) const int kAlphaMode = 0;

layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  float alpha_cutoff;  // kAlphaMode 1 only
} draw;

layout(location = 0) out vec4 out_color;

void main() {
  vec4 c = texture(base_color_texture, in_uv) * draw.base_color_factor * in_color;
  if (kAlphaMode == 1) {
    if (c.a < draw.alpha_cutoff) discard;
    c.a = 1.0;
  } else if (kAlphaMode == 0) {
    c.a = 1.0;
  }
  out_color = c;
}
