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

layout(location = 0) out vec2 out_uv;
layout(location = 1) out vec4 out_color;
layout(location = 2) out vec3 out_q;  // projector frame, metres: linear in clip, so interpolated exactly

void main() {
  vec4 clip = draw.clip_from_model * vec4(in_position, 1.0);
  gl_Position = clip;
  out_uv = in_uv;
  out_color = in_color;
  out_q = vec3(clip.x * draw.ray.x + clip.w * draw.ray.y, clip.y * draw.ray.z + clip.w * draw.ray.w, clip.w);
}
