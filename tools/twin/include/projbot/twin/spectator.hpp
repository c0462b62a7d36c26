#pragma once
// A spectator's view of a visit: the room as a visitor standing beside the robot sees it, dimmed for
// projection, with the projector's light falling on the true surfaces (on the target, and wherever it
// spills past it), so a person sees at a glance whether the content sits on the object.

#include <Eigen/Core>
#include <memory>

#include "projbot/assets/image.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

/// A camera frame (z forward, x right, y down) at `eye` looking at `at`, the world's z up.
Eigen::Matrix4d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& at);

/// Where a visitor stands to watch a stop: a metre to the right of the robot's head and a little behind
/// it, eyes at 1.6 m, looking at the middle of the target (world frame).
Eigen::Matrix4d spectator_pose(const Eigen::Vector3d& head, const Eigen::Vector3d& target_middle);

class SpectatorView {
 public:
  static constexpr int kWidth = 960;
  static constexpr int kHeight = 720;
  static constexpr double kRoomLight = 0.3;  ///< the room's light while projecting, of full white

  SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector);

  /// The spectator's picture at T_world_spectator: each visible surface point's albedo (the twin's
  /// colour) lit by the room light plus the projector's pixel that reaches it (Eq. 3 from
  /// T_world_projector, blocked by whatever stands nearer the projector). Throws TwinError when the
  /// frame is not the projector's size.
  assets::Image draw(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const Eigen::Matrix4d& T_world_projector,
                     const assets::Image& projector_frame);

  const config::ProjectorConfig& pinhole() const { return pinhole_; }

 private:
  engine::Renderer& renderer_;
  config::ProjectorConfig projector_;
  config::ProjectorConfig pinhole_;  // the spectator's eye: 960 x 720, about 69 degrees across
  std::unique_ptr<engine::RenderTarget> colour_, depth_, projector_depth_;
};

}  // namespace projbot::twin
