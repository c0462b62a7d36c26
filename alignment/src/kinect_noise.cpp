#include "projbot/alignment/kinect_noise.hpp"

#include <cmath>
#include <random>
#include <vector>

namespace projbot::alignment {
namespace {

// Standard normal samples, drawn once: a frame then costs a table lookup per pixel instead of a
// std::normal_distribution draw (the noise model was 25 ms of a 30 ms simulated capture).
const std::vector<float>& gaussian_table() {
  static const std::vector<float> table = [] {
    std::vector<float> t(1 << 16);
    std::mt19937 rng(20121);
    std::normal_distribution<float> gauss(0.0F, 1.0F);
    for (auto& v : t) v = gauss(rng);
    return t;
  }();
  return table;
}

// xorshift64*: a fast, seedable index stream into the table.
struct XorShift {
  std::uint64_t state;
  explicit XorShift(std::uint32_t seed) : state(0x9E3779B97F4A7C15ULL ^ (std::uint64_t{seed} * 0xBF58476D1CE4E5B9ULL)) {
    if (state == 0) state = 1;
  }
  std::uint32_t next() {
    state ^= state >> 12;
    state ^= state << 25;
    state ^= state >> 27;
    return static_cast<std::uint32_t>((state * 0x2545F4914F6CDD1DULL) >> 32);
  }
};

}  // namespace

DepthImage apply_kinect_v1_noise(const DepthImage& clean, const CameraIntrinsics& k, const KinectNoiseConfig& cfg,
                                 std::uint32_t seed) {
  if (clean.width != k.width_px || clean.height != k.height_px)
    throw AlignmentError("noise model: depth image and intrinsics differ in size");
  DepthImage out = clean;
  const int w = clean.width, h = clean.height;
  const float* zin = clean.depth_m.data();
  const float ifx = static_cast<float>(1.0 / k.fx_px), ify = static_cast<float>(1.0 / k.fy_px);
  const float cx = static_cast<float>(k.cx_px), cy = static_cast<float>(k.cy_px);
  const auto point = [&](int x, int y, float z) {
    return Eigen::Vector3f((static_cast<float>(x) - cx) * z * ifx, (static_cast<float>(y) - cy) * z * ify, z);
  };
  const double cos_max = std::cos(cfg.max_incidence_deg * M_PI / 180.0);
  const float cos2_max = static_cast<float>(cos_max * cos_max);
  const std::vector<float>& gauss = gaussian_table();
  XorShift rng(seed);
  const float bf = static_cast<float>(cfg.baseline_m * cfg.disparity_focal_px);
  const bool quantise = cfg.disparity_step_px > 0.0;
  const float step = static_cast<float>(cfg.disparity_step_px), inv_step = quantise ? 1.0F / step : 0.0F;
  const float sigma_coeff = static_cast<float>(cfg.sigma_z_coeff);
  const bool border_drops = cfg.edge_jump_m < 1e8;
  const float edge_jump = static_cast<float>(cfg.edge_jump_m);
  const float min_range = static_cast<float>(cfg.min_range_m), max_range = static_cast<float>(cfg.max_range_m);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      float& z_out = out.depth_m[i];
      const float zf = zin[i];
      if (!has_depth(zf)) {
        z_out = 0.0F;
        continue;
      }
      bool drop = zf < min_range || zf > max_range;
      // Discontinuities and the image border: the Kinect's pattern is shadowed or ambiguous there.
      const bool inside = x > 0 && y > 0 && x + 1 < w && y + 1 < h;
      const float zr = x + 1 < w ? zin[i + 1] : 0.0F, zl = x > 0 ? zin[i - 1] : 0.0F;
      const float zd = y + 1 < h ? zin[i + static_cast<std::size_t>(w)] : 0.0F,
                  zu = y > 0 ? zin[i - static_cast<std::size_t>(w)] : 0.0F;
      const bool all_valid = inside && has_depth(zr) && has_depth(zl) && has_depth(zd) && has_depth(zu);
      if (!drop) {
        if (!all_valid) {
          drop = border_drops;
        } else {
          const float jump = edge_jump + 0.02F * zf;
          drop = std::abs(zr - zf) > jump || std::abs(zl - zf) > jump || std::abs(zd - zf) > jump || std::abs(zu - zf) > jump;
        }
      }
      // Grazing angles: the surface normal from the neighbours against the viewing ray (squared, no roots).
      if (!drop && cos_max > 0.0 && all_valid) {
        const Eigen::Vector3f n = (point(x + 1, y, zr) - point(x - 1, y, zl)).cross(point(x, y + 1, zd) - point(x, y - 1, zu));
        const Eigen::Vector3f ray = point(x, y, zf);
        const float along = n.dot(ray);
        drop = along * along < cos2_max * n.squaredNorm() * ray.squaredNorm();
      }
      if (drop) {
        z_out = 0.0F;
        continue;
      }
      float noisy = zf + sigma_coeff * zf * zf * gauss[rng.next() & 0xFFFFU];
      if (quantise && noisy > 0.0F) {  // to the disparity steps: d = bf / z, rounded to 1/8 px
        const float d = std::nearbyint(bf / noisy * inv_step) * step;
        noisy = d > 0.0F ? bf / d : 0.0F;
      }
      z_out = noisy;
    }
  return out;
}

}  // namespace projbot::alignment
