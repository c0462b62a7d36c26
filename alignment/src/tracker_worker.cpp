#include "projbot/alignment/tracker_worker.hpp"

namespace projbot::alignment {

TargetFollower::TargetFollower(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : aligner_(model, config.acquisition),
      tracker_(std::move(model), intrinsics, config.tracking),
      k_(intrinsics),
      cfg_(std::move(config)) {}

void TargetFollower::set_initial_guess(const Eigen::Matrix4d& T_camera_target) {
  guess_ = T_camera_target;
  have_guess_ = true;
  pose_.reset();
  rejected_ = 0;
}

void TargetFollower::set_pose(const Eigen::Matrix4d& T_camera_target) {
  set_initial_guess(T_camera_target);
  pose_ = T_camera_target;
}

std::optional<PoseSample> TargetFollower::step(const DepthImage& frame) {
  if (!have_guess_ && !pose_) return std::nullopt;  // nothing to start from yet
  if (pose_) {
    const TrackResult r = tracker_.track(frame, *pose_);
    if (r.accepted) {
      pose_ = r.T_camera_target;
      rejected_ = 0;
      return PoseSample{*pose_, 0, frame.capture_time_s, false, r.inlier_ratio, r.rmse_mm};
    }
    // The target moved more than tracking follows (or the worker fell behind and frames were dropped):
    // acquire on this same frame, from where it was last seen.
    guess_ = *pose_;
  }
  const PointCloud scan = depth_to_cloud(frame, k_);
  std::optional<AlignmentResult> a;
  if (scan.finite_count() >= aligner_.config().min_points) a = aligner_.align(scan, guess_);
  if (a && a->converged) {
    pose_ = a->T_scan_model;
    rejected_ = 0;
    return PoseSample{*pose_, 0, frame.capture_time_s, false, a->inlier_ratio, a->rmse_mm};
  }
  // Neither tracking nor acquisition found it. After lost_after such frames, say so.
  const bool was_tracking = pose_.has_value();
  if (++rejected_ >= cfg_.lost_after && (was_tracking || rejected_ == cfg_.lost_after)) {
    pose_.reset();
    return PoseSample{guess_, 0, frame.capture_time_s, true, a ? a->inlier_ratio : 0.0, a ? a->rmse_mm : 0.0};
  }
  return std::nullopt;
}

TrackerWorker::TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : follower_(std::move(model), intrinsics, std::move(config)), thread_([this](std::stop_token stop) { run(stop); }) {}

TrackerWorker::~TrackerWorker() {
  thread_.request_stop();
  wake_.notify_all();
}  // jthread joins

void TrackerWorker::submit(std::shared_ptr<const DepthImage> frame) {
  {
    std::lock_guard lock(mutex_);
    inbox_ = std::move(frame);  // a frame not yet taken is dropped: only the newest matters
  }
  wake_.notify_one();
}

void TrackerWorker::set_initial_guess(const Eigen::Matrix4d& T_camera_target) {
  if (!T_camera_target.allFinite()) throw AlignmentError("initial guess is not finite");
  std::lock_guard lock(mutex_);
  guess_ = T_camera_target;
}

std::exception_ptr TrackerWorker::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void TrackerWorker::run(std::stop_token stop) {
  std::uint64_t sequence = 0;
  try {
    while (!stop.stop_requested()) {
      std::shared_ptr<const DepthImage> frame;
      {
        std::unique_lock lock(mutex_);
        if (!wake_.wait(lock, stop, [&] { return inbox_ != nullptr || guess_.has_value(); })) break;
        if (guess_) {  // a new stop: acquire afresh from Eq. 1's guess
          follower_.set_initial_guess(*guess_);
          guess_.reset();
        }
        frame = std::move(inbox_);
      }
      if (!frame) continue;
      ++processed_;
      if (auto sample = follower_.step(*frame)) {
        sample->sequence = ++sequence;
        poses_.publish(*sample);
      }
    }
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
    }
    poses_.publish({follower_.last_pose(), ++sequence, 0.0, true, 0.0, 0.0});  // the renderer blanks the target
  }
}

}  // namespace projbot::alignment
