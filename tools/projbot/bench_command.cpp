// projbot bench render: frame rate and frame-time percentiles of the projector pass.

#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

struct BenchModel {
  std::string name;
  assets::Model model;
};

config::ProjectorConfig projector_for(int w, int h) {
  config::ProjectorConfig p;
  p.width_px = w;
  p.height_px = h;
  p.fx_px = p.fy_px = 1.1 * w;  // about a 48 degree horizontal field, a typical projector
  p.cx_px = (w - 1) / 2.0;
  p.cy_px = (h - 1) / 2.0;
  return p;
}

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

}  // namespace

const Command kBenchRender{
    "bench render",
    "benchmark the projector pass (frame rate, frame-time percentiles)",
    "projbot bench render [--frames N] [--sizes WxH,...] [--offscreen-only | --windowed-only]\n\n"
    "Draws the Duck (4212 triangles) and a 100k-triangle textured sphere at each size, offscreen and\n"
    "(when a display is there, e.g. under xvfb-run) in a window, and prints one row per run. Frame time\n"
    "is start-to-start of consecutive frames; windowed runs use the IMMEDIATE present mode where offered.\n",
    {{"frames", "N", "measured frames per run, after 20 warm-up frames (default 300)"},
     {"sizes", "WxH,...", "target sizes (default 1280x800,1920x1080)"},
     {"offscreen-only", "", "skip the windowed runs"},
     {"windowed-only", "", "skip the offscreen runs"},
     {"device", "N", "Vulkan physical device index"}},
    [](const cli::Args& args) {
      const int frames = args.get_int("frames", 300, 1, 1000000);
      const auto sizes = parse_sizes(args.get_or("sizes", "1280x800,1920x1080"));
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
      std::printf("%-11s %8s %10s %-9s %8s %8s %8s %8s %8s %8s\n", "model", "tris", "size", "target", "fps", "p50_ms", "p95_ms",
                  "p99_ms", "max_ms", "gpu_p50");
      for (const auto& m : models) {
        const std::size_t id = renderer.add_model(m.model);
        const double radius = 0.5 * m.model.bounds().diagonal().norm();
        for (const auto& [w, h] : sizes) {
          const auto projector = projector_for(w, h);
          const std::vector<engine::DrawItem> items{{id, framing_pose(projector, radius)}};
          for (const bool windowed : {false, true}) {
            if ((windowed && !want_window) || (!windowed && !want_offscreen)) continue;
            std::unique_ptr<engine::RenderTarget> target;
            if (windowed) {
              engine::WindowOptions wo;
              wo.width_px = w;
              wo.height_px = h;
              wo.title = "projbot bench";
              wo.present_mode = engine::PresentMode::kImmediate;
              target = renderer.make_window(wo);
            } else {
              target = renderer.make_offscreen(w, h);
            }
            for (int i = 0; i < 20 && !interrupted(); ++i) {
              target->poll_close();
              renderer.draw_frame(*target, projector, items);
            }
            renderer.finish(*target);
            engine::FrameProfiler profiler;
            for (int i = 0; i < frames && !interrupted(); ++i) {
              target->poll_close();
              renderer.draw_frame(*target, projector, items, &profiler);
            }
            renderer.finish(*target);
            const auto s = profiler.summary();
            if (interrupted())
              return benchmark_interrupted("after " + std::to_string(s.frames) + " of " + std::to_string(frames) +
                                           " frames of this run (not reported)");
            char size[32];
            std::snprintf(size, sizeof size, "%dx%d", w, h);
            std::printf("%-11s %8zu %10s %-9s %8.1f %8.2f %8.2f %8.2f %8.2f %8.2f\n", m.name.c_str(), m.model.triangle_count(),
                        size, windowed ? "window" : "offscreen", s.fps, s.p50_ms, s.p95_ms, s.p99_ms, s.max_ms, s.gpu_p50_ms);
            std::fflush(stdout);
          }
        }
      }
      return 0;
    }};

}  // namespace projbot::tools
