#include "projbot/alignment/tracker_worker.hpp"

namespace projbot::alignment {

TrackerWorker::TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : aligner_(model, config.acquisition),
      tracker_(std::move(model), intrinsics, config.tracking),
      k_(intrinsics),
      cfg_(std::move(config)),
      thread_([this](std::stop_token stop) { run(stop); }) {}

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
  std::optional<Eigen::Matrix4d> pose;  // tracked pose; empty while acquiring
  Eigen::Matrix4d guess = Eigen::Matrix4d::Identity();
  bool have_guess = false;
  int rejected = 0;
  std::uint64_t sequence = 0;
  const auto publish = [&](const Eigen::Matrix4d& T, double t, bool lost, double inliers, double rmse) {
    poses_.publish({T, ++sequence, t, lost, inliers, rmse});
  };
  try {
    while (!stop.stop_requested()) {
      std::shared_ptr<const DepthImage> frame;
      {
        std::unique_lock lock(mutex_);
        if (!wake_.wait(lock, stop, [&] { return inbox_ != nullptr || guess_.has_value(); })) break;
        if (guess_) {  // a new stop: acquire afresh from Eq. 1's guess
          guess = *guess_;
          guess_.reset();
          have_guess = true;
          pose.reset();
          rejected = 0;
        }
        frame = std::move(inbox_);
      }
      if (!frame) continue;
      ++processed_;
      if (!have_guess && !pose) continue;  // nothing to start from yet
      if (pose) {
        const TrackResult r = tracker_.track(*frame, *pose);
        if (r.accepted) {
          pose = r.T_camera_target;
          rejected = 0;
          publish(*pose, frame->capture_time_s, false, r.inlier_ratio, r.rmse_mm);
          continue;
        }
        // The target moved more than tracking follows (or the worker fell behind and frames were dropped):
        // acquire on this same frame, from where it was last seen.
        guess = *pose;
      }
      const PointCloud scan = depth_to_cloud(*frame, k_);
      std::optional<AlignmentResult> a;
      if (scan.finite_count() >= aligner_.config().min_points) a = aligner_.align(scan, guess);
      if (a && a->converged) {
        pose = a->T_scan_model;
        rejected = 0;
        publish(*pose, frame->capture_time_s, false, a->inlier_ratio, a->rmse_mm);
        continue;
      }
      // Neither tracking nor acquisition found it. After lost_after such frames, say so.
      const bool was_tracking = pose.has_value();
      if (++rejected >= cfg_.lost_after && (was_tracking || rejected == cfg_.lost_after)) {
        pose.reset();
        publish(guess, frame->capture_time_s, true, a ? a->inlier_ratio : 0.0, a ? a->rmse_mm : 0.0);
      }
    }
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
    }
    publish(pose.value_or(guess), 0.0, true, 0.0, 0.0);  // the renderer blanks the target
  }
}

}  // namespace projbot::alignment
