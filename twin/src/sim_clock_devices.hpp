#pragma once
// Internal to the twin's tour: a stop's acquisition, and the camera and trackers of the tour's simulated
// clock (frames every 1/30 s of simulated time, results ready when their step would end).

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/twin/tour.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

constexpr double kCameraHz = 30.0;  ///< the twin's depth camera, on the simulated clock

using config::ms_since;  // wall milliseconds of a step

// What a stop's acquisition gave for one target: the estimate, its check against free space, whether it
// is lit, and its wall time.
struct Acquired {
  alignment::AlignmentResult icp;
  alignment::FreeSpaceCheck free_space;
  bool projected = false;
  double align_ms = 0.0;
};

// One acquisition at arrival. Odometry and localized modes: the whole acquisition once (the paper's
// one alignment per stop; odometry projects whatever it gives). Tracking mode: the follower's first
// step, the bounded start of its search, as the live engine's worker does it.
Acquired acquire(TourMode mode, alignment::TargetFollower& follower, const Twin& twin, const alignment::DepthImage& depth,
                 const Eigen::Matrix4d& T_init, const alignment::Footing& footing, const assets::Image* colour);

// A tracker result on the simulated clock: usable by projector frames that start at or after ready_s.
struct InFlight {
  std::optional<alignment::PoseSample> sample;
  double ready_s = 0.0;
};

// The tour's simulated clock as its camera and its trackers share it: how long the camera's last frame took
// to render (wall time; a tracker starts on a frame that long after its exposure, the twin's rendering
// standing in for the camera's readout), unless options.processing_ms fixes each frame's whole
// processing time.
struct SimClock {
  double capture_ms = 0.0;
  std::optional<double> processing_ms;
};

// One target's tracker worker on the tour's simulated clock: what StopSequence::visit hands a lit target's
// frames to in the tour, as `projbot run` hands them to alignment::TrackerWorker. The stop's first frame
// is its acquisition (the mode's, acquire()). Later frames (tracking mode) are tracked by the follower,
// the policy the engine's worker runs: a frame that comes while the tracker is still busy with an earlier
// one is dropped (a worker always takes the newest), and a result is ready on the simulated clock when
// its step ends: after the frame's capture, its measured wall time, or processing_ms for both together.
class SimClockTracker final : public alignment::PoseTracker {
 public:
  SimClockTracker(TourMode mode, alignment::TargetFollower& follower, const Twin& twin, const SimClock& clock)
      : mode_(mode), follower_(follower), twin_(twin), clock_(clock) {}
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target, const alignment::Footing& footing,
                         std::shared_ptr<const assets::Image> colour) override;
  std::optional<alignment::PoseSample> track(std::shared_ptr<const alignment::DepthImage> frame) override;
  // The tour runs in lockstep: a frame handed over is tracked at once, its result kept for its ready time.
  void submit(std::shared_ptr<const alignment::DepthImage> frame) override { track(std::move(frame)); }
  // Whether it takes a frame that arrives at t_s (simulated clock).
  bool free_at(double t_s) const { return free_s_ <= t_s; }
  // The results ready by t_s, oldest first.
  std::vector<alignment::PoseSample> ready_by(double t_s);
  const Acquired& acquired() const { return acquired_; }  // the stop's acquisition
  alignment::TargetFollower& follower() { return follower_; }
  double track_ms() const { return track_ms_; }  // at this stop, after the acquisition
  int tracked() const { return tracked_; }       // frames it took there

 private:
  struct Start {
    Eigen::Matrix4d T_camera_target;
    alignment::Footing footing;
    std::shared_ptr<const assets::Image> colour;
  };
  TourMode mode_;
  alignment::TargetFollower& follower_;
  const Twin& twin_;
  const SimClock& clock_;
  std::optional<Start> start_;  // set: the next frame acquires
  Acquired acquired_;
  std::deque<InFlight> in_flight_;
  double free_s_ = 0.0;  // when its current step ends
  double track_ms_ = 0.0;
  int tracked_ = 0;
};

// The twin's RGB-D camera on the tour's simulated clock, as StopSequence::visit reads one. A stop's first
// frame is the arrival's capture: depth, and the colour registered to it unless the mode is odometry
// (the paper's set-up has none). Then, in tracking mode, a frame every 1/30 s, the visited target moved
// by its motion script to the frame's instant first; it is rendered only when a lit target's tracker will
// take it (one is free before the next frame comes), else its depth is empty. In the other modes nothing
// is tracked while the robot dwells, and nothing is rendered.
class TourCamera final : public alignment::RgbdCamera {
 public:
  struct Stop {
    std::size_t target = 0;  // index into Twin::targets()
    int target_visit = 0;
    Eigen::Matrix4d T_world_camera = Eigen::Matrix4d::Identity();  // true
    std::uint32_t noise_seed = 0;                                  // the arrival's; frame k's is noise_seed + k
    bool colour = true, tracking = true;
    bool present = true;                 // the target was there at arrival
    std::function<bool(double)> wanted;  // whether a lit target's tracker takes a frame arriving at t_s
  };
  TourCamera(Twin& twin, SimClock& clock) : twin_(twin), clock_(clock) {}
  void at_stop(Stop stop) {
    stop_ = std::move(stop);
    frames_ = 0;
    arrival_ = true;
    gone_s_ = -1.0;
  }
  alignment::RgbdFrame next() override;
  int frames() const { return frames_; }             // after the arrival's
  double gone_s() const { return gone_s_; }          // capture time of the first frame without the target, -1: none
  double arrival_ms() const { return arrival_ms_; }  // wall time of the arrival's depth

 private:
  Twin& twin_;
  SimClock& clock_;
  Stop stop_;
  int frames_ = 0;
  bool arrival_ = true;
  double gone_s_ = -1.0, arrival_ms_ = 0.0;
};

}  // namespace projbot::twin
