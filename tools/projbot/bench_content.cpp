// projbot bench content: moving content on the targets (issue 44), drawn offscreen at the projector's
// refresh for a while: what decoding and uploading cost the render thread, and whether each frame shows the
// content of its own display time.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/engine/content.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

double rss_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  return std::nan("");
}

struct ContentRun {
  std::size_t frames = 0;
  std::vector<double> offset_ms;  // per target-frame: content time less the shown frame's presentation time
  double in_step_ms_max = 0.0;    // the largest spread of that offset between targets within one frame
  double within_one_frame = 0.0;  // share of target-frames whose offset is under one video frame
  std::size_t waits = 0, repeated = 0, skipped = 0, shown = 0;
  double rss_start_mb = 0.0, rss_end_mb = 0.0, seconds = 0.0;
  bool interrupted = false;
};

// Draws every target at its scene pose for `seconds`, paced like a projector at its refresh (an offscreen
// target has no vsync), each target's content sampled at the frame's display time (one period ahead).
ContentRun run_content(engine::Renderer& renderer, engine::RenderTarget& target, const config::Scene& scene,
                       const std::vector<engine::DrawItem>& items, engine::SceneContent& content, double seconds,
                       engine::FrameProfiler& profiler) {
  ContentRun run;
  run.rss_start_mb = rss_mb();
  const double period_s = 1.0 / scene.projector.refresh_hz;
  const double t0 = config::steady_now_s();
  auto next = std::chrono::steady_clock::now();
  std::size_t within = 0;
  while (!interrupted() && config::steady_now_s() - t0 < seconds) {
    pace_frame(next, std::chrono::microseconds(static_cast<std::int64_t>(1e6 * period_s)));
    const auto read = [&](std::vector<engine::DrawItem>& out) {
      out.assign(items.begin(), items.end());
      const double display_s = config::steady_now_s() + period_s;
      double lo = INFINITY, hi = -INFINITY;
      for (int i = 0; i < static_cast<int>(items.size()); ++i) {
        if (!content.has(i)) continue;
        const auto s = content.apply(i, display_s - content.start_s(i, t0, t0), out[static_cast<std::size_t>(i)]);
        if (std::isnan(s.pts_s)) continue;  // no video, or none decoded yet
        const double offset = 1000.0 * (s.content_s - s.pts_s);
        run.offset_ms.push_back(offset);
        within += offset < 1000.0 / content.player(i).info().fps ? 1 : 0;
        lo = std::min(lo, offset);
        hi = std::max(hi, offset);
      }
      if (hi >= lo) run.in_step_ms_max = std::max(run.in_step_ms_max, hi - lo);
    };
    if (renderer.draw_frame(target, scene.projector, read, &profiler)) ++run.frames;
  }
  renderer.finish(target);
  run.seconds = config::steady_now_s() - t0;
  run.interrupted = interrupted();
  for (const assets::VideoPlayer* video : content.videos()) {
    const auto st = video->stats();
    run.waits += st.waits;
    run.repeated += st.repeated;
    run.skipped += st.skipped;
    run.shown += st.shown;
  }
  run.within_one_frame = run.offset_ms.empty() ? 0.0 : static_cast<double>(within) / static_cast<double>(run.offset_ms.size());
  run.rss_end_mb = rss_mb();
  return run;
}

nlohmann::json finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

void write_report(const std::filesystem::path& file, const ContentRun& r, const engine::FrameSummary& frames) {
  const nlohmann::json out = {{"frames", r.frames},
                              {"renderer_waits", r.waits},
                              {"content_offset_ms_p50", finite(engine::percentile(r.offset_ms, 0.5))},
                              {"content_offset_ms_p99", finite(engine::percentile(r.offset_ms, 0.99))},
                              {"content_within_one_frame", r.within_one_frame},
                              {"repeated", r.repeated},
                              {"skipped", r.skipped},
                              {"upload_ms_p50", finite(frames.upload_p50_ms)},
                              {"upload_ms_p99", finite(frames.upload_p99_ms)},
                              {"rss_mb_start", r.rss_start_mb},
                              {"rss_mb_end", r.rss_end_mb},
                              {"targets_in_step_ms_max", r.in_step_ms_max},
                              {"seconds", r.seconds},
                              {"interrupted", r.interrupted}};
  config::write_file_atomically(file, out.dump(1) + "\n");
}

void print(const ContentRun& r, const engine::FrameSummary& frames) {
  std::printf("%zu frames in %.1f s (%s)\n", r.frames, r.seconds, engine::format_summary(frames).c_str());
  std::printf(
      "content time less the shown frame's time: p50 %.1f ms, p99 %.1f ms; within one video frame on %.1f %% of "
      "target-frames\n",
      engine::percentile(r.offset_ms, 0.5), engine::percentile(r.offset_ms, 0.99), 100.0 * r.within_one_frame);
  std::printf("video frames shown %zu, skipped %zu, repeated %zu; the renderer waited on a decoder %zu times\n", r.shown,
              r.skipped, r.repeated, r.waits);
  std::printf("upload on the render thread: p50 %.3f ms, p99 %.3f ms (%zu uploads)\n", frames.upload_p50_ms, frames.upload_p99_ms,
              frames.uploads);
  std::printf("targets in step: offsets within one frame differ by at most %.2f ms\n", r.in_step_ms_max);
  std::printf("memory (RSS): %.0f MB at the start, %.0f MB at the end\n", r.rss_start_mb, r.rss_end_mb);
}

}  // namespace

const Command kBenchContent{
    "bench content",
    "benchmark moving content (video on the targets): decode, upload, and content time against display time",
    "projbot bench content [--scene S.yaml] [--seconds N] [--report FILE.json] [--out FILE.png]\n\n"
    "Draws the scene's targets at their `pose:` offscreen at the projector's refresh (paced like vsync) for\n"
    "N seconds (default 10), each target with `content:` showing its video at the frame's display time (one\n"
    "frame period after the frame starts; every start counts from the run's start). Prints what the render\n"
    "thread paid to upload video frames, the content time less the presentation time of the frame shown\n"
    "(within one video frame is in time), frames skipped (decoded but their time had passed) and repeated\n"
    "(the due frame was not decoded yet), how often the renderer waited on a decoder's queue, how far\n"
    "targets drawn together were apart, and memory at the start and end. Without --scene,\n"
    "assets/scenes/content.yaml (its video, a 1920x1080 H.264 clip whose frames show their own number, is\n"
    "made by the build). --out writes the last frame drawn. Ctrl-C prints and reports what was measured.\n",
    {{"scene", "FILE", "scene whose targets carry content (default: assets/scenes/content.yaml)", cli::PathRole::input_file},
     {"seconds", "N", "how long to draw (default 10)"},
     {"device", "N", "Vulkan physical device index (default: best available)"},
     {"report", "FILE", "JSON report of the figures", cli::PathRole::output_file},
     {"out", "FILE.png", "write the last frame drawn (what the projector showed)", cli::PathRole::output_file}},
    [](const cli::Args& args) {
      const double seconds = args.get_double("seconds", 10.0);
      if (!(seconds >= 0.1 && seconds <= 86400.0)) throw cli::UsageError("--seconds must be 0.1..86400");
      const config::Scene scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "content.yaml").string()));
      if (std::none_of(scene.targets.begin(), scene.targets.end(), [](const auto& t) { return t.content.has_value(); }))
        throw config::ConfigError(scene.source.string() + ": no target has `content:` to play");
      engine::RendererOptions ro;
      ro.device_index = args.get_int("device", -1, -1, 64);
      engine::Renderer renderer(ro);
      std::cout << "device: " << renderer.device_info().name << std::endl;
      std::vector<assets::Model> models;
      const auto items = engine::upload_scene(renderer, scene, &models);
      engine::SceneContent content(renderer, scene, models, items);
      for (int i = 0; i < static_cast<int>(scene.targets.size()); ++i)
        if (content.has_video(i)) {
          const auto& info = content.player(i).info();
          std::printf("%s: %s, %dx%d %s at %.2f fps\n", scene.targets[static_cast<std::size_t>(i)].name.c_str(),
                      content.player(i).name().c_str(), info.width, info.height, info.codec.c_str(), info.fps);
        }
      auto target = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
      catch_interrupts();
      engine::FrameProfiler profiler;
      const ContentRun run = run_content(renderer, *target, scene, items, content, seconds, profiler);
      const engine::FrameSummary frames = profiler.summary();
      print(run, frames);
      if (const auto out = args.get("out")) assets::write_png(*out, target->read_back());
      for (const std::string& e : content.take_errors()) std::cerr << "content: " << e << '\n';
      if (const auto file = args.get("report")) write_report(*file, run, frames);
      if (run.interrupted) return benchmark_interrupted("while drawing (the figures above are those measured)");
      return 0;
    }};

}  // namespace projbot::tools
