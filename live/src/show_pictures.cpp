#include "projbot/live/show_pictures.hpp"

#include <limits>

#include "projbot/config/clock.hpp"

namespace projbot::live {

ShowPictures::ShowPictures(PictureConfig config)
    : config_(config), encoder_([this](std::stop_token stop) { encode(std::move(stop)); }) {}

ShowPictures::~ShowPictures() {
  encoder_.request_stop();
  offered_.notify_all();
}

ShowPictures::Png ShowPictures::png(Kind kind) {
  Slot& s = slot(kind);
  s.wanted_until_s = config::steady_now_s() + config_.interest_s;
  const std::lock_guard lock(mutex_);
  return s.png;
}

std::string ShowPictures::unavailable(Kind kind) const {
  const std::lock_guard lock(mutex_);
  return slot(kind).unavailable;
}

bool ShowPictures::due(Kind kind) const {
  const Slot& s = slot(kind);
  const double now = config::steady_now_s();
  return now < s.wanted_until_s.load() && now - s.offered_s.load() >= config_.period_s;
}

void ShowPictures::offer(Kind kind, assets::Image image) {
  Slot& s = slot(kind);
  s.offered_s = config::steady_now_s();
  {
    const std::lock_guard lock(mutex_);
    s.pending = std::move(image);
  }
  offered_.notify_all();
}

void ShowPictures::set_unavailable(Kind kind, std::string why) {
  slot(kind).offered_s = std::numeric_limits<double>::infinity();  // never due again
  const std::lock_guard lock(mutex_);
  slot(kind).unavailable = std::move(why);
}

// The encoder's thread: each picture offered, shrunk and encoded outside the lock, then published. A
// picture that cannot be encoded (an empty image) is dropped.
void ShowPictures::encode(std::stop_token stop) {
  std::unique_lock lock(mutex_);
  while (!stop.stop_requested()) {
    offered_.wait(lock, stop, [this] { return slots_[0].pending || slots_[1].pending; });
    for (Slot& s : slots_) {
      if (!s.pending || stop.stop_requested()) continue;
      assets::Image image = std::move(*s.pending);
      s.pending.reset();
      lock.unlock();
      Png png;
      try {
        png = std::make_shared<const std::vector<std::uint8_t>>(assets::encode_png(assets::shrunk(image, config_.max_width)));
      } catch (const assets::AssetError&) {
      }
      lock.lock();
      if (png) {
        s.png = std::move(png);
        ++encoded_;
      }
    }
  }
}

}  // namespace projbot::live
