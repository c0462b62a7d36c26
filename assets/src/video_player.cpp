// The video player: a decoder thread ahead of the content clock, a bounded queue, and frame_at() for the
// render thread, which never waits for decoding.
#include <algorithm>
#include <cmath>

#include "projbot/assets/video.hpp"

namespace projbot::assets {
namespace {
constexpr double kEpsS = 1e-6;  // presentation times are compared with this slack (rounding of time bases)
// Content asked for this far past the newest decoded frame (its target was not drawn for a while, its time
// going on) is jumped to rather than decoded through.
constexpr double kSeekAheadS = 1.0;
}  // namespace

VideoPlayer::VideoPlayer(std::unique_ptr<VideoDecoder> decoder, bool loop, std::size_t queue_frames)
    : decoder_(std::move(decoder)),
      info_(decoder_->info()),
      name_(decoder_->name()),
      loop_(loop),
      capacity_(std::max<std::size_t>(1, queue_frames)) {
  thread_ = std::jthread([this](const std::stop_token& stop) { decode_loop(stop); });
}

VideoPlayer::~VideoPlayer() {
  thread_.request_stop();  // wakes the thread's wait; the jthread joins it
  thread_ = std::jthread();
}

std::shared_ptr<VideoFrame> VideoPlayer::spare_frame() {
  if (spare_.empty()) return std::make_shared<VideoFrame>();
  auto f = std::move(spare_.back());
  spare_.pop_back();
  return f;
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
      if (rewind) {
        decoder_->rewind();
        offset_s = pass_end_s = 0.0;
        in_pass = 0;
      } else if (seek >= 0.0) {  // into the pass that holds the time asked for (the last frame, not looping)
        if (!loop_ && length_s > 0.0) seek = std::min(seek, length_s - 0.5 / info_.fps);
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
      continue;
    }
    if (restart_ || seek_s_ >= 0.0) continue;  // decoded before a restart or a jump was asked for: dropped
    ++stats_.decoded;
    seeking_ = false;
    queue_.push_back(std::move(f));
  }
}

VideoPlayer::Shown VideoPlayer::frame_at(double content_s) {
  std::unique_lock lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) {
    lock.lock();
    ++stats_.waits;
  }
  const double period = 1.0 / info_.fps;
  if (content_s < last_ask_s_ - 0.5 * period) {  // the content began again
    restart_ = true;
    queue_.clear();
    last_ask_s_ = content_s;
    wake_.notify_all();
    return {current_, false};
  }
  last_ask_s_ = content_s;
  const auto recycle = [this](std::shared_ptr<VideoFrame>& f) {
    if (f && f.use_count() == 1 && spare_.size() < capacity_ + 2) spare_.push_back(std::move(f));
    f.reset();
  };
  std::shared_ptr<VideoFrame> due;
  while (!queue_.empty() && !restart_ && queue_.front()->pts_s <= content_s + kEpsS) {
    if (due) ++stats_.skipped;
    recycle(due);
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
    recycle(current_);
    current_ = std::move(due);
    ++stats_.shown;
    out.fresh = true;
    wake_.notify_all();
  }
  if (!current_ || (!ended_ && content_s >= current_->pts_s + current_->duration_s + kEpsS))
    ++stats_.repeated;  // the due frame is not decoded yet: an older one stays up
  out.frame = current_;
  return out;
}

void VideoPlayer::restart() {
  std::lock_guard lock(mutex_);
  restart_ = true;
  queue_.clear();
  last_ask_s_ = 0.0;
  wake_.notify_all();
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
