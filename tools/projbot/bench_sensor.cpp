// projbot bench sensor DIR: the real depth camera beside the twin's, both at a BOP dataset's ground truth
// (issue 41): what the real sensor does that the twin's Kinect model does or does not (noise inside the
// silhouette, missing pixels, the band of mixed pixels and the shadow outside it, depth quantisation).

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/alignment/bop.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

namespace fs = std::filesystem;

constexpr int kRings = 4;           // rings of pixels outside the silhouette, 1..kRings px away
constexpr int kBackgroundRing = 8;  // where the background's depth is read, along the same direction
constexpr double kSameSurfaceM = 0.015;

// What one sensor showed over all instances.
struct Stats {
  std::vector<double> residual_mm;  // depth - rendered truth, silhouette interior, both valid
  long interior = 0, interior_missing = 0, edge = 0, edge_missing = 0;
  std::array<long, kRings + 1> ring{}, ring_missing{}, ring_object{}, ring_between{};
  long left = 0, left_missing = 0, right = 0, right_missing = 0;  // rings 1..3, by side of the silhouette
  std::vector<double> step_per_z2;                                // nonzero depth steps between neighbours / z^2
  std::vector<double> offset_mm;  // per instance: the median residual (what the ground truth's own error explains)
  std::vector<double> noise_mm;   // residuals less their instance's plane (offset and tilt): the sensor's noise
  std::array<std::vector<double>, 3> lag_difference;  // |noise - noise kLags[i] px to the right|
};

constexpr std::array<int, 3> kLags{1, 3, 8};

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
void add_noise(const Silhouette& s, const std::vector<float>& residual_mm, Stats& out) {
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
void add_inside(const Silhouette& s, const std::vector<float>& depth, Stats& out) {
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
void add_outside(const Silhouette& s, const std::vector<float>& depth, Stats& out) {
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

config::ProjectorConfig camera_of(const alignment::CameraIntrinsics& k) { return config::ProjectorConfig(k, 0.1, 10.0); }

// Renders the dataset's models at their ground truth through each image's camera.
class TwinSensor {
 public:
  TwinSensor(const alignment::BopDataset& data, double scale) : renderer_(engine::RendererOptions{}) {
    for (const auto& o : data.objects) {
      assets::Model mesh = assets::load_model(o.model);
      assets::scale_and_recenter(mesh, scale, false);
      ids_[o.id] = renderer_.add_model(mesh);
    }
  }
  // Depth of the given instances alone (truth), metres, 0 where nothing is.
  std::vector<float> render(const alignment::BopImage& image, const std::vector<const alignment::BopInstance*>& which) {
    if (!target_ || width_ != image.k.width_px || height_ != image.k.height_px) {
      target_ = renderer_.make_depth_camera(image.k.width_px, image.k.height_px);
      width_ = image.k.width_px, height_ = image.k.height_px;
    }
    std::vector<engine::DrawItem> items;
    for (const auto* inst : which) items.push_back({ids_.at(inst->obj_id), inst->T_camera_model});
    renderer_.draw_frame(*target_, camera_of(image.k), items);
    return target_->read_back_depth().z_m;
  }

 private:
  engine::Renderer renderer_;
  std::map<int, std::size_t> ids_;
  std::unique_ptr<engine::RenderTarget> target_;
  int width_ = 0, height_ = 0;
};

}  // namespace

namespace {

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

struct Sensors {
  Stats real, twin, fitted;  // the twin's published Kinect model, and the one fitted to real frames
  int instances = 0, images = 0;
};

void measure_image(TwinSensor& sensor, const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible,
                   std::uint32_t seed, Sensors& out) {
  std::vector<const alignment::BopInstance*> all;
  for (const auto& inst : image.instances) all.push_back(&inst);
  const alignment::DepthImage real = alignment::read_bop_depth(image);
  const std::vector<float> models = sensor.render(image, all);
  const auto image_seed = seed ^ static_cast<std::uint32_t>(image.id);
  const alignment::DepthImage scene_depth = twin_scene(models, real);  // one scene, under each Kinect model
  const alignment::DepthImage twin = alignment::apply_kinect_v1_noise(scene_depth, image.k, {}, image_seed);
  const alignment::DepthImage fitted =
      alignment::apply_kinect_v1_noise(scene_depth, image.k, alignment::KinectNoiseConfig::fitted(), image_seed);
  ++out.images;
  for (const auto* inst : all) {
    if (inst->visible_px >= 0 && inst->visible_px < min_visible) continue;
    Silhouette s{real.width, real.height, alignment::read_bop_mask(scene, image, *inst), models, {}, {}};
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

std::string share(long part, long whole) {
  char text[32];
  std::snprintf(text, sizeof text, whole > 0 ? "%.1f %%" : "-",
                whole > 0 ? 100.0 * static_cast<double>(part) / static_cast<double>(whole) : 0.0);
  return text;
}

std::string number(double v, const char* format) {
  char text[32];
  std::snprintf(text, sizeof text, std::isnan(v) ? "-" : format, v);
  return text;
}

using Cell = std::function<std::string(const Stats&)>;

void print_row(const std::string& what, const Sensors& s, const Cell& cell) {
  std::cout << "| " << what << " | " << cell(s.real) << " | " << cell(s.twin) << " | " << cell(s.fitted) << " |\n";
}

std::string residuals(const Stats& s) {
  std::vector<double> a;
  for (const double r : s.residual_mm) a.push_back(std::abs(r));
  return number(engine::percentile(a, 0.5), "%.2f") + " / " + number(engine::percentile(a, 0.9), "%.2f") + " / " +
         number(engine::percentile(s.residual_mm, 0.5), "%+.2f");
}

double typical_noise(const Stats& t) {
  std::vector<double> size;
  for (const double r : t.noise_mm) size.push_back(std::abs(r));
  return engine::percentile(size, 0.5);
}

std::string noise(const Stats& t) {
  std::vector<double> a, o;
  for (const double r : t.noise_mm) a.push_back(std::abs(r));
  for (const double r : t.offset_mm) o.push_back(std::abs(r));
  return number(engine::percentile(o, 0.5), "%.2f") + " / " + number(engine::percentile(a, 0.5), "%.2f") + " / " +
         number(engine::percentile(a, 0.9), "%.2f");
}

// Robustly, from medians (the edges' outliers would rule a mean): for a normal field with correlation rho,
// |a - b| has median sqrt(2 (1 - rho)) times that of |a|.
std::string alike(const Stats& t) {
  const double typical = typical_noise(t);
  std::string text;
  for (std::size_t l = 0; l < kLags.size(); ++l) {
    const double ratio = engine::percentile(t.lag_difference[l], 0.5) / typical;
    text += (l ? " / " : "") + number(typical > 0.0 ? 1.0 - 0.5 * ratio * ratio : NAN, "%.2f");
  }
  return text;
}

std::string steps(const Stats& t) {
  return number(engine::percentile(t.step_per_z2, 0.1) * 1000.0, "%.2f") + " / " +
         number(engine::percentile(t.step_per_z2, 0.5) * 1000.0, "%.2f");
}

// The fitted model's noise inside a surface is nearly all smooth: its size scales with the smooth coefficient.
void print_needed_noise(const Sensors& s) {
  const double real = typical_noise(s.real), fitted = typical_noise(s.fitted);
  if (!(real > 0.0) || !(fitted > 0.0)) return;
  const double coeff = alignment::KinectNoiseConfig::fitted().smooth_sigma_z_coeff;
  std::printf(
      "\nThe real frames' noise (less each instance's plane) is %.2f times the fitted model's: its smooth noise\n"
      "would match with sigma = %.2e z^2 (it has %.2e z^2; the real figure holds the ground truth's own error too).\n",
      real / fitted, coeff * real / fitted, coeff);
}

void print_sensors(const Sensors& s) {
  std::cout << "\nThe real sensor and the twin's at the ground truth: " << s.instances << " instances in " << s.images
            << " images\n| | real | twin (published Kinect v1 model, the twin's) | twin (fitted to real frames) |\n"
            << "|---|---|---|---|\n";
  print_row("inside the silhouette: depth - truth, median of its size / p90 of its size / median, mm", s, residuals);
  print_row("per instance: size of its median residual (median) / the rest less its plane, median / p90 of its size, mm", s,
            noise);
  print_row("that noise's correlation with the pixel 1 / 3 / 8 px to the right", s, alike);
  print_row("missing inside (2 px from the edge and more)", s,
            [](const Stats& t) { return share(t.interior_missing, t.interior); });
  print_row("missing at the silhouette's edge (its outer 2 px)", s, [](const Stats& t) { return share(t.edge_missing, t.edge); });
  for (int d = 1; d <= kRings; ++d)
    print_row(std::to_string(d) + " px outside: missing / object's depth / between object and background", s,
              [d](const Stats& t) {
                const auto i = static_cast<std::size_t>(d);
                return share(t.ring_missing[i], t.ring[i]) + " / " + share(t.ring_object[i], t.ring[i]) + " / " +
                       share(t.ring_between[i], t.ring[i]);
              });
  print_row("missing 1-3 px outside, left of the object / right", s,
            [](const Stats& t) { return share(t.left_missing, t.left) + " / " + share(t.right_missing, t.right); });
  print_row("depth step between neighbours / z^2, p10 / median, mm per m^2", s, steps);
  print_needed_noise(s);
}

int run_bench_sensor(const cli::Args& args) {
  if (args.positional().size() != 1) throw cli::UsageError("give the BOP dataset's folder: projbot bench sensor DIR");
  const int min_visible = args.get_int("min-visible", 1500, 0, 100000000);
  const int max_images = args.get_int("max-images", 1 << 30, 1, 1 << 30);
  const auto seed = static_cast<std::uint32_t>(args.get_int("seed", 1, 0, 1 << 30));
  const double scale = model_scale_option(args, 0.001);
  const alignment::BopDataset data = alignment::read_bop_dataset(args.positional().front(), args.get_list("scenes"));
  TwinSensor sensor(data, scale);
  catch_interrupts();
  int total = 0;
  for (const auto& scene : data.scenes) total += static_cast<int>(scene.images.size());
  Progress progress("image", std::min(total, max_images));
  Sensors out;
  for (const auto& scene : data.scenes)
    for (const auto& image : scene.images) {
      if (interrupted() || out.images >= max_images) break;
      measure_image(sensor, scene, image, min_visible, seed, out);
      progress.step(out.images);
    }
  print_sensors(out);
  if (interrupted()) return benchmark_interrupted("after " + std::to_string(out.images) + " images");
  return 0;
}

}  // namespace

const Command kBenchSensor{
    "bench sensor",
    "the real depth camera beside the twin's, at a BOP dataset's ground truth",
    "projbot bench sensor DIR [--scenes A,B] [--max-images N] [--min-visible PX] [--model-scale S] [--seed K]\n\n"
    "DIR is a BOP dataset (as for bench dataset). Each image's models are rendered at their ground truth through\n"
    "its camera; the twin's depth is that render with the real frame's background behind it (the twin has no\n"
    "table) under the twin's Kinect v1 model (noise, disparity steps, edge and grazing-angle dropouts), and under\n"
    "the model fitted to real frames (smooth noise, finer steps, the shadow band, bleeding, holes). For every\n"
    "instance with at least PX visible pixels (default 1500), real and twin side by side: inside the visible\n"
    "silhouette the depth minus the rendered truth and the missing pixels (inside, and on its outer 2 px); in the\n"
    "rings 1-4 px outside it, the pixels missing, those at the object's depth (it bleeds outward) and those\n"
    "between the object and the background (mixed pixels); on which side the missing pixels lie (the IR\n"
    "projector's shadow); and the depth steps between neighbours over z^2 (the disparity quantisation: the\n"
    "twin's is 1000 x 0.125 / (580 x 0.075) = 2.87 mm per m^2, the fitted one's 1.82). Inside, each instance's residuals less "
    "the\n"
    "plane through them (the ground truth's offset and tilt) are the sensor's noise: its size, and how alike\n"
    "it is 1, 3 and 8 px apart (1 - d^2 / 2, d the median difference over the median size: a correlation\n"
    "not ruled by outliers). Ctrl-C prints the images measured.\n",
    {{"scenes", "A,B", "scenes to measure (default: all)"},
     {"max-images", "N", "stop after N images"},
     {"min-visible", "PX", "instances with fewer visible pixels are left out (default 1500)"},
     {"model-scale", "S", "model units to metres (default 0.001: BOP's millimetres)"},
     {"seed", "K", "seed of the twin's noise (default 1)"}},
    run_bench_sensor};

}  // namespace projbot::tools
