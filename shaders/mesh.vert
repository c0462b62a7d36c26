#version 450
// The projector pass (Eq. 3): clip_from_model = P(A_p) * T_projector_target, computed on the host in
// double precision. Unlit: only texture coordinates and vertex colours travel to the fragment stage.

layout(location = 0) in vec3 in_position;  // model frame, metres
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_color;

layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  float alpha_cutoff;  // < 0: opaque (alpha forced to 1); >= 0: MASK cutoff; BLEND passes -2
  int alpha_mode;      // 0 opaque, 1 mask, 2 blend
} draw;

layout(location = 0) out vec2 out_uv;
layout(location = 1) out vec4 out_color;

void main() {
  gl_Position = draw.clip_from_model * vec4(in_position, 1.0);
  out_uv = in_uv;
  out_color = in_color;
}
