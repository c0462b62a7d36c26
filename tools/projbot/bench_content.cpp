// projbot bench content: moving content on the targets (issue 44), drawn offscreen at the projector's
// refresh for a while: what decoding and uploading cost the render thread, and whether each frame shows the
// content of its own display time.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/bench/frames.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/engine/content.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

nlohmann::json finite(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

void write_report(const std::filesystem::path& file, const bench::ContentRun& r, const engine::FrameSummary& frames) {
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

void print(const bench::ContentRun& r, const engine::FrameSummary& frames) {
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
      if (!args.get("scene")) check_made_video(scene);
      check_scene_outputs(args, scene);
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
      const bench::ContentRun run =
          bench::run_content(renderer, *target, scene, items, content, seconds, profiler, [] { return !interrupted(); });
      const engine::FrameSummary frames = profiler.summary();
      print(run, frames);
      if (const auto out = args.get("out")) assets::write_png(*out, target->read_back());
      for (const std::string& e : content.take_errors()) std::cerr << "content: " << e << '\n';
      if (const auto file = args.get("report")) write_report(*file, run, frames);
      if (run.interrupted) return benchmark_interrupted("while drawing (the figures above are those measured)");
      return 0;
    }};

}  // namespace projbot::tools
