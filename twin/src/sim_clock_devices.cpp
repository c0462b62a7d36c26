#include "sim_clock_devices.hpp"

#include <algorithm>
#include <utility>

#include "projbot/alignment/depth.hpp"

namespace projbot::twin {

using Clock = std::chrono::steady_clock;

Acquired acquire(TourMode mode, alignment::TargetFollower& follower, const Twin& twin, const alignment::DepthImage& depth,
                 const Eigen::Matrix4d& T_init, const alignment::Footing& footing, const assets::Image* colour) {
  const auto t0 = Clock::now();
  Acquired r;
  r.icp.T_scan_model = T_init;  // too little in view: nothing to align
  r.icp.converged = false;
  if (mode == TourMode::tracking) {
    follower.set_initial_guess(T_init, footing);
    const auto sample = follower.step(depth, colour);
    if (follower.last_attempt()) r.icp = *follower.last_attempt();
    if (sample && !sample->lost) r.icp.T_scan_model = sample->T_camera_target;  // colour may have moved it
    r.icp.colour_shift_mm = follower.search_stats().colour_shift_mm;
    r.icp.colour_agreement = follower.search_stats().colour_agreement;
    if (sample && !sample->lost && !follower.last_attempt()) {  // the projective tracker found it from the guess
      r.icp.T_scan_model = sample->T_camera_target;
      r.icp.converged = true;
      r.icp.inlier_ratio = sample->inlier_ratio;
      r.icp.rmse_mm = sample->rmse_mm;
    }
    r.free_space = follower.last_check();
    r.projected = sample && !sample->lost;
  } else {
    try {
      // Ours leaves out the floor (known from the map and where the robot believes its camera is) and
      // what lies outside the guess's silhouette, and takes only a pose that stands as surveyed; the
      // paper's set-up aligns to everything near the guess.
      r.icp = mode == TourMode::localized ? follower.acquire(depth, T_init, footing, follower.silhouette_grow_m(), colour)
                                          : follower.aligner().align(alignment::depth_to_cloud(depth, twin.camera()), T_init);
    } catch (const alignment::AlignmentError&) {
    }
    // Ours also checks the estimate against free space; the paper's set-up projects whatever ICP gives.
    r.free_space = follower.verify(depth, r.icp.T_scan_model);
    if (mode == TourMode::localized && !follower.passes(r.free_space)) r.icp.converged = false;
    r.projected = mode == TourMode::odometry || r.icp.converged;
  }
  r.align_ms = ms_since(t0);
  return r;
}

void SimClockTracker::set_initial_guess(const Eigen::Matrix4d& T_camera_target, const alignment::Footing& footing,
                                        std::shared_ptr<const assets::Image> colour) {
  start_ = Start{T_camera_target, footing, std::move(colour)};
  acquired_ = Acquired{};
  in_flight_.clear();
  free_s_ = track_ms_ = 0.0;
  tracked_ = 0;
}

std::optional<alignment::PoseSample> SimClockTracker::track(std::shared_ptr<const alignment::DepthImage> frame) {
  if (start_) {
    acquired_ = acquire(mode_, follower_, twin_, *frame, start_->T_camera_target, start_->footing, start_->colour.get());
    start_.reset();
    alignment::PoseSample s;
    s.T_camera_target = s.motion.T = acquired_.icp.T_scan_model;
    s.lost = !acquired_.projected;
    return s;
  }
  const double t_k = frame->capture_time_s;
  // Not rendered (nothing is tracked in this mode, or every tracker was busy), or this one is still busy
  // when the next frame comes: dropped.
  if (frame->width == 0 || free_s_ > t_k + 1.0 / kCameraHz) return std::nullopt;
  const auto t0 = Clock::now();
  InFlight f{follower_.step(*frame), 0.0};
  const double step_ms = ms_since(t0);
  track_ms_ += step_ms;
  ++tracked_;
  const double start_s = std::max(free_s_, t_k + (clock_.processing_ms ? 0.0 : 1e-3 * clock_.capture_ms));
  f.ready_s = free_s_ = start_s + 1e-3 * clock_.processing_ms.value_or(step_ms);
  in_flight_.push_back(f);
  return f.sample;
}

std::vector<alignment::PoseSample> SimClockTracker::ready_by(double t_s) {
  std::vector<alignment::PoseSample> out;
  while (!in_flight_.empty() && in_flight_.front().ready_s <= t_s + 1e-9) {
    if (in_flight_.front().sample) out.push_back(*in_flight_.front().sample);
    in_flight_.pop_front();
  }
  return out;
}

alignment::RgbdFrame TourCamera::next() {
  alignment::RgbdFrame f;
  if (arrival_) {
    arrival_ = false;
    const auto t0 = Clock::now();
    f.depth = twin_.capture(stop_.T_world_camera, stop_.noise_seed);
    arrival_ms_ = ms_since(t0);
    if (stop_.colour) f.colour = twin_.capture_colour(stop_.T_world_camera, stop_.noise_seed);
    return f;
  }
  if (!stop_.tracking) return f;  // nothing is tracked while the robot dwells: no frame is taken
  const double t_k = ++frames_ / kCameraHz;
  f.depth.capture_time_s = t_k;
  TwinTarget& target = twin_.targets()[stop_.target];
  target.T_world_target_true = twin_.scripted_pose(stop_.target, stop_.target_visit, t_k);
  target.in_world = twin_.scripted_presence(stop_.target, stop_.target_visit, t_k);
  if (!target.in_world && stop_.present && gone_s_ < 0.0) gone_s_ = t_k;
  if (!stop_.wanted(t_k + 1.0 / kCameraHz)) return f;
  const auto t0 = Clock::now();
  f.depth = twin_.capture(stop_.T_world_camera, stop_.noise_seed + static_cast<std::uint32_t>(frames_));
  f.depth.capture_time_s = t_k;  // the exposure, on the simulated clock
  clock_.capture_ms = ms_since(t0);
  return f;
}
}  // namespace projbot::twin
