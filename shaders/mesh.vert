#version 450
// The projector pass (Eq. 3): clip_from_model = P(A_p) * T_projector_target, computed on the host in
// double precision. Unlit: only texture coordinates and vertex colours travel to the fragment stage.

layout(location = 0) in vec3 in_position;  // model frame, metres
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec4 in_color;     // UNORM8 in the vertex buffer

layout(push_constant) uniform Draw {
  mat4 clip_from_model;
  vec4 base_color_factor;
  float alpha_cutoff;  // MASK cutoff, used by the fragment stage
} draw;

layout(location = 0) out vec2 out_uv;
layout(location = 1) out vec4 out_color;

void main() {
  gl_Position = draw.clip_from_model * vec4(in_position, 1.0);
  out_uv = in_uv;
  out_color = in_color;
}
