#version 450
// The lens pass (issue 13): each panel pixel shows the undistorted canvas at the ray its light leaves
// along, so that content drawn for a ray lands on that ray after the projector's lens. The ray is the
// lens undone by Newton's method on OpenCV's model (k1, k2, p1, p2, k3), as config::undistort does.

layout(set = 0, binding = 0) uniform sampler2D canvas;

layout(push_constant) uniform Lens {
  vec4 intrinsics;  // fx, fy, cx, cy of the panel, projector pixels
  vec4 k;           // k1, k2, p1, p2
  vec4 k3_scale;    // k3, projector pixels per target pixel in x and y, unused
  vec4 place;       // canvas margins left and top (projector pixels), 1 / canvas width, 1 / canvas height
} lens;

layout(location = 0) out vec4 out_color;

vec2 distort(vec2 x, out mat2 jacobian) {
  const float k1 = lens.k.x, k2 = lens.k.y, p1 = lens.k.z, p2 = lens.k.w, k3 = lens.k3_scale.x;
  const float r2 = dot(x, x);
  const float radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const float g = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
  const float cross = 2.0 * x.x * x.y * g + 2.0 * p1 * x.x + 2.0 * p2 * x.y;
  // GLSL matrices are column-major: mat2(col0, col1).
  jacobian = mat2(radial + 2.0 * x.x * x.x * g + 2.0 * p1 * x.y + 6.0 * p2 * x.x, cross,
                  cross, radial + 2.0 * x.y * x.y * g + 6.0 * p1 * x.y + 2.0 * p2 * x.x);
  return vec2(x.x * radial + 2.0 * p1 * x.x * x.y + p2 * (r2 + 2.0 * x.x * x.x),
              x.y * radial + p1 * (r2 + 2.0 * x.y * x.y) + 2.0 * p2 * x.x * x.y);
}

void main() {
  // The panel position of this pixel's centre (pixel centres at integers, the projector stretched onto the target).
  const vec2 panel = gl_FragCoord.xy * lens.k3_scale.yz - 0.5;
  const vec2 d = (panel - lens.intrinsics.zw) / lens.intrinsics.xy;
  vec2 x = d;
  for (int i = 0; i < 8; ++i) {
    mat2 J;
    const vec2 r = distort(x, J) - d;
    x -= inverse(J) * r;
  }
  const vec2 ideal = x * lens.intrinsics.xy + lens.intrinsics.zw;
  const vec2 uv = (ideal + lens.place.xy + 0.5) * lens.place.zw;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || any(isnan(uv)))
    out_color = vec4(0.0, 0.0, 0.0, 1.0);
  else
    out_color = texture(canvas, uv);
}
