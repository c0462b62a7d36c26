#version 450
// Unlit: the model's colouring is the projection content. Texture texels are sampled from a UNORM
// image and written to a UNORM target, so stored values reach the projector unchanged.

layout(location = 0) in vec2 in_uv;
layout(location = 1) in vec4 in_color;

layout(set = 0, binding = 0) uniform sampler2D base_color_texture;

layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  float alpha_cutoff;
  int alpha_mode;
} draw;

layout(location = 0) out vec4 out_color;

void main() {
  vec4 c = texture(base_color_texture, in_uv) * draw.base_color_factor * in_color;
  if (draw.alpha_mode == 1) {
    if (c.a < draw.alpha_cutoff) discard;
    c.a = 1.0;
  } else if (draw.alpha_mode == 0) {
    c.a = 1.0;
  }
  out_color = c;
}
