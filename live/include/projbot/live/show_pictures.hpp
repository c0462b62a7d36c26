#pragma once
// The projector's frame and the camera's view as small pictures for the operator's page (issue 70), about
// twice a second while someone looks at them. The engine's threads ask whether a picture is due (two atomic
// reads: nothing is copied while no one has asked for one in the last few seconds) and hand over a copy; a
// thread of its own shrinks and encodes it to PNG, so neither the render thread nor the robot thread encodes.
// The console (any thread) takes the newest PNG, which also marks its kind wanted.

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "projbot/assets/image.hpp"

namespace projbot::live {

struct PictureConfig {
  int max_width = 320;      ///< pictures are shrunk to at most this wide
  double period_s = 0.5;    ///< at most one picture of a kind this often
  double interest_s = 5.0;  ///< a kind is taken while someone asked for it this recently
};

class ShowPictures {
 public:
  enum class Kind { frame, camera };  ///< the projector's frame, the camera's colour view
  using Png = std::shared_ptr<const std::vector<std::uint8_t>>;

  explicit ShowPictures(PictureConfig config = {});
  ~ShowPictures();  ///< stops the encoder (what it was encoding is dropped)
  ShowPictures(const ShowPictures&) = delete;
  ShowPictures& operator=(const ShowPictures&) = delete;

  // The operator's side (any thread).
  /// The newest PNG of `kind` (null: none yet); marks `kind` wanted for the next interest_s.
  Png png(Kind kind);
  /// Why `kind` will never have a picture (e.g. the projector's frames go to a window); empty: it will.
  std::string unavailable(Kind kind) const;

  // The engine's side.
  /// Whether a picture of `kind` is wanted now: asked for recently and none taken for period_s.
  bool due(Kind kind) const;
  /// Takes `image` (RGBA) for encoding; a picture still waiting for the encoder is replaced.
  void offer(Kind kind, assets::Image image);
  /// `kind` cannot be given, and why (said to whoever asks for it).
  void set_unavailable(Kind kind, std::string why);
  /// Pictures encoded so far, of both kinds.
  std::size_t encoded() const { return encoded_; }

 private:
  struct Slot {
    std::atomic<double> wanted_until_s{-1.0};
    std::atomic<double> offered_s{-1e300};
    std::optional<assets::Image> pending;  // under mutex_
    Png png;                               // under mutex_
    std::string unavailable;               // under mutex_
  };
  Slot& slot(Kind kind) { return slots_[static_cast<std::size_t>(kind)]; }
  const Slot& slot(Kind kind) const { return slots_[static_cast<std::size_t>(kind)]; }
  void encode(std::stop_token stop);

  PictureConfig config_;
  std::array<Slot, 2> slots_;
  mutable std::mutex mutex_;
  std::condition_variable_any offered_;
  std::atomic<std::size_t> encoded_{0};
  std::jthread encoder_;  // last: starts once the above exist
};

}  // namespace projbot::live
