#pragma once
// The projection loop (`run`, `run --replay`, the twin's `tour` and `bench motion`): every projector frame
// draws each lit target at its newest accepted pose, moved on to the frame's display time
// (ProjectionFrames: Eq. 2), with its content and compensation, or a blank frame; and measures it (the
// pose's age at display, the display error where a truth is known). `run` paces the frames on its clock
// and draws them; the tour steps them one by one on its simulated clock (`frame`) and measures them
// without drawing. Times are seconds on the loop's clock; rows' times are the frame profiler's ms (the
// clock's, from the start, without one). The robot's state, the poses and the truth come in through callbacks.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "projbot/config/clock.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/projection_frames.hpp"

namespace projbot::live {

/// The stop as the robot thread last published it.
struct LitStop {
  std::vector<int> targets;  ///< lit targets, scene indices, the visited one first
  double since_s = 0.0;      ///< the stop began: poses captured before are an earlier stop's
  int visit = 0;             ///< the visit (a target's compensation gain is chosen once per visit)
};

/// A drawn target's error against a truth at its display time: the mean marker error (mm; NaN where
/// it is not measured) and whether the target was moving then.
struct DisplayError {
  double error_mm = 0.0;
  bool moving = false;
};
using DisplayMeter = std::function<DisplayError(const DrawnPose& drawn)>;

/// One frame: start (profiler ms), the first drawn target's pose age (capture to expected display, ms;
/// -1 for a blank frame), its capture and display times (profiler ms, NaN blank) and error (mm, NaN).
struct ProjectionRow {
  double start_ms = 0.0, age_ms = -1.0, capture_ms = 0.0, display_ms = 0.0, error_mm = 0.0;
  int target = -1;       ///< scene index of the first drawn target; -1: blank
  double clock_s = 0.0;  ///< the frame's start on the loop's clock since the loop began (a replay: the recording's)
  /// The first drawn target's content time and the presentation time of its video's frame shown (s; NaN:
  /// none), and where it was drawn: its origin in the projector's frame (mm; NaN blank).
  double content_s = 0.0, video_pts_s = 0.0;
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();
};

/// What the loop measured.
struct ProjectionFigures {
  std::vector<ProjectionRow> rows;          ///< one per frame drawn
  std::vector<double> ages_ms;              ///< pose age at display, frames with a target
  std::vector<double> moving_mm, still_mm;  ///< display errors, per drawn target and frame, where measured
  std::vector<double> content_offsets_ms;   ///< per target-frame with video: its content time less the shown frame's
  std::size_t blank = 0;                    ///< frames with no target drawn (not counting `uniform` ones)
  std::size_t uniform = 0;                  ///< frames that showed ProjectionInputs::uniform's colour instead
  std::size_t with_neighbours = 0;          ///< frames that drew more than one target
};

struct ProjectionLoopConfig {
  ProjectionConfig projection;
  double seconds = 0.0;   ///< stop after this long on the loop's clock; 0: until `keep_going` says no
  double paced_hz = 0.0;  ///< offscreen: frames paced at this rate (no vsync to pace them); 0: the target paces
};

/// One frame as it was decided: the targets drawn (empty: blank), its start and expected display time (s).
struct DecidedFrame {
  std::vector<DrawnPose> drawn;
  double start_s = 0.0, display_s = 0.0;
  bool uniform = false;  ///< ProjectionInputs::uniform's colour was shown instead of the targets
};

/// What the loop reads and calls each frame. `stop` and `poses` are needed; `camera_last_s` where the
/// projection watches for a silent camera, `keep_going` for `run`.
struct ProjectionInputs {
  std::function<LitStop()> stop;                         ///< the robot's newest state, read once per frame
  PoseSource poses;                                      ///< each target's newest accepted pose
  std::function<double()> camera_last_s;                 ///< the camera's newest hand-off to the trackers
  std::function<bool()> keep_going;                      ///< asked before each frame
  DisplayMeter meter;                                    ///< empty: nothing measured against a truth
  std::function<void(const DecidedFrame&)> after_frame;  ///< after each frame is decided and drawn, before it is measured
  /// A colour (8-bit levels) to show over the whole image instead of the targets (a reflectance measured
  /// at a stop: the projector's black, then its mid grey); nullopt or empty: the targets. Read once per frame.
  std::function<std::optional<std::array<std::uint8_t, 3>>()> uniform;
  /// Offscreen pacing (paced_hz): sleeps until `until_s` on the loop's clock, or less when something must
  /// be shown at once (an operator's blackout), saying so with true; empty: the clock's own sleep.
  std::function<bool(double until_s)> pace_sleep;
};

/// The render thread's loop. Not thread-safe: one owner, the thread that owns the renderer.
class ProjectionLoop {
 public:
  /// `items[i]` draws scene target i (its model). `plan` and `content` may be null (no compensation, no
  /// content); they and the renderer must outlive the loop.
  ProjectionLoop(engine::Renderer& renderer, const config::ProjectorConfig& projector, std::vector<engine::DrawItem> items,
                 ProjectionLoopConfig config, config::Clock clock = config::Clock::steady());
  void set_compensation(engine::CompensationPlan* plan) { plan_ = plan; }
  void set_content(engine::SceneContent* content) { content_ = content; }
  /// Draws frames into `target` until `in.keep_going` says no, `seconds` have passed or the target is
  /// closed; what was measured.
  ProjectionFigures run(engine::RenderTarget& target, const ProjectionInputs& in, engine::FrameProfiler& profiler);
  /// Stepping the loop by hand: `begin` starts a run at the clock's now (figures cleared); each `frame`
  /// is one projector frame starting at the clock's now, decided, drawn into `target` (null: not drawn)
  /// and measured; nullopt when the target had no image to draw into. `figures` are those so far.
  void begin();
  std::optional<DecidedFrame> frame(engine::RenderTarget* target, const ProjectionInputs& in, engine::FrameProfiler* profiler);
  const ProjectionFigures& figures() const { return figures_; }
  /// When the run (or begin) started, on the loop's clock.
  double started_s() const { return t0_s_; }
  /// Frames blanked because the camera was silent.
  std::size_t silent_frames() const { return frames_.silent_frames(); }

 private:
  std::vector<DrawnPose> decide(const LitStop& stop, const ProjectionInputs& in, double now_s);
  void pace(double& next_s, const ProjectionInputs& in);
  void compose(const LitStop& stop, const ProjectionInputs& in, std::vector<engine::DrawItem>& out,
               std::vector<DrawnPose>& drawn);
  void measure(const std::vector<DrawnPose>& drawn, const DisplayMeter& meter, double start_ms, double start_s, bool uniform);
  engine::SceneContent::Sample first_content_;  // the first drawn target's, this frame

  engine::Renderer& renderer_;
  const config::ProjectorConfig& projector_;
  std::vector<engine::DrawItem> items_;
  ProjectionLoopConfig cfg_;
  config::Clock clock_;
  ProjectionFrames frames_;
  engine::CompensationPlan* plan_ = nullptr;
  engine::SceneContent* content_ = nullptr;
  double t0_s_ = 0.0;
  double decided_s_ = 0.0;  // when this frame's poses were read
  ProjectionFigures figures_;
};

}  // namespace projbot::live
