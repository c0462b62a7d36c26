#pragma once
// What each projector frame draws (the live loop's decision, without the window or the renderer): every
// lit target at its newest accepted pose, moved on to the frame's display time by its measured motion,
// through Eq. 2 into the projector's frame; a target not found yet, lost, or seen only before the stop
// began is blanked on its own, and every target while the camera is silent. Times are seconds on one
// steady clock (config::steady_now_s in `run`, the simulated clock in the twin's tour; any clock in a test).

#include <Eigen/Core>
#include <cstddef>
#include <deque>
#include <functional>
#include <vector>

#include "projbot/alignment/tracker_worker.hpp"

namespace projbot::live {

/// The projector's frame period as the loop sees it: the median interval between the last 31 frame
/// starts (vsync paces them in FIFO mode); the configured period until 10 intervals have run.
class PresentCadence {
 public:
  void frame_started(double t_s);
  double period_s(double configured_s) const;

 private:
  std::deque<double> intervals_;
  double last_s_ = 0.0;
};

struct ProjectionConfig {
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  ///< R_cp, T_cp (Eq. 2)
  double refresh_hz = 60.0;                                          ///< the projector's configured refresh
  double input_lag_ms = 0.0;  ///< the projector's input lag: light leaves it this long after the frame is presented
  bool predict = true;        ///< draw each pose moved on to the display time (else as measured)
  /// A live camera that has handed over no frame for this long blanks every target: what it saw last may
  /// no longer be there; once it is back, only poses captured from then on are drawn. 0: not watched (a
  /// replay, whose frames play in lockstep).
  double silent_camera_s = 0.1;
  /// A target whose newest pose comes from a frame this much older than the camera's newest hand-off (or,
  /// with no camera watched, than the frame's start) is blanked: the tracker has not confirmed it on the
  /// frames since (it is busy on a rescue or a search) and what it showed may be off by then. Three frames
  /// of a 30 Hz camera: under the fitted depth model the shop figure's held poses were lit up to 0.4 m off
  /// while its tracker was busy for half a second. 0: not watched.
  double max_unconfirmed_s = 0.1;
};

/// One target drawn in a frame.
struct DrawnPose {
  int target = -1;                                                   ///< scene index
  double capture_s = 0;                                              ///< capture time of the depth its pose came from
  double display_s = 0;                                              ///< when the frame is expected to be lit
  Eigen::Matrix4d T_camera_target = Eigen::Matrix4d::Identity();     ///< at display_s (predicted) or as measured
  Eigen::Matrix4d T_projector_target = Eigen::Matrix4d::Identity();  ///< Eq. 2 of the above
  double quality = 0.0;                                              ///< the tracker's inlier ratio for the pose
};

/// A target's newest accepted pose (TrackerWorker::latest): false where there is none yet.
using PoseSource = std::function<bool(int target, alignment::PoseSample& out)>;

/// The lit targets of a stop, as the robot last published them.
struct LitNow {
  std::vector<int> targets;   ///< scene indices, the visited one first
  double since_s = 0.0;       ///< the stop began: poses captured before belong to an earlier one
  double last_frame_s = 0.0;  ///< the camera's newest hand-off to the trackers
};

class ProjectionFrames {
 public:
  explicit ProjectionFrames(ProjectionConfig config) : cfg_(std::move(config)) {}
  /// A projector frame starts at t_s (paces the cadence).
  void frame_started(double t_s) { cadence_.frame_started(t_s); }
  /// The targets to draw in the frame whose poses are read at now_s: displayed one measured frame
  /// period plus the input lag later (FIFO presents at the next vblank). Empty: a blank frame.
  std::vector<DrawnPose> compose(double now_s, const LitNow& lit, const PoseSource& poses);
  /// Frames blanked because the camera was silent.
  std::size_t silent_frames() const { return silent_; }
  /// Targets blanked in a frame because their pose was unconfirmed (max_unconfirmed_s), over all frames.
  std::size_t unconfirmed_blanks() const { return unconfirmed_; }
  double period_s() const { return cadence_.period_s(1.0 / cfg_.refresh_hz); }
  /// When the frame whose poses are read at now_s is expected to be lit: one measured frame period plus
  /// the projector's input lag later.
  double display_time_s(double now_s) const { return now_s + period_s() + 1e-3 * cfg_.input_lag_ms; }

 private:
  ProjectionConfig cfg_;
  PresentCadence cadence_;
  double stale_before_s_ = 0.0;
  std::size_t silent_ = 0;
  std::size_t unconfirmed_ = 0;
};

}  // namespace projbot::live
