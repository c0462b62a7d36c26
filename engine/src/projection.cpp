#include "projbot/engine/projection.hpp"

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

std::array<float, 16> to_gpu_matrix(const Eigen::Matrix4d& m) {
  std::array<float, 16> out{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[static_cast<std::size_t>(c * 4 + r)] = static_cast<float>(m(r, c));  // GLSL: column-major
  return out;
}

}  // namespace projbot::engine
