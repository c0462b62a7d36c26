#include "projbot/alignment/kinect_noise.hpp"

#include <cmath>
#include <random>

namespace projbot::alignment {

DepthImage apply_kinect_v1_noise(const DepthImage& clean, const CameraIntrinsics& k, const KinectNoiseConfig& cfg,
                                 std::uint32_t seed) {
  if (clean.width != k.width_px || clean.height != k.height_px)
    throw AlignmentError("noise model: depth image and intrinsics differ in size");
  DepthImage out = clean;
  const int w = clean.width, h = clean.height;
  const auto valid = [&](int x, int y) {
    const float z = clean.at(x, y);
    return z > 0.0F && std::isfinite(z);
  };
  const auto point = [&](int x, int y) {
    const double z = clean.at(x, y);
    return Eigen::Vector3d((x - k.cx_px) * z / k.fx_px, (y - k.cy_px) * z / k.fy_px, z);
  };
  const double cos_max = std::cos(cfg.max_incidence_deg * M_PI / 180.0);
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double bf = cfg.baseline_m * cfg.disparity_focal_px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float& z_out = out.depth_m[static_cast<std::size_t>(y) * w + x];
      if (!valid(x, y)) {
        z_out = 0.0F;
        continue;
      }
      const double z = clean.at(x, y);
      bool drop = z < cfg.min_range_m || z > cfg.max_range_m;
      // Discontinuities and the image border: the Kinect's pattern is shadowed or ambiguous there.
      for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
        const int nx = x + dx, ny = y + dy;
        if (drop) break;
        if (nx < 0 || ny < 0 || nx >= w || ny >= h || !valid(nx, ny)) {
          drop = cfg.edge_jump_m < 1e8;
          continue;
        }
        drop = std::abs(clean.at(nx, ny) - z) > cfg.edge_jump_m + 0.02 * z;
      }
      // Grazing angles: the surface normal from the neighbours against the viewing ray.
      if (!drop && cos_max > 0.0 && x > 0 && y > 0 && x + 1 < w && y + 1 < h && valid(x + 1, y) && valid(x - 1, y) &&
          valid(x, y + 1) && valid(x, y - 1)) {
        const Eigen::Vector3d n = (point(x + 1, y) - point(x - 1, y)).cross(point(x, y + 1) - point(x, y - 1));
        const Eigen::Vector3d ray = point(x, y);
        if (n.norm() > 0.0) drop = std::abs(n.dot(ray)) / (n.norm() * ray.norm()) < cos_max;
      }
      if (drop) {
        z_out = 0.0F;
        continue;
      }
      double noisy = z + cfg.sigma_z_coeff * z * z * gauss(rng);
      if (cfg.disparity_step_px > 0.0 && noisy > 0.0) {
        const double d = std::round(bf / noisy / cfg.disparity_step_px) * cfg.disparity_step_px;
        noisy = d > 0.0 ? bf / d : 0.0;
      }
      z_out = static_cast<float>(noisy);
    }
  return out;
}

}  // namespace projbot::alignment
