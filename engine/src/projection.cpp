#include "projbot/engine/projection.hpp"

#include <algorithm>
#include <cmath>

namespace projbot::engine {

Eigen::Matrix4d clip_from_projector(const config::ProjectorConfig& p) {
  const double w = p.width_px, h = p.height_px, n = p.near_m, f = p.far_m;
  // x_ndc = 2 (u + 0.5) / W - 1 with u = fx X/Z + cx, so that the viewport puts u = i at the centre
  // i + 0.5 of pixel i; likewise y (Vulkan's y points down, like OpenCV's v). z_ndc: near 0, far 1.
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m(0, 0) = 2.0 * p.fx_px / w;
  m(0, 2) = 2.0 * (p.cx_px + 0.5) / w - 1.0;
  m(1, 1) = 2.0 * p.fy_px / h;
  m(1, 2) = 2.0 * (p.cy_px + 0.5) / h - 1.0;
  m(2, 2) = f / (f - n);
  m(2, 3) = -f * n / (f - n);
  m(3, 2) = 1.0;
  return m;
}

LensCanvas lens_canvas(const config::ProjectorConfig& p) {
  // The rays of the panel's edges (its outermost pixel edges, -0.5 and size - 0.5), as pinhole pixels.
  double u0 = 0.0, v0 = 0.0, u1 = p.width_px - 1.0, v1 = p.height_px - 1.0;
  constexpr int kSteps = 256;
  for (int i = 0; i <= kSteps; ++i) {
    const double s = static_cast<double>(i) / kSteps;
    const double us[] = {-0.5 + s * p.width_px, -0.5, p.width_px - 0.5};
    const double vs[] = {-0.5 + s * p.height_px, -0.5, p.height_px - 0.5};
    const std::pair<double, double> edges[] = {{us[0], vs[1]}, {us[0], vs[2]}, {us[1], vs[0]}, {us[2], vs[0]}};
    for (const auto& [u, v] : edges) {
      const auto ray = p.panel_ray(u, v);
      if (!ray) continue;  // validate_projector refuses such lenses; the canvas then only holds the panel
      const Eigen::Vector2d image = p.project(*ray);
      u0 = std::min(u0, image.x()), u1 = std::max(u1, image.x()), v0 = std::min(v0, image.y()), v1 = std::max(v1, image.y());
    }
  }
  LensCanvas c;
  c.left_px = static_cast<int>(std::ceil(-u0)) + 1;  // a pixel more: bilinear sampling reads the neighbour
  c.top_px = static_cast<int>(std::ceil(-v0)) + 1;
  c.pinhole = p;
  c.pinhole.distortion = {};
  c.pinhole.width_px = c.left_px + static_cast<int>(std::ceil(u1)) + 2;
  c.pinhole.height_px = c.top_px + static_cast<int>(std::ceil(v1)) + 2;
  c.pinhole.cx_px = p.cx_px + c.left_px;
  c.pinhole.cy_px = p.cy_px + c.top_px;
  return c;
}

std::vector<float> lens_warp(const config::ProjectorConfig& p, const LensCanvas& c, int width, int height) {
  std::vector<float> uv(2 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1.0F);
  const double sx = static_cast<double>(p.width_px) / width, sy = static_cast<double>(p.height_px) / height;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      // The panel position of the target pixel's centre (pixel centres at integers).
      const auto ray = p.panel_ray((x + 0.5) * sx - 0.5, (y + 0.5) * sy - 0.5);
      if (!ray) continue;
      const std::size_t i = 2 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
      const Eigen::Vector2d image = p.project(*ray);
      uv[i] = static_cast<float>((image.x() + c.left_px + 0.5) / c.pinhole.width_px);
      uv[i + 1] = static_cast<float>((image.y() + c.top_px + 0.5) / c.pinhole.height_px);
    }
  return uv;
}

std::array<float, 16> to_gpu_matrix(const Eigen::Matrix4d& m) {
  std::array<float, 16> out{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[static_cast<std::size_t>(c * 4 + r)] = static_cast<float>(m(r, c));  // GLSL: column-major
  return out;
}

}  // namespace projbot::engine
