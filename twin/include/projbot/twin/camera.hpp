#pragma once
// The twin's RGB-D camera as a session reads it (alignment::RgbdCamera): depth rendered from the camera's
// true pose with the Kinect v1 noise, at 30 Hz on the host's steady clock, the colour registered to it on
// the first frame of each stop (or on every frame). Before each capture the visited target is moved by its motion script to
// the capture instant, so a live run sees it move as a real one would. Not thread-safe: the twin's owner
// thread reads it.

#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

class TwinCamera final : public alignment::RgbdCamera {
 public:
  /// `twin` outlives the camera; `seed` seeds its noise (with the stop and frame numbers). Colour comes
  /// with every frame when `colour_every_frame` (a recording's), else with a stop's first only.
  TwinCamera(Twin& twin, std::uint64_t seed, bool colour_every_frame = false)
      : twin_(twin), seed_(seed), colour_every_frame_(colour_every_frame) {}
  /// A new stop: the visited target (index into Twin::targets()) and its visit number, whose motion
  /// script runs from `since_s` (steady clock, seconds); `visit` numbers the stop for the noise seeds.
  void at_stop(std::size_t target, int target_visit, int visit, double since_s);
  /// Waits for the next 30 Hz tick, then captures. Stamped with the instant the scene was sampled
  /// (the exposure), so the simulated sensor's own rendering counts in a pose's age, as a real
  /// camera's readout and transfer would.
  alignment::RgbdFrame next() override;
  /// Wall time of the last capture (render and noise), ms.
  double last_capture_ms() const { return last_capture_ms_; }
  /// What the projector shows over its whole image, when it shows one colour (a reflectance measured at a
  /// stop; nullopt: the content): while it does, every frame carries colour, the scene lit by it as the
  /// colour camera sees it (SpectatorView through the camera's pinhole, drawn with `renderer`).
  using UniformLight = std::function<std::optional<std::array<std::uint8_t, 3>>()>;
  void see_projector(engine::Renderer& renderer, UniformLight shown);
  /// Colour also with each frame while `wanted` says so (the operator's page asked for the camera's view).
  void colour_wanted(std::function<bool()> wanted) { colour_wanted_ = std::move(wanted); }

 private:
  Twin& twin_;
  std::uint64_t seed_;
  bool colour_every_frame_;
  std::size_t target_ = 0;
  int target_visit_ = 0, visit_ = 0;
  double since_s_ = 0.0;
  std::uint32_t frame_ = 0;  // frames at this stop
  std::chrono::steady_clock::time_point tick_{};
  double last_capture_ms_ = 0.0;
  UniformLight shown_;
  std::function<bool()> colour_wanted_;
  std::unique_ptr<SpectatorView> colour_camera_;  // see_projector's
};

}  // namespace projbot::twin
