#include "projbot/alignment/tracker_worker.hpp"

#include <utility>

namespace projbot::alignment {

TrackerWorker::TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : follower_(std::move(model), intrinsics, std::move(config)), thread_([this](std::stop_token stop) { run(stop); }) {}

TrackerWorker::~TrackerWorker() {
  thread_.request_stop();
  wake_.notify_all();
}  // jthread joins

std::uint64_t TrackerWorker::post(std::shared_ptr<const DepthImage> frame) {
  std::uint64_t ticket = 0;
  {
    std::lock_guard lock(mutex_);
    inbox_ = std::move(frame);  // a frame not yet taken is dropped: only the newest matters
    ticket = ++submitted_;
  }
  wake_.notify_one();
  return ticket;
}

void TrackerWorker::submit(std::shared_ptr<const DepthImage> frame) { post(std::move(frame)); }

std::optional<PoseSample> TrackerWorker::track(std::shared_ptr<const DepthImage> frame) {
  const std::uint64_t ticket = post(std::move(frame));
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return finished_ >= ticket || error_; });
  if (error_) std::rethrow_exception(error_);
  return finished_sample_;
}

void TrackerWorker::set_initial_guess(const Eigen::Matrix4d& T_camera_target) {
  if (!T_camera_target.allFinite()) throw AlignmentError("initial guess is not finite");
  std::lock_guard lock(mutex_);
  guess_ = Start{T_camera_target, std::nullopt, nullptr};
}

void TrackerWorker::set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing,
                                      std::shared_ptr<const assets::Image> colour) {
  if (!T_camera_target.allFinite()) throw AlignmentError("initial guess is not finite");
  std::lock_guard lock(mutex_);
  guess_ = Start{T_camera_target, footing, std::move(colour)};
}

std::exception_ptr TrackerWorker::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void TrackerWorker::run(std::stop_token stop) {
  std::uint64_t sequence = 0;
  std::shared_ptr<const assets::Image> colour;  // the stop's arrival colour, until its first frame
  std::uint64_t ticket = 0;                     // the frame taken: the submitted_ count when it was
  try {
    while (!stop.stop_requested()) {
      std::shared_ptr<const DepthImage> frame;
      {
        std::unique_lock lock(mutex_);
        if (!wake_.wait(lock, stop, [&] { return inbox_ != nullptr || guess_.has_value(); })) break;
        if (guess_) {  // a new stop: acquire afresh from Eq. 1's guess
          if (guess_->footing)
            follower_.set_initial_guess(guess_->T_camera_target, *guess_->footing);
          else
            follower_.set_initial_guess(guess_->T_camera_target);
          colour = std::move(guess_->colour);
          guess_.reset();
        }
        frame = std::move(inbox_);
        ticket = submitted_;
      }
      if (!frame) continue;
      ++processed_;
      // The arrival's colour serves the stop's first frame only: later the projector lights the target.
      auto sample = follower_.step(*frame, colour.get());
      colour.reset();
      if (sample) {
        sample->sequence = ++sequence;
        poses_.publish(*sample);
      }
      {
        std::lock_guard lock(mutex_);
        finished_ = ticket;
        finished_sample_ = sample;
      }
      done_.notify_all();
    }
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
    }
    done_.notify_all();
    PoseSample lost;  // lost: the renderer blanks the target
    lost.T_camera_target = lost.motion.T = follower_.last_pose();
    lost.sequence = ++sequence;
    poses_.publish(lost);
  }
}

}  // namespace projbot::alignment
