#include "projbot/live/projection_frames.hpp"

#include <algorithm>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/motion_model.hpp"

namespace projbot::live {

void PresentCadence::frame_started(double t_s) {
  if (last_s_ > 0.0) intervals_.push_back(t_s - last_s_);
  if (intervals_.size() > 31) intervals_.pop_front();
  last_s_ = t_s;
}

double PresentCadence::period_s(double configured_s) const {
  if (intervals_.size() < 10) return configured_s;
  std::vector<double> sorted(intervals_.begin(), intervals_.end());
  std::sort(sorted.begin(), sorted.end());
  const std::size_t n = sorted.size();  // the median, halfway between the middle two of an even count
  return n % 2 == 1 ? sorted[n / 2] : 0.5 * (sorted[n / 2 - 1] + sorted[n / 2]);
}

std::vector<DrawnPose> ProjectionFrames::compose(double now_s, const LitNow& lit, const PoseSource& poses) {
  std::vector<DrawnPose> drawn;
  const double display_s = display_time_s(now_s);
  if (cfg_.silent_camera_s > 0.0 && !lit.targets.empty() && now_s - lit.last_frame_s > cfg_.silent_camera_s) {
    ++silent_;                // the camera has gone quiet: blank rather than show what it saw last...
    stale_before_s_ = now_s;  // ...and, once it is back, only what it sees from then on
    return drawn;
  }
  for (const int target : lit.targets) {
    alignment::PoseSample pose;
    if (!poses(target, pose) || !pose.drawable() || pose.capture_time_s < std::max(lit.since_s, stale_before_s_)) continue;
    if (cfg_.max_unconfirmed_s > 0.0 && lit.last_frame_s - pose.capture_time_s > cfg_.max_unconfirmed_s) {
      ++unconfirmed_;
      continue;
    }
    DrawnPose d;
    d.target = target;
    d.capture_s = pose.capture_time_s;
    d.display_s = display_s;
    d.T_camera_target = cfg_.predict ? alignment::predict_pose(pose.motion, display_s) : pose.T_camera_target;
    d.T_projector_target = alignment::projector_from_target(cfg_.T_projector_camera, d.T_camera_target);  // Eq. 2
    d.quality = pose.inlier_ratio;
    drawn.push_back(d);
  }
  return drawn;
}

}  // namespace projbot::live
