// projbot bench render: frame rate and frame-time percentiles of the projector pass.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/bench/frames.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

struct BenchModel {
  std::string name;
  assets::Model model;
};

std::vector<std::pair<int, int>> parse_sizes(const std::string& text) {
  std::vector<std::pair<int, int>> out;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    int w = 0, h = 0;
    char x = 0;
    if (std::sscanf(item.c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x' || w <= 0 || h <= 0 || w > 16384 || h > 16384)
      throw cli::UsageError("--sizes must look like 1280x800,1920x1080, got '" + item + "'");
    out.emplace_back(w, h);
    pos = comma + 1;
  }
  return out;
}

// The pinhole, and with --lens K1,K2 a projector lens with those radial terms, validated at every size
// as a scene's lens would be.
std::vector<std::optional<config::Distortion>> lenses_to_measure(const std::optional<std::string>& text,
                                                                 const std::vector<std::pair<int, int>>& sizes) {
  std::vector<std::optional<config::Distortion>> lenses{std::nullopt};
  if (!text) return lenses;
  double k1 = 0.0, k2 = 0.0;
  char extra = 0;
  if (std::sscanf(text->c_str(), "%lf,%lf%c", &k1, &k2, &extra) != 2 || !std::isfinite(k1) || !std::isfinite(k2))
    throw cli::UsageError("--lens must be K1,K2 (two radial terms, e.g. -0.12,0.05), not '" + *text + "'");
  lenses.push_back(config::Distortion{k1, k2, 0.0, 0.0, 0.0});
  for (const auto& [w, h] : sizes) {
    auto p = bench::typical_projector(w, h);
    p.distortion = *lenses.back();
    try {
      config::validate_projector(p, "--lens " + *text + " at " + std::to_string(w) + "x" + std::to_string(h));
    } catch (const config::ConfigError& e) {
      throw cli::UsageError(e.what());
    }
  }
  return lenses;
}

}  // namespace

const Command kBenchRender{
    "bench render",
    "benchmark the projector pass (frame rate, frame-time percentiles)",
    "projbot bench render [--frames N] [--sizes WxH,...] [--lens K1,K2] [--compensation]\n"
    "                     [--offscreen-only | --windowed-only]\n\n"
    "Draws the Duck (4212 triangles) and a 100k-triangle textured sphere at each size, offscreen and\n"
    "(when a display is there, e.g. under xvfb-run) in a window, and prints one row per run. Frame time\n"
    "is start-to-start of consecutive frames; windowed runs use the IMMEDIATE present mode where offered.\n"
    "With --lens every run is made twice, through a pinhole and through a projector lens with those\n"
    "radial terms (the lens pass: the models drawn onto an undistorted canvas, then warped per pixel).\n"
    "With --compensation every run is made twice, the content as stored and radiometrically compensated\n"
    "(issue 43: a beige surface in 50 lux, the default 3000-lumen projector; its cost is the difference).\n",
    {{"frames", "N", "measured frames per run, after 20 warm-up frames (default 300)"},
     {"sizes", "WxH,...", "target sizes (default 1280x800,1920x1080)"},
     {"lens", "K1,K2", "also measure each run through a projector lens with these radial terms"},
     {"compensation", "", "also measure each run with radiometric compensation on"},
     {"offscreen-only", "", "skip the windowed runs"},
     {"windowed-only", "", "skip the offscreen runs"},
     {"device", "N", "Vulkan physical device index"}},
    [](const cli::Args& args) {
      const int frames = args.get_int("frames", 300, 1, 1000000);
      const auto sizes = parse_sizes(args.get_or("sizes", "1280x800,1920x1080"));
      const auto lenses = lenses_to_measure(args.get("lens"), sizes);
      if (args.flag("offscreen-only") && args.flag("windowed-only"))
        throw cli::UsageError("--offscreen-only and --windowed-only together leave nothing to measure: give one");
      const bool want_offscreen = !args.flag("windowed-only");
      const char* display = std::getenv("DISPLAY");
      bool want_window = !args.flag("offscreen-only");
      if (want_window && (display == nullptr || *display == '\0')) {
        std::cout << "no DISPLAY: skipping windowed runs (run under xvfb-run for them)\n";
        want_window = false;
      }
      std::vector<BenchModel> models;
      models.push_back({"duck", assets::load_gltf(asset_dir() / "models" / "Duck" / "Duck.glb")});
      models.push_back({"sphere100k", assets::make_uv_sphere(0.25, 224, 224)});
      for (auto& m : models) assets::scale_and_recenter(m.model, 1.0, true);

      engine::RendererOptions ro;
      ro.windowing = want_window;
      ro.device_index = args.get_int("device", -1, -1, 64);
      engine::Renderer renderer(ro);
      catch_interrupts();  // Ctrl-C: the rows printed are whole; the run under way is dropped; exit 130
      std::cout << "device: " << renderer.device_info().name << " (" << renderer.device_info().driver << ")\n";
      std::vector<engine::Compensation> compensations{engine::Compensation{}};
      if (args.flag("compensation")) compensations.push_back(engine::compensation({0.72, 0.58, 0.44}, 50.0, 0.5));
      std::printf("%-11s %8s %10s %-9s %8s %8s %8s %8s %8s %8s  %-16s %s\n", "model", "tris", "size", "target", "fps", "p50_ms",
                  "p95_ms", "p99_ms", "max_ms", "gpu_p50", "lens", "compensation");
      for (const auto& m : models) {
        const std::size_t id = renderer.add_model(m.model);
        const double radius = 0.5 * m.model.bounds().diagonal().norm();
        for (const auto& [w, h] : sizes)
          for (const auto& lens : lenses)
            for (const engine::Compensation& comp : compensations)
              for (const bool windowed : {false, true}) {
                auto projector = bench::typical_projector(w, h);
                if (lens) projector.distortion = *lens;
                const std::vector<engine::DrawItem> items{{id, framing_pose(projector, radius), comp}};
                if ((windowed && !want_window) || (!windowed && !want_offscreen)) continue;
                const engine::FrameSummary s =
                    bench::measure_render(renderer, projector, items, windowed, frames, [] { return !interrupted(); });
                if (interrupted())
                  return benchmark_interrupted("after " + std::to_string(s.frames) + " of " + std::to_string(frames) +
                                               " frames of this run (not reported)");
                char size[32], lens_text[48] = "pinhole";
                std::snprintf(size, sizeof size, "%dx%d", w, h);
                if (lens) std::snprintf(lens_text, sizeof lens_text, "k1=%g,k2=%g", (*lens)[0], (*lens)[1]);
                std::printf("%-11s %8zu %10s %-9s %8.1f %8.2f %8.2f %8.2f %8.2f %8.2f  %-16s %s\n", m.name.c_str(),
                            m.model.triangle_count(), size, windowed ? "window" : "offscreen", s.fps, s.p50_ms, s.p95_ms,
                            s.p99_ms, s.max_ms, s.gpu_p50_ms, lens_text, comp.on ? "on" : "off");
                std::fflush(stdout);
              }
      }
      return 0;
    }};

}  // namespace projbot::tools
