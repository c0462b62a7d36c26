#pragma once
// The tracker worker: a std::jthread that takes the newest depth frame (older ones are dropped, never
// queued), tracks the target from its last pose (acquires it when lost or not yet found: a
// TargetFollower), and publishes the newest accepted pose. Any thread may submit frames and initial
// guesses; one reader thread (the render thread) reads poses, without ever blocking.

#include <atomic>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "projbot/alignment/latest_value.hpp"
#include "projbot/alignment/target_follower.hpp"

namespace projbot::alignment {

/// What a projection session hands a lit target's frames to (live::StopSequence::visit): the stop's initial
/// guess, then the camera's frames, each tracked in order (lockstep) or the newest taken when free (live).
/// TrackerWorker is the engine's; the twin's tour has one on its simulated clock.
class PoseTracker {
 public:
  virtual ~PoseTracker() = default;
  /// The stop's initial guess (Eq. 1), the target's surveyed footing and the colour taken on arrival
  /// (null: none): the next frame acquires from them.
  virtual void set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing,
                                 std::shared_ptr<const assets::Image> colour) = 0;
  /// Tracks `frame` before returning: the sample published for it, if any.
  virtual std::optional<PoseSample> track(std::shared_ptr<const DepthImage> frame) = 0;
  /// Hands `frame` over without waiting; a frame not yet taken is replaced.
  virtual void submit(std::shared_ptr<const DepthImage> frame) = 0;
};

class TrackerWorker final : public PoseTracker {
 public:
  /// Starts the worker thread. Throws AlignmentError for a bad model or intrinsics.
  TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config = {});
  /// Stops the worker promptly (within one tracking step) and joins it.
  ~TrackerWorker();
  TrackerWorker(const TrackerWorker&) = delete;
  TrackerWorker& operator=(const TrackerWorker&) = delete;

  /// A new depth frame (from the sensor thread). Replaces any frame not yet taken.
  void submit(std::shared_ptr<const DepthImage> frame) override;
  /// Submits `frame` and waits until the worker has tracked it, so that every frame is tracked, in order,
  /// and the same frames give the same poses (record and replay). Returns the sample published for it
  /// (none when the step published none). Rethrows what the worker died of.
  std::optional<PoseSample> track(std::shared_ptr<const DepthImage> frame) override;
  /// The stop's initial guess (Eq. 1): the next frame acquires from it.
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target);
  /// ...with what the robot knows at the stop, as the tour uses it: the target's surveyed footing (its
  /// floor left out, only poses that stand as surveyed found) and the colour image taken on arrival,
  /// before the projector lit anything, registered to the depth (null: none). The next frame's search
  /// is moved and checked by that colour (TargetFollower::step), later ones are depth alone.
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing,
                         std::shared_ptr<const assets::Image> colour) override;
  /// The newest published sample (reader thread only); false before the first.
  bool latest(PoseSample& out) { return poses_.read(out); }
  /// Frames taken and processed so far (for tests and statistics).
  std::uint64_t frames_processed() const { return processed_.load(); }
  /// An exception the worker thread died of, if any; the worker publishes `lost` before it stops.
  std::exception_ptr error() const;

 private:
  void run(std::stop_token stop);
  // Puts `frame` in the inbox (replacing one not yet taken) and wakes the worker; returns its ticket.
  std::uint64_t post(std::shared_ptr<const DepthImage> frame);

  TargetFollower follower_;  // used by the worker thread only
  LatestValue<PoseSample> poses_;
  std::atomic<std::uint64_t> processed_{0};

  mutable std::mutex mutex_;  // guards the inbox below, not the pose hand-off
  std::condition_variable_any wake_;
  std::shared_ptr<const DepthImage> inbox_;
  std::uint64_t submitted_ = 0, finished_ = 0;  // frames submitted, and the last one tracked (track())
  std::optional<PoseSample> finished_sample_;   // what that one published
  std::condition_variable done_;
  struct Start {
    Eigen::Matrix4d T_camera_target;
    std::optional<Footing> footing;
    std::shared_ptr<const assets::Image> colour;
  };
  std::optional<Start> guess_;
  std::exception_ptr error_;
  std::jthread thread_;  // last: started after everything it uses exists, stopped first
};

}  // namespace projbot::alignment
