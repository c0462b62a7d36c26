#pragma once
// The twin serving a projection session (`run --sim`, `record` in the twin): its robot and pan-tilt, and
// its camera unless a configured one replaces it.

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "projbot/engine/renderer.hpp"
#include "projbot/session/session.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

/// The twin serving the session's robot (and camera, unless `configured`). Renders on the thread that
/// builds it, which must be the one that drives it.
class TwinSession {
 public:
  /// `stop_requested`, asked while the twin is built (its map survey), ends that with
  /// robot::SetupInterrupted.
  /// `depth_model`: the twin's depth camera (TwinOptions::depth_model).
  TwinSession(const config::Scene& scene, const std::vector<session::Target>& targets, std::uint64_t seed,
              alignment::RgbdCamera* configured, std::function<bool()> stop_requested, bool colour_every_frame = false,
              const alignment::KinectNoiseConfig& depth_model = alignment::KinectNoiseConfig::fitted());
  session::Session& session() { return session_; }
  Twin& twin() { return twin_; }
  /// The renderer the twin draws with (its thread is the one that built the session).
  engine::Renderer& renderer() { return renderer_; }
  /// The dwell: `dwell_s` at each stop, the camera the configured one or the twin's.
  session::Dwell dwell(double dwell_s, bool lockstep);
  /// The twin's camera sees the projector's light when it shows one colour (TwinCamera::see_projector).
  void see_projector(TwinCamera::UniformLight shown) { twin_camera_.see_projector(renderer_, std::move(shown)); }

 private:
  engine::Renderer renderer_;
  Twin twin_;
  TwinCamera twin_camera_;
  alignment::RgbdCamera* configured_;
  session::Session session_;
};

}  // namespace projbot::twin
