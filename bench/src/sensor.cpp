#include "projbot/bench/sensor.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>

#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/engine/frame_profiler.hpp"

namespace projbot::bench {
namespace {

constexpr int kBackgroundRing = 8;  // where the background's depth is read, along the same direction
constexpr double kSameSurfaceM = 0.015;

// One instance's pixels: its visible silhouette, the truth's depth there, and the rings around it.
struct Silhouette {
  int width = 0, height = 0;
  std::vector<std::uint8_t> mask;
  std::vector<float> truth_m;  // rendered depth of the instance alone at its ground truth
  std::vector<int> ring;       // 0 inside; 1..kBackgroundRing outside; -1 farther
  std::vector<int> source;     // the silhouette pixel each outside pixel is nearest to (by BFS)
};

void find_rings(Silhouette& s) {
  const int n = s.width * s.height;
  s.ring.assign(static_cast<std::size_t>(n), -1);
  s.source.assign(static_cast<std::size_t>(n), -1);
  std::deque<int> todo;
  for (int i = 0; i < n; ++i)
    if (s.mask[static_cast<std::size_t>(i)]) {
      s.ring[static_cast<std::size_t>(i)] = 0;
      s.source[static_cast<std::size_t>(i)] = i;
      todo.push_back(i);
    }
  while (!todo.empty()) {
    const int i = todo.front();
    todo.pop_front();
    const int d = s.ring[static_cast<std::size_t>(i)], x = i % s.width, y = i / s.width;
    if (d >= kBackgroundRing) continue;
    for (const auto& [dx, dy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= s.width || v >= s.height) continue;
      const int j = v * s.width + u;
      if (s.ring[static_cast<std::size_t>(j)] >= 0) continue;
      s.ring[static_cast<std::size_t>(j)] = d + 1;
      s.source[static_cast<std::size_t>(j)] = s.source[static_cast<std::size_t>(i)];
      todo.push_back(j);
    }
  }
}

bool interior(const Silhouette& s, int x, int y) {
  for (int v = y - 2; v <= y + 2; ++v)
    for (int u = x - 2; u <= x + 2; ++u)
      if (u < 0 || v < 0 || u >= s.width || v >= s.height || !s.mask[static_cast<std::size_t>(v * s.width + u)]) return false;
  return true;
}

// The instance's residuals less the plane through them (least squares in the pixel coordinates): what is
// left is the sensor's noise, not a few tenths of a degree or millimetres of error in the ground truth.
// Also how the noise differs kLags px apart along a row (the sensor's correlation window smooths it).
void add_noise(const Silhouette& s, const std::vector<float>& residual_mm, SensorStats& out) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  std::vector<double> all;
  for (int i = 0; i < s.width * s.height; ++i) {
    const float r = residual_mm[static_cast<std::size_t>(i)];
    if (std::isnan(r)) continue;
    const Eigen::Vector3d a(1.0, (i % s.width) / 100.0, (i / s.width) / 100.0);
    normal += a * a.transpose();
    rhs += a * r;
    all.push_back(r);
  }
  if (all.size() < 100) return;
  out.offset_mm.push_back(engine::percentile(all, 0.5));
  const Eigen::Vector3d plane = normal.ldlt().solve(rhs);
  std::vector<float> noise(residual_mm.size(), std::nanf(""));
  for (int i = 0; i < s.width * s.height; ++i) {
    const float r = residual_mm[static_cast<std::size_t>(i)];
    if (std::isnan(r)) continue;
    const double n = r - plane.dot(Eigen::Vector3d(1.0, (i % s.width) / 100.0, (i / s.width) / 100.0));
    noise[static_cast<std::size_t>(i)] = static_cast<float>(n);
    out.noise_mm.push_back(n);
  }
  for (std::size_t l = 0; l < kLags.size(); ++l)
    for (int i = 0; i + kLags[l] < s.width * s.height; ++i) {
      const float a = noise[static_cast<std::size_t>(i)], b = noise[static_cast<std::size_t>(i + kLags[l])];
      if (std::isnan(a) || std::isnan(b) || i % s.width + kLags[l] >= s.width) continue;
      out.lag_difference[l].push_back(std::abs(static_cast<double>(a) - b));
    }
}

// Inside the silhouette: residuals against the truth, missing pixels, depth steps.
void add_inside(const Silhouette& s, const std::vector<float>& depth, SensorStats& out) {
  std::vector<float> residual(depth.size(), std::nanf(""));
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      const auto i = static_cast<std::size_t>(y * s.width + x);
      if (!s.mask[i] || !(s.truth_m[i] > 0.0F)) continue;
      const bool inner = interior(s, x, y);
      (inner ? out.interior : out.edge)++;
      if (!(depth[i] > 0.0F)) {
        (inner ? out.interior_missing : out.edge_missing)++;
        continue;
      }
      if (!inner) continue;
      out.residual_mm.push_back(1000.0 * (depth[i] - s.truth_m[i]));
      residual[i] = static_cast<float>(out.residual_mm.back());
      const float right = depth[i + 1];
      const double step = std::abs(static_cast<double>(right) - depth[i]);
      if (x + 1 < s.width && s.mask[i + 1] && right > 0.0F && step > 1e-5 && step < 0.01)
        out.step_per_z2.push_back(step / (static_cast<double>(depth[i]) * depth[i]));
    }
  add_noise(s, residual, out);
}

// Outside it, ring by ring: missing, the object's depth bled outward, depths between object and background.
void add_outside(const Silhouette& s, const std::vector<float>& depth, SensorStats& out) {
  for (int j = 0; j < s.width * s.height; ++j) {
    const int d = s.ring[static_cast<std::size_t>(j)];
    if (d < 1 || d > kRings) continue;
    const int q = s.source[static_cast<std::size_t>(j)];
    const float z_obj = s.truth_m[static_cast<std::size_t>(q)], z = depth[static_cast<std::size_t>(j)];
    if (!(z_obj > 0.0F)) continue;
    const int dx = j % s.width - q % s.width, dy = j / s.width - q / s.width;
    ++out.ring[static_cast<std::size_t>(d)];
    if (d <= 3) (dx < 0 ? out.left : out.right) += dx != 0 ? 1 : 0;
    if (!(z > 0.0F)) {
      ++out.ring_missing[static_cast<std::size_t>(d)];
      if (d <= 3 && dx != 0) (dx < 0 ? out.left_missing : out.right_missing)++;
      continue;
    }
    if (std::abs(z - z_obj) < kSameSurfaceM) {
      ++out.ring_object[static_cast<std::size_t>(d)];
      continue;
    }
    const double len = std::hypot(dx, dy);
    const int bx = q % s.width + static_cast<int>(std::lround(dx / len * kBackgroundRing)),
              by = q / s.width + static_cast<int>(std::lround(dy / len * kBackgroundRing));
    if (bx < 0 || by < 0 || bx >= s.width || by >= s.height) continue;
    const float z_bg = depth[static_cast<std::size_t>(by * s.width + bx)];
    if (z > z_obj + kSameSurfaceM && z_bg > 0.0F && z < z_bg - kSameSurfaceM) ++out.ring_between[static_cast<std::size_t>(d)];
  }
}

// The twin's scene of the image, before its Kinect model: the models rendered at their ground truth, and
// behind them the real frame's background (the table, the wall: the twin has no geometry for them), taken
// 4 px and more from any model at the farthest depth of its 9 x 9 neighbourhood, so that none of the real
// frame's edge pixels come with it.
alignment::DepthImage twin_scene(const std::vector<float>& models, const alignment::DepthImage& real) {
  const int w = real.width, h = real.height;
  alignment::DepthImage clean{w, h, models, 0.0};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const auto i = static_cast<std::size_t>(y * w + x);
      if (models[i] > 0.0F) continue;
      float far = 0.0F;
      bool near_model = false;
      for (int v = std::max(0, y - 4); v <= std::min(h - 1, y + 4); ++v)
        for (int u = std::max(0, x - 4); u <= std::min(w - 1, x + 4); ++u) {
          near_model |= models[static_cast<std::size_t>(v * w + u)] > 0.0F;
          far = std::max(far, real.depth_m[static_cast<std::size_t>(v * w + u)]);
        }
      clean.depth_m[i] = near_model ? far : real.depth_m[i];
    }
  return clean;
}

}  // namespace

void SensorStats::add(const SensorStats& more) {
  const auto append = [](std::vector<double>& to, const std::vector<double>& from) {
    to.insert(to.end(), from.begin(), from.end());
  };
  append(residual_mm, more.residual_mm);
  append(step_per_z2, more.step_per_z2);
  append(offset_mm, more.offset_mm);
  append(noise_mm, more.noise_mm);
  for (std::size_t l = 0; l < lag_difference.size(); ++l) append(lag_difference[l], more.lag_difference[l]);
  interior += more.interior, interior_missing += more.interior_missing, edge += more.edge, edge_missing += more.edge_missing;
  for (std::size_t d = 0; d < ring.size(); ++d) {
    ring[d] += more.ring[d], ring_missing[d] += more.ring_missing[d];
    ring_object[d] += more.ring_object[d], ring_between[d] += more.ring_between[d];
  }
  left += more.left, left_missing += more.left_missing, right += more.right, right_missing += more.right_missing;
}

void SensorComparison::add(const SensorComparison& more) {
  real.add(more.real), twin.add(more.twin), fitted.add(more.fitted);
  instances += more.instances, images += more.images;
}

void SensorBench::image(const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible, std::uint32_t seed,
                        SensorComparison& out) {
  std::vector<const alignment::BopInstance*> all;
  for (const auto& inst : image.instances) all.push_back(&inst);
  const alignment::DepthImage real = alignment::read_bop_depth(image);
  const std::vector<float> models = render(image, all, real.width, real.height);  // at the real depth's size
  const auto image_seed = seed ^ static_cast<std::uint32_t>(image.id);
  const alignment::DepthImage scene_depth = twin_scene(models, real);  // one scene, under each Kinect model
  const alignment::DepthImage twin = alignment::apply_kinect_v1_noise(scene_depth, image.k, {}, image_seed);
  const alignment::DepthImage fitted =
      alignment::apply_kinect_v1_noise(scene_depth, image.k, alignment::KinectNoiseConfig::fitted(), image_seed);
  ++out.images;
  for (const auto* inst : all) {
    if (inst->visible_px >= 0 && inst->visible_px < min_visible) continue;
    Silhouette s{real.width, real.height, alignment::read_bop_mask(scene, image, *inst, real), models, {}, {}};
    find_rings(s);
    add_inside(s, real.depth_m, out.real);
    add_inside(s, twin.depth_m, out.twin);
    add_inside(s, fitted.depth_m, out.fitted);
    add_outside(s, real.depth_m, out.real);
    add_outside(s, twin.depth_m, out.twin);
    add_outside(s, fitted.depth_m, out.fitted);
    ++out.instances;
  }
}

SensorBench::SensorBench(const alignment::BopDataset& data, double scale) : renderer_(engine::RendererOptions{}) {
  for (const auto& o : data.objects) {
    assets::Model mesh = assets::load_model(o.model);
    assets::scale_and_recenter(mesh, scale, false);
    ids_[o.id] = renderer_.add_model(mesh);
  }
}

// Depth of the given instances alone (truth), metres, 0 where nothing is.
std::vector<float> SensorBench::render(const alignment::BopImage& image, const std::vector<const alignment::BopInstance*>& which,
                                       int width, int height) {
  if (!target_ || width_ != width || height_ != height) {
    target_ = renderer_.make_depth_camera(width, height);
    width_ = width, height_ = height;
  }
  alignment::CameraIntrinsics k = image.k;
  k.width_px = width, k.height_px = height;
  std::vector<engine::DrawItem> items;
  for (const auto* inst : which) items.push_back({ids_.at(inst->obj_id), inst->T_camera_model});
  renderer_.draw_frame(*target_, config::Camera(k, 0.1, 10.0), items);
  return target_->read_back_depth().z_m;
}

}  // namespace projbot::bench
