// The video player: a decoder thread ahead of the content clock, a bounded queue, and frame_at() for the
// render thread, which never waits for decoding.
#include <algorithm>
#include <chrono>
#include <cmath>

#include "projbot/assets/video.hpp"

namespace projbot::assets {
namespace {
constexpr double kEpsS = 1e-6;  // presentation times are compared with this slack (rounding of time bases)
// Content asked for this far past the newest decoded frame (its target was not drawn for a while, its time
// going on) is jumped to rather than decoded through.
constexpr double kSeekAheadS = 1.0;
}  // namespace

// Frames go back to the pool when their last holder lets go (the queue, the frame shown, a renderer's frame
// in flight), on whichever thread that is: decoded into again, never while anyone still reads them.
struct VideoPlayer::FramePool {
  std::mutex mutex;
  std::vector<std::unique_ptr<VideoFrame>> spare;
  std::size_t keep = 0;  // at most this many spare frames are kept
};

VideoPlayer::VideoPlayer(std::unique_ptr<VideoDecoder> decoder, bool loop, std::size_t queue_frames, PixelAllocator allocator)
    : decoder_(std::move(decoder)),
      allocator_(std::move(allocator)),
      info_(decoder_->info()),
      name_(decoder_->name()),
      loop_(loop),
      capacity_(std::max<std::size_t>(1, queue_frames)),
      pool_(std::make_shared<FramePool>()) {
  pool_->keep = capacity_ + 4;  // the queue, the frame shown, one being decoded, two in a renderer's frames in flight
  thread_ = std::jthread([this](const std::stop_token& stop) { decode_loop(stop); });
}

VideoPlayer::~VideoPlayer() {
  thread_.request_stop();  // wakes the thread's wait; the jthread joins it
  thread_ = std::jthread();
}

std::shared_ptr<VideoFrame> VideoPlayer::spare_frame() {
  std::unique_ptr<VideoFrame> f;
  {
    std::lock_guard lock(pool_->mutex);
    if (!pool_->spare.empty()) {
      f = std::move(pool_->spare.back());
      pool_->spare.pop_back();
    }
  }
  if (!f) f = std::make_unique<VideoFrame>();
  std::weak_ptr<FramePool> pool = pool_;
  return {f.release(), [pool](VideoFrame* done) {
            if (const auto p = pool.lock()) {
              std::lock_guard lock(p->mutex);
              if (p->spare.size() < p->keep) {
                p->spare.emplace_back(done);
                return;
              }
            }
            delete done;
          }};
}

void VideoPlayer::decode_loop(const std::stop_token& stop) {
  double offset_s = 0.0, pass_end_s = 0.0;  // the times of earlier passes (loops); this pass's end
  double length_s = info_.duration_s;       // one pass, as the container says until a pass has been played
  std::size_t in_pass = 0;
  while (!stop.stop_requested()) {
    std::shared_ptr<VideoFrame> f;
    bool rewind = false;
    double seek = -1.0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, stop, [&] { return restart_ || seek_s_ >= 0.0 || (!ended_ && queue_.size() < capacity_); });
      if (stop.stop_requested()) return;
      if (restart_) {
        restart_ = ended_ = seeking_ = false;
        seek_s_ = -1.0;
        queue_.clear();
        rewind = true;
      }
      seek = seek_s_;
      seek_s_ = -1.0;
      f = spare_frame();
    }
    bool got = false;
    std::string error;
    bool looped = false;
    try {
      const std::size_t bytes = static_cast<std::size_t>(info_.width) * info_.height * 4;
      if (allocator_ && f->pixels.size != bytes) f->pixels = allocator_(bytes);  // outside the lock: frame_at never waits
      if (rewind) {
        decoder_->rewind();
        offset_s = pass_end_s = 0.0;
        in_pass = 0;
      } else if (seek >= 0.0) {  // into the pass holding that time (frame_at keeps it within a clip that does not loop)
        const double passes = loop_ && length_s > 0.0 ? std::floor(seek / length_s) : 0.0;
        offset_s = passes * length_s;
        decoder_->seek(seek - offset_s);
        pass_end_s = 0.0;
        in_pass = 1;  // a pass under way: its end loops
      }
      got = decoder_->next(*f);
      if (!got && loop_ && in_pass > 0) {  // the end of a pass: the stream again, its times going on
        decoder_->rewind();
        if (pass_end_s > 0.0) length_s = pass_end_s;  // a pass seen to its end gives the clip's length
        offset_s += length_s > 0.0 ? length_s : pass_end_s;
        pass_end_s = 0.0;
        in_pass = 0;
        looped = true;
        got = decoder_->next(*f);
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (got) {
      pass_end_s = std::max(pass_end_s, f->pts_s + f->duration_s);
      f->pts_s += offset_s;
      ++in_pass;
    }
    std::lock_guard lock(mutex_);
    if (looped) ++stats_.loops;
    if (seek >= 0.0) ++stats_.seeks;
    if (!error.empty() && error_.empty()) error_ = error;
    if (!got) {
      ended_ = true;  // the end (not looping), or an error: the last frame stays
      seeking_ = false;
      wake_.notify_all();
      continue;
    }
    if (restart_ || seek_s_ >= 0.0) continue;  // decoded before a restart or a jump was asked for: dropped
    ++stats_.decoded;
    seeking_ = false;
    queue_.push_back(std::move(f));
    wake_.notify_all();  // frame_due may wait for it
  }
}

VideoPlayer::Shown VideoPlayer::frame_at(double content_s) {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) {
    lock.lock();
    ++stats_.waits;
  }
  return take_due(content_s, true);
}

// Whether the frame due at content_s is decoded: a queued frame after it (all before it are queued), the
// frame shown lasting past it, or the end of the stream.
bool VideoPlayer::due_known(double content_s) const {
  if (restart_ || seeking_ || seek_s_ >= 0.0) return false;
  if (ended_) return true;
  for (const auto& f : queue_)
    if (f->pts_s > content_s + kEpsS) return true;
  return queue_.empty() && current_ && content_s >= current_->pts_s - kEpsS &&
         content_s < current_->pts_s + current_->duration_s - kEpsS;
}

VideoPlayer::Shown VideoPlayer::frame_due(double content_s, double timeout_s) {
  std::unique_lock lock(mutex_);
  Shown out = take_due(content_s, false);  // asks for a restart or a jump where the content needs one
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  bool waited = false;
  while (!due_known(content_s)) {
    if (queue_.size() >= capacity_ && !restart_ && !seeking_) {  // full of frames before it: taken, making room
      const Shown more = take_due(content_s, false);
      out = {more.frame, out.fresh || more.fresh};
      continue;
    }
    if (!waited) ++stats_.waits;  // once an ask
    waited = true;
    if (wake_.wait_until(lock, give_up) == std::cv_status::timeout) break;
  }
  const Shown last = take_due(content_s, true);
  return {last.frame, out.fresh || last.fresh};
}

VideoPlayer::Shown VideoPlayer::take_due(double content_s, bool count_repeat) {
  const double period = 1.0 / info_.fps;
  if (content_s < last_ask_s_ - 0.5 * period) {  // the content began again
    restart_ = true;
    queue_.clear();
    last_ask_s_ = content_s;
    wake_.notify_all();
    return {current_, false};
  }
  last_ask_s_ = content_s;
  std::shared_ptr<VideoFrame> due;
  while (!queue_.empty() && !restart_ && queue_.front()->pts_s <= content_s + kEpsS) {
    if (due) ++stats_.skipped;
    due = std::move(queue_.front());
    queue_.pop_front();
  }
  const double newest = !queue_.empty() ? queue_.back()->pts_s : due ? due->pts_s : current_ ? current_->pts_s : 0.0;
  // Not looping, the last frame is as far as it goes.
  const double target = !loop_ && info_.duration_s > 0.0 ? std::min(content_s, info_.duration_s - 0.5 * period) : content_s;
  if (!ended_ && !seeking_ && target > newest + kSeekAheadS) {  // far behind: jump, not decode through
    seek_s_ = target;
    seeking_ = true;  // until the jump's first frame is queued: one jump at a time
    queue_.clear();
    wake_.notify_all();
  }
  Shown out;
  if (due) {
    current_ = std::move(due);
    ++stats_.shown;
    out.fresh = true;
    wake_.notify_all();
  }
  if (count_repeat && (!current_ || (!ended_ && content_s >= current_->pts_s + current_->duration_s + kEpsS)))
    ++stats_.repeated;  // the due frame is not decoded yet: an older one stays up
  out.frame = current_;
  return out;
}

PlaybackStats VideoPlayer::stats() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

std::string VideoPlayer::take_error() {
  std::lock_guard lock(mutex_);
  if (error_.empty() || error_reported_) return {};
  error_reported_ = true;
  return error_;
}

}  // namespace projbot::assets
