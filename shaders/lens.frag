#version 450
// The lens pass (issue 13): each panel pixel shows the undistorted canvas at the ray its light leaves
// along, so that content drawn for a ray lands on that ray after the projector's lens. The rays are the
// lens undone once per target and lens on the host (engine::lens_warp: OpenCV's k1, k2, p1, p2, k3 by
// Newton's method, as config::undistort does); solved here per pixel and frame it cost 24 ms a frame.

layout(set = 0, binding = 0) uniform sampler2D canvas;
layout(set = 0, binding = 1) uniform sampler2D warp;  // canvas position per target pixel; negative: no ray

layout(location = 0) out vec4 out_color;

void main() {
  const vec2 uv = texelFetch(warp, ivec2(gl_FragCoord.xy), 0).xy;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || any(isnan(uv)))
    out_color = vec4(0.0, 0.0, 0.0, 1.0);
  else
    out_color = texture(canvas, uv);
}
