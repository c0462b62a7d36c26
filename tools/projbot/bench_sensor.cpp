// projbot bench sensor DIR: the real depth camera beside the twin's, both at a BOP dataset's ground truth
// (issue 41): what the real sensor does that the twin's Kinect model does or does not (noise inside the
// silhouette, missing pixels, the band of mixed pixels and the shadow outside it, depth quantisation).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/alignment/bop.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/bench/sensor.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

namespace fs = std::filesystem;

using bench::kLags;
using bench::kRings;

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

using Cell = std::function<std::string(const bench::SensorStats&)>;

void print_row(const std::string& what, const bench::SensorComparison& s, const Cell& cell) {
  std::cout << "| " << what << " | " << cell(s.real) << " | " << cell(s.twin) << " | " << cell(s.fitted) << " |\n";
}

std::string residuals(const bench::SensorStats& s) {
  std::vector<double> a;
  for (const double r : s.residual_mm) a.push_back(std::abs(r));
  return number(engine::percentile(a, 0.5), "%.2f") + " / " + number(engine::percentile(a, 0.9), "%.2f") + " / " +
         number(engine::percentile(s.residual_mm, 0.5), "%+.2f");
}

double typical_noise(const bench::SensorStats& t) {
  std::vector<double> size;
  for (const double r : t.noise_mm) size.push_back(std::abs(r));
  return engine::percentile(size, 0.5);
}

std::string noise(const bench::SensorStats& t) {
  std::vector<double> a, o;
  for (const double r : t.noise_mm) a.push_back(std::abs(r));
  for (const double r : t.offset_mm) o.push_back(std::abs(r));
  return number(engine::percentile(o, 0.5), "%.2f") + " / " + number(engine::percentile(a, 0.5), "%.2f") + " / " +
         number(engine::percentile(a, 0.9), "%.2f");
}

// Robustly, from medians (the edges' outliers would rule a mean): for a normal field with correlation rho,
// |a - b| has median sqrt(2 (1 - rho)) times that of |a|.
std::string alike(const bench::SensorStats& t) {
  const double typical = typical_noise(t);
  std::string text;
  for (std::size_t l = 0; l < kLags.size(); ++l) {
    const double ratio = engine::percentile(t.lag_difference[l], 0.5) / typical;
    text += (l ? " / " : "") + number(typical > 0.0 ? 1.0 - 0.5 * ratio * ratio : NAN, "%.2f");
  }
  return text;
}

std::string steps(const bench::SensorStats& t) {
  return number(engine::percentile(t.step_per_z2, 0.1) * 1000.0, "%.2f") + " / " +
         number(engine::percentile(t.step_per_z2, 0.5) * 1000.0, "%.2f");
}

// The fitted model's noise inside a surface is nearly all smooth: its size scales with the smooth coefficient.
void print_needed_noise(const bench::SensorComparison& s) {
  const double real = typical_noise(s.real), fitted = typical_noise(s.fitted);
  if (!(real > 0.0) || !(fitted > 0.0)) return;
  const double coeff = alignment::KinectNoiseConfig::fitted().smooth_sigma_z_coeff;
  std::printf(
      "\nThe real frames' noise (less each instance's plane) is %.2f times the fitted model's: its smooth noise\n"
      "would match with sigma = %.2e z^2 (it has %.2e z^2; the real figure holds the ground truth's own error too).\n",
      real / fitted, coeff * real / fitted, coeff);
}

void print_sensors(const bench::SensorComparison& s) {
  std::cout << "\nThe real sensor and the twin's at the ground truth: " << s.instances << " instances in " << s.images
            << " images\n| | real | twin (published Kinect v1 model, the twin's) | twin (fitted to real frames) |\n"
            << "|---|---|---|---|\n";
  print_row("inside the silhouette: depth - truth, median of its size / p90 of its size / median, mm", s, residuals);
  print_row("per instance: size of its median residual (median) / the rest less its plane, median / p90 of its size, mm", s,
            noise);
  print_row("that noise's correlation with the pixel 1 / 3 / 8 px to the right", s, alike);
  print_row("missing inside (2 px from the edge and more)", s,
            [](const bench::SensorStats& t) { return share(t.interior_missing, t.interior); });
  print_row("missing at the silhouette's edge (its outer 2 px)", s,
            [](const bench::SensorStats& t) { return share(t.edge_missing, t.edge); });
  for (int d = 1; d <= kRings; ++d)
    print_row(std::to_string(d) + " px outside: missing / object's depth / between object and background", s,
              [d](const bench::SensorStats& t) {
                const auto i = static_cast<std::size_t>(d);
                return share(t.ring_missing[i], t.ring[i]) + " / " + share(t.ring_object[i], t.ring[i]) + " / " +
                       share(t.ring_between[i], t.ring[i]);
              });
  print_row("missing 1-3 px outside, left of the object / right", s,
            [](const bench::SensorStats& t) { return share(t.left_missing, t.left) + " / " + share(t.right_missing, t.right); });
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
  if (const std::string note = alignment::rounded_rotations_note(data); !note.empty()) std::cout << note << "\n";
  bench::SensorBench sensor(data, scale);
  catch_interrupts();
  int total = 0;
  for (const auto& scene : data.scenes) total += static_cast<int>(scene.images.size());
  Progress progress("image", std::min(total, max_images));
  bench::SensorComparison out;
  for (const auto& scene : data.scenes)
    for (const auto& image : scene.images) {
      if (interrupted() || out.images >= max_images) break;
      // An image takes seconds: measured on a thread of its own, kept whole or dropped at a signal.
      const auto one = unless_interrupted<bench::SensorComparison>([&] {
        bench::SensorComparison its;
        sensor.image(scene, image, min_visible, seed, its);
        return its;
      });
      if (!one) {
        print_sensors(out);
        benchmark_interrupted("after " + std::to_string(out.images) + " images (the one under way dropped)");
        quit_now();
      }
      out.add(*one);
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
