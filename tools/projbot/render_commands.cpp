// projbot render | show | bench render: the projector pass, offscreen or in a window.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

engine::RendererOptions renderer_options(const cli::Args& args, bool windowing) {
  engine::RendererOptions o;
  o.validation = args.flag("validation");
  o.windowing = windowing;
  o.device_index = args.get_int("device", -1, -1, 64);
  return o;
}

// Prints validation results and returns false when the layer reported anything.
bool report_validation(const cli::Args& args, const engine::Renderer& renderer) {
  if (!args.flag("validation")) return true;
  std::cout << "validation: " << renderer.validation_errors() << " errors, " << renderer.validation_warnings() << " warnings\n";
  return renderer.validation_errors() == 0 && renderer.validation_warnings() == 0;
}

void finish_profile(const cli::Args& args, const engine::FrameProfiler& profiler) {
  std::cout << engine::format_summary(profiler.summary()) << '\n';
  if (const auto csv = args.get("profile")) {
    profiler.write_csv(*csv);
    std::cout << "per-frame profile written to " << *csv << '\n';
  }
}

// A still frame's content: each target's video frame and timeline at content time `at_s`. Offline, so it
// waits for the decoder to reach the frame of that time (a clip that does not loop holds its last frame).
void content_at(engine::SceneContent& content, std::vector<engine::DrawItem>& items, double at_s) {
  content.set_exact(true);
  for (int i = 0; i < static_cast<int>(items.size()); ++i) content.apply(i, at_s, items[static_cast<std::size_t>(i)]);
}

}  // namespace

const Command kRender{
    "render", "render the projector image headless (offscreen) to a PNG",
    "projbot render [--scene S.yaml] --out frame.png [--frames N] [--profile p.csv] [overrides]\n\n"
    "Draws every target of the scene through the projector's intrinsics, with no window system, and\n"
    "writes the last frame as an RGBA PNG: exactly the image the projector must show. With --model\n"
    "alone the model is framed whole, seen from its front (glTF +Z). Targets with `content:` show their\n"
    "video's frame and timeline at --content-time (default 0 s). Exit status 3: the frame came out empty\n"
    "(written all the same).\n",
    with_scene_options({{"out", "FILE", "PNG to write (required)", cli::PathRole::output_file},
                        {"content-time", "S", "content time of the targets' videos and timelines, seconds (default 0)"},
                        {"frames", "N", "frames to draw, for timing (default 1)"},
                        {"profile", "FILE", "write one CSV row of timings per frame", cli::PathRole::output_file}}),
    [](const cli::Args& args) {
      const auto out = args.get("out");
      if (!out) throw cli::UsageError("--out FILE is required");
      if (std::filesystem::path(*out).extension() != ".png" && std::filesystem::path(*out).extension() != ".PNG")
        throw cli::UsageError("--out must name a .png file, got '" + *out + "'");
      const int frames = args.get_int("frames", 1, 1, 1000000);
      const config::Scene scene = scene_from_args(args);
      engine::Renderer renderer(renderer_options(args, false));
      std::cout << "device: " << renderer.device_info().name << '\n';
      const double content_time = args.get_double("content-time", 0.0);
      if (!(content_time >= 0.0 && content_time <= 1e6)) throw cli::UsageError("--content-time must be 0..1e6 seconds");
      std::vector<assets::Model> models;
      auto items = engine::upload_scene(renderer, scene, &models);
      engine::SceneContent content(renderer, scene, models, items);
      content_at(content, items, content_time);
      auto target = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
      engine::FrameProfiler profiler;
      for (int i = 0; i < frames; ++i) renderer.draw_frame(*target, scene.projector, items, &profiler);
      renderer.finish(*target);
      const assets::Image image = target->read_back();
      assets::write_png(*out, image);
      std::cout << "wrote " << *out << " (" << scene.projector.width_px << "x" << scene.projector.height_px << ", "
                << scene.targets.size() << " target" << (scene.targets.size() == 1 ? "" : "s") << ")\n";
      finish_profile(args, profiler);
      if (!report_validation(args, renderer)) return 1;
      if (image.lit_pixels() == 0) {  // "targets: []" too: a black frame is never a silent success
        std::cerr << "projbot render: warning: the frame is empty: "
                  << (scene.targets.empty() ? "the scene has no targets"
                                            : "no target is in the projector's view (check the poses, --near / --far and "
                                              "the intrinsics)")
                  << '\n';
        return 3;
      }
      return 0;
    }};

const Command kShow{
    "show", "open the projector output in a window (fullscreen on a projector, or a preview)",
    "projbot show [--scene S.yaml] [--fullscreen] [--monitor N] [--present-mode fifo|mailbox|immediate]\n\n"
    "Opens a window showing the projector image and redraws it every frame until the window is closed\n"
    "(or --frames have been drawn). Without --fullscreen the window has the projector's size. Targets with\n"
    "`content:` or animated materials play them from the moment the window opens; a model, texture or\n"
    "video changed on disk is drawn anew within a second. Ctrl-C closes it at the next frame, and what was\n"
    "measured is printed and written (exit 130).\n",
    with_scene_options({{"fullscreen", "", "fullscreen on --monitor (the projector)"},
                        {"monitor", "N", "monitor index for --fullscreen (default 0)"},
                        {"present-mode", "MODE", "fifo (default, vsync), mailbox or immediate"},
                        {"frames", "N", "close after N frames (default: run until closed)"},
                        {"profile", "FILE", "write one CSV row of timings per frame", cli::PathRole::output_file}}),
    [](const cli::Args& args) {
      catch_interrupts();  // Ctrl-C / SIGTERM: close at the next frame, then write what was measured
      const config::Scene scene = scene_from_args(args);
      const int frames = args.get_int("frames", 0, 0, 100000000);
      const engine::WindowOptions w = window_options(
          args, scene.projector, "projbot: " + (scene.source.empty() ? std::string("model") : scene.source.filename().string()));
      engine::Renderer renderer(renderer_options(args, true));
      std::cout << "device: " << renderer.device_info().name << std::endl;  // said at once: the window comes next
      std::vector<assets::Model> models;
      const auto items = engine::upload_scene(renderer, scene, &models);
      engine::SceneContent content(renderer, scene, models, items);  // the targets' videos and animations, previewed
      auto window = open_window(renderer, w, scene.projector);
      if (interrupted()) return nothing_written("before the window opened");
      engine::FrameProfiler profiler;
      int drawn = 0;
      const double t0 = config::steady_now_s();  // every content start (arrival, tour) is the window's opening
      const auto read = [&](std::vector<engine::DrawItem>& out) {
        out.assign(items.begin(), items.end());
        const double now = config::steady_now_s();
        for (int i = 0; i < static_cast<int>(items.size()); ++i)
          if (content.has(i)) content.apply(i, now - content.start_s(i, t0, t0), out[static_cast<std::size_t>(i)]);
      };
      while (!window->poll_close() && (frames == 0 || drawn < frames) && !interrupted()) {
        if (renderer.draw_frame(*window, scene.projector, read, &profiler)) ++drawn;
        for (const std::string& e : content.reload_changed(config::steady_now_s()))  // a texture or video edited
          std::cout << "content: " << e << '\n';
      }
      renderer.finish(*window);
      finish_profile(args, profiler);
      const bool clean = report_validation(args, renderer);
      if (interrupted()) return interrupt_exit_code();
      return clean ? 0 : 1;
    }};

}  // namespace projbot::tools
