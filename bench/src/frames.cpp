#include "projbot/bench/frames.hpp"

#include <cmath>
#include <fstream>
#include <string>

#include "projbot/config/clock.hpp"

namespace projbot::bench {
namespace {

double rss_mb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
  return std::nan("");
}

}  // namespace

config::ProjectorConfig typical_projector(int w, int h) {
  config::ProjectorConfig p;
  p.width_px = w;
  p.height_px = h;
  p.fx_px = p.fy_px = 1.1 * w;  // about a 48 degree horizontal field, a typical projector
  p.cx_px = (w - 1) / 2.0;
  p.cy_px = (h - 1) / 2.0;
  return p;
}

engine::FrameSummary measure_render(engine::Renderer& renderer, const config::ProjectorConfig& projector,
                                    const std::vector<engine::DrawItem>& items, bool windowed, int frames,
                                    const std::function<bool()>& keep_going) {
  std::unique_ptr<engine::RenderTarget> target;
  if (windowed) {
    engine::WindowOptions wo;
    wo.width_px = projector.width_px;
    wo.height_px = projector.height_px;
    wo.title = "projbot bench";
    wo.present_mode = engine::PresentMode::kImmediate;
    target = renderer.make_window(wo);
  } else {
    target = renderer.make_offscreen(projector.width_px, projector.height_px);
  }
  for (int i = 0; i < 20 && keep_going(); ++i) {
    target->poll_close();
    renderer.draw_frame(*target, projector, items);
  }
  renderer.finish(*target);
  engine::FrameProfiler profiler;
  for (int i = 0; i < frames && keep_going(); ++i) {
    target->poll_close();
    renderer.draw_frame(*target, projector, items, &profiler);
  }
  renderer.finish(*target);
  return profiler.summary();
}

ContentRun run_content(engine::Renderer& renderer, engine::RenderTarget& target, const config::Scene& scene,
                       const std::vector<engine::DrawItem>& items, engine::SceneContent& content, double seconds,
                       engine::FrameProfiler& profiler, const std::function<bool()>& keep_going) {
  ContentRun run;
  run.rss_start_mb = rss_mb();
  const double period_s = 1.0 / scene.projector.refresh_hz;
  const double t0 = config::steady_now_s();
  const config::Clock clock = config::Clock::steady();
  double next_s = t0;
  std::size_t within = 0;
  while (keep_going() && config::steady_now_s() - t0 < seconds) {
    clock.pace(next_s, period_s);
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
  run.interrupted = !keep_going();
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

}  // namespace projbot::bench
