#pragma once
// The tracker worker: a std::jthread that takes the newest depth frame (older ones are dropped, never
// queued), tracks the target from its last pose (acquires it when lost or not yet found), and publishes
// the newest accepted pose. Any thread may submit frames and initial guesses; one reader thread (the
// render thread) reads poses, without ever blocking.

#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "projbot/alignment/latest_value.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker.hpp"

namespace projbot::alignment {

struct WorkerConfig {
  AcquisitionConfig acquisition;
  TrackerConfig tracking;
  /// Consecutive frames in which neither tracking nor re-acquisition (from the last pose, on the same
  /// frame) found the target, after which it is reported lost.
  int lost_after = 5;
};

/// What the render thread reads: the newest accepted pose, or the news that the target is lost.
struct PoseSample {
  Eigen::Matrix4d T_camera_target = Eigen::Matrix4d::Identity();
  std::uint64_t sequence = 0;   ///< increases with every publication
  double capture_time_s = 0.0;  ///< capture time of the depth frame the pose came from
  bool lost = true;             ///< true: blank the target, do not project
  double inlier_ratio = 0.0;
  double rmse_mm = 0.0;
};

/// The worker's policy for one frame, without the thread: track from the last pose; when tracking
/// fails, acquire on the same frame from where the target was last seen; after `lost_after` frames in
/// which neither found it, report it lost. The twin's tour runs it in simulated time. Not thread-safe.
class TargetFollower {
 public:
  /// Throws AlignmentError for a bad model or intrinsics.
  TargetFollower(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config = {});
  /// A new stop: the next frame acquires from this guess (Eq. 1).
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target);
  /// The target was already acquired at T_camera_target: the next frame tracks from there.
  void set_pose(const Eigen::Matrix4d& T_camera_target);
  /// One frame: the sample to publish (sequence left 0), or nothing when there is no guess yet or the
  /// frame was rejected without the target being lost yet.
  std::optional<PoseSample> step(const DepthImage& frame);
  /// The tracked pose, or the guess while acquiring.
  Eigen::Matrix4d last_pose() const { return pose_.value_or(guess_); }
  const Aligner& aligner() const { return aligner_; }

 private:
  Aligner aligner_;
  ProjectiveTracker tracker_;
  CameraIntrinsics k_;
  WorkerConfig cfg_;
  std::optional<Eigen::Matrix4d> pose_;  // tracked pose; empty while acquiring
  Eigen::Matrix4d guess_ = Eigen::Matrix4d::Identity();
  bool have_guess_ = false;
  int rejected_ = 0;
};

class TrackerWorker {
 public:
  /// Starts the worker thread. Throws AlignmentError for a bad model or intrinsics.
  TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config = {});
  /// Stops the worker promptly (within one tracking step) and joins it.
  ~TrackerWorker();
  TrackerWorker(const TrackerWorker&) = delete;
  TrackerWorker& operator=(const TrackerWorker&) = delete;

  /// A new depth frame (from the sensor thread). Replaces any frame not yet taken.
  void submit(std::shared_ptr<const DepthImage> frame);
  /// The stop's initial guess (Eq. 1): the next frame acquires from it.
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target);
  /// The newest published sample (reader thread only); false before the first.
  bool latest(PoseSample& out) { return poses_.read(out); }
  /// Frames taken and processed so far (for tests and statistics).
  std::uint64_t frames_processed() const { return processed_.load(); }
  /// An exception the worker thread died of, if any; the worker publishes `lost` before it stops.
  std::exception_ptr error() const;

 private:
  void run(std::stop_token stop);

  TargetFollower follower_;  // used by the worker thread only
  LatestValue<PoseSample> poses_;
  std::atomic<std::uint64_t> processed_{0};

  mutable std::mutex mutex_;  // guards the inbox below, not the pose hand-off
  std::condition_variable_any wake_;
  std::shared_ptr<const DepthImage> inbox_;
  std::optional<Eigen::Matrix4d> guess_;
  std::exception_ptr error_;
  std::jthread thread_;  // last: started after everything it uses exists, stopped first
};

}  // namespace projbot::alignment
