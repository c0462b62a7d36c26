#include "projbot/alignment/kinect_noise.hpp"

#include <Eigen/Geometry>  // cross(): without it the product was only declared, and PCL's libraries happened to define it
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "projbot/config/angles.hpp"

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

// True with probability p; certain outcomes draw nothing, so the published model's stream (and its
// frames) stay what they were before the fitted model's chances were added.
bool chance(XorShift& rng, double p) {
  if (p >= 1.0) return true;
  if (p <= 0.0) return false;
  return static_cast<double>(rng.next() >> 8) * (1.0 / 16777216.0) < p;
}

// A smooth random field of unit variance: standard normals on a grid `scale` px apart, interpolated
// bilinearly and rescaled so that the variance is 1 between the grid's nodes too.
class SmoothField {
 public:
  SmoothField(int width, int height, double scale, XorShift& rng)
      : inv_scale_(static_cast<float>(1.0 / std::max(scale, 1.0))),
        columns_(static_cast<int>(static_cast<float>(width) * inv_scale_) + 2),
        nodes_(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(static_cast<float>(height) * inv_scale_ + 2)) {
    const std::vector<float>& gauss = gaussian_table();
    for (auto& v : nodes_) v = gauss[rng.next() & 0xFFFFU];
  }
  float at(int x, int y) const {
    const float fx = static_cast<float>(x) * inv_scale_, fy = static_cast<float>(y) * inv_scale_;
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float tx = fx - static_cast<float>(ix), ty = fy - static_cast<float>(iy);
    const float* n = &nodes_[static_cast<std::size_t>(iy) * columns_ + ix];
    const float top = n[0] + tx * (n[1] - n[0]), bottom = n[columns_] + tx * (n[columns_ + 1] - n[columns_]);
    const float norm = ((1 - tx) * (1 - tx) + tx * tx) * ((1 - ty) * (1 - ty) + ty * ty);
    return (top + ty * (bottom - top)) / std::sqrt(norm);
  }

 private:
  float inv_scale_;
  int columns_;
  std::vector<float> nodes_;
};

// t with P(N(0,1) > t) = share (bisection: once per frame).
float normal_upper_quantile(double share) {
  double lo = -8.0, hi = 8.0;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > share ? lo : hi) = mid;
  }
  return static_cast<float>(lo);
}

// A pixel beside a depth edge. Near side: a 4-neighbour is farther by a jump or has no depth. Far side:
// a pixel within the band, left, right, above or below, is nearer by a jump; then the chance that it
// is lost (by the side the foreground lies on) and the nearest foreground's depth (for the bleed).
struct EdgeSide {
  bool step = false;  // a 4-neighbour differs by a jump or has no depth: the surface's slope is unknown
  bool near = false;
  float lost = 0.0F;
  float bleed_z = 0.0F;  // the adjacent foreground's depth, 0 if none is adjacent
};

EdgeSide edge_side(const float* z, int x, int y, int w, int h, const KinectNoiseConfig& cfg) {
  EdgeSide out;
  const float here = z[static_cast<std::size_t>(y) * w + x], jump = static_cast<float>(cfg.edge_jump_m) + 0.02F * here;
  const std::array<std::array<int, 2>, 4> dirs{{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
  const std::array<float, 4> lost{static_cast<float>(cfg.shadow_right), static_cast<float>(cfg.shadow_left),
                                  static_cast<float>(cfg.shadow_vertical), static_cast<float>(cfg.shadow_vertical)};
  for (std::size_t d = 0; d < dirs.size(); ++d)
    for (int step = 1; step <= std::max(cfg.shadow_band_px, 1); ++step) {
      const int u = x + dirs[d][0] * step, v = y + dirs[d][1] * step;
      if (u < 0 || v < 0 || u >= w || v >= h) break;
      const float there = z[static_cast<std::size_t>(v) * w + u];
      if (step == 1 && (!has_depth(there) || there - here > jump)) out.near = out.step = true;
      if (step == 1 && has_depth(there) && here - there > jump) out.step = true;
      if (has_depth(there) && here - there > jump) {
        if (step <= cfg.shadow_band_px) out.lost = std::max(out.lost, lost[d]);
        if (step == 1 && (out.bleed_z == 0.0F || there < out.bleed_z)) out.bleed_z = there;
        break;
      }
    }
  return out;
}

bool grazing(const float* z, int x, int y, int w, const CameraIntrinsics& k, float cos2_max) {
  const float ifx = static_cast<float>(1.0 / k.fx_px), ify = static_cast<float>(1.0 / k.fy_px);
  const float cx = static_cast<float>(k.cx_px), cy = static_cast<float>(k.cy_px);
  const auto point = [&](int u, int v) {
    const float d = z[static_cast<std::size_t>(v) * w + u];
    return Eigen::Vector3f((static_cast<float>(u) - cx) * d * ifx, (static_cast<float>(v) - cy) * d * ify, d);
  };
  const Eigen::Vector3f n = (point(x + 1, y) - point(x - 1, y)).cross(point(x, y + 1) - point(x, y - 1));
  const Eigen::Vector3f ray = point(x, y);
  const float along = n.dot(ray);  // squared, no roots
  return along * along < cos2_max * n.squaredNorm() * ray.squaredNorm();
}

}  // namespace

DepthImage apply_kinect_v1_noise(const DepthImage& clean, const CameraIntrinsics& k, const KinectNoiseConfig& cfg,
                                 std::uint32_t seed) {
  if (clean.width != k.width_px || clean.height != k.height_px)
    throw AlignmentError("noise model: depth image and intrinsics differ in size");
  DepthImage out = clean;
  const int w = clean.width, h = clean.height;
  const float* zin = clean.depth_m.data();
  const double cos_max = std::cos(config::radians(cfg.max_incidence_deg));
  const auto cos2_max = static_cast<float>(cos_max * cos_max);
  const std::vector<float>& gauss = gaussian_table();
  XorShift rng(seed);
  std::optional<SmoothField> smooth, holes;
  if (cfg.smooth_sigma_z_coeff > 0.0) smooth.emplace(w, h, cfg.smooth_scale_px, rng);
  if (cfg.hole_ratio > 0.0) holes.emplace(w, h, 4.0, rng);
  const float hole_above = holes ? normal_upper_quantile(cfg.hole_ratio) : 0.0F;
  const auto bf = static_cast<float>(cfg.baseline_m * cfg.disparity_focal_px);
  const bool quantise = cfg.disparity_step_px > 0.0;
  const auto step = static_cast<float>(cfg.disparity_step_px), inv_step = quantise ? 1.0F / step : 0.0F;
  const auto white = static_cast<float>(cfg.sigma_z_coeff), smooth_coeff = static_cast<float>(cfg.smooth_sigma_z_coeff);
  const bool edges = cfg.edge_jump_m < 1e8;
  const auto min_range = static_cast<float>(cfg.min_range_m), max_range = static_cast<float>(cfg.max_range_m);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      float& z_out = out.depth_m[i];
      float z = zin[i];
      const bool inside = x > 0 && y > 0 && x + 1 < w && y + 1 < h;
      if (!has_depth(z) || z < min_range || z > max_range || (edges && !inside) || (holes && holes->at(x, y) > hole_above)) {
        z_out = 0.0F;
        continue;
      }
      // Always looked at: with edges kept (edge_jump_m off) a missing neighbour still leaves the slope
      // unknown for the grazing test.
      const EdgeSide e = edge_side(zin, x, y, w, h, cfg);
      const bool bled = edges && e.bleed_z > 0.0F && chance(rng, cfg.bleed);
      if (edges && !bled && ((e.near && chance(rng, cfg.edge_drop)) || (e.lost > 0.0F && chance(rng, e.lost)))) {
        z_out = 0.0F;
        continue;
      }
      if (bled)
        z = e.bleed_z;
      else if (cos_max > 0.0 && inside && !e.step && grazing(zin, x, y, w, k, cos2_max)) {
        z_out = 0.0F;
        continue;
      }
      float noisy = z + white * z * z * gauss[rng.next() & 0xFFFFU];
      if (smooth) noisy += z * z * smooth_coeff * smooth->at(x, y);
      if (quantise && noisy > 0.0F) {  // to the disparity steps: d = bf / z, rounded to the step
        const float d = std::nearbyint(bf / noisy * inv_step) * step;
        noisy = d > 0.0F ? bf / d : 0.0F;
      }
      z_out = noisy;
    }
  return out;
}

}  // namespace projbot::alignment
