#pragma once
// What drawing costs (`projbot bench render`, `projbot bench content`): frame-time percentiles of the
// projector pass, and moving content drawn at the projector's refresh, each frame's content against its
// display time. Times in ms unless named otherwise.

#include <cstddef>
#include <functional>
#include <vector>

#include "projbot/config/scene.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::bench {

/// A projector of `w` x `h` pixels with about a 48 degree horizontal field (a typical one), principal
/// point at the image's centre.
config::ProjectorConfig typical_projector(int w, int h);

/// 20 warm-up frames, then `frames` measured ones of `items` (fewer when `keep_going` says no), into a
/// window (IMMEDIATE present mode where offered) or offscreen at the projector's size.
engine::FrameSummary measure_render(engine::Renderer& renderer, const config::ProjectorConfig& projector,
                                    const std::vector<engine::DrawItem>& items, bool windowed, int frames,
                                    const std::function<bool()>& keep_going);

struct ContentRun {
  std::size_t frames = 0;
  std::vector<double> offset_ms;  ///< per target-frame: content time less the shown frame's presentation time
  double in_step_ms_max = 0.0;    ///< the largest spread of that offset between targets within one frame
  double within_one_frame = 0.0;  ///< share of target-frames whose offset is under one video frame
  std::size_t waits = 0, repeated = 0, skipped = 0, shown = 0;  ///< the players' counts
  double rss_start_mb = 0.0, rss_end_mb = 0.0, seconds = 0.0;   ///< the process's resident memory, the run's length
  bool interrupted = false;                                     ///< `keep_going` ended it
};

/// Draws every target at its scene pose into `target` for `seconds`, paced like a projector at its refresh
/// (an offscreen target has no vsync), each target's content sampled at the frame's display time (one
/// period ahead). The renderer's frame times go to `profiler`.
ContentRun run_content(engine::Renderer& renderer, engine::RenderTarget& target, const config::Scene& scene,
                       const std::vector<engine::DrawItem>& items, engine::SceneContent& content, double seconds,
                       engine::FrameProfiler& profiler, const std::function<bool()>& keep_going);

}  // namespace projbot::bench
