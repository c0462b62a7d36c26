#pragma once
// A spectator's view of a visit: the room as a visitor standing beside the robot sees it, in its own dim
// light, with the projector's light falling on the true surfaces (on the target, and wherever it spills
// past it), so a person sees at a glance whether the content sits on the object, and in what colour
// (issue 43: engine/photometry.hpp's light, each surface's own reflectance).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

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

/// What the spectator sees, and per pixel what the appearance bench scores it by (row-major, top first).
struct SpectatorPicture {
  assets::Image image;           ///< sRGB: reflectance x (room + projector light) / engine::kReferenceLux
  assets::Image albedo;          ///< the surfaces' own colours, sRGB (the twin's; targets' from `surface:`)
  std::vector<float> white_lux;  ///< full white's lux on the surface seen; 0 where the projector cannot reach it
  std::vector<float> z_m;        ///< the spectator's depth of the surface seen, 0 for none
};

/// What the eye and the projector see of the true surfaces from two fixed poses: all of see() that does not
/// depend on the projector's frame, so that several frames can be lit from one look (off and on, black
/// and grey).
struct SpectatorScene {
  assets::Image albedo;             ///< as SpectatorPicture's
  std::vector<float> white_lux;     ///< likewise
  std::vector<float> z_m;           ///< likewise
  std::vector<std::int32_t> panel;  ///< the projector pixel whose light reaches each pixel (row-major), -1 none
  double ambient_lux = 0.0;         ///< the room's light
};

/// A target as the spectator would see it: its content (sRGB, the content model drawn from the spectator)
/// and where the target itself is the nearest surface.
struct ContentView {
  assets::Image content;
  std::vector<std::uint8_t> mask;  ///< 1 where the spectator sees the target
};

/// A projector frame of one colour (8-bit levels) over its whole image: what it shows while a target's
/// reflectance is measured (black, then mid grey).
assets::Image uniform_frame(const config::ProjectorConfig& projector, const std::array<std::uint8_t, 3>& rgb);

class SpectatorView {
 public:
  static constexpr int kWidth = 960;
  static constexpr int kHeight = 720;

  SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector);
  /// The same light seen through another pinhole: the RGB-D camera's colour camera, as a radiometrically
  /// calibrated camera (sRGB, a white surface under engine::kReferenceLux reads 1).
  SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector, const config::Camera& eye);

  /// The spectator's picture at T_world_spectator: each visible surface point's reflectance lit by the
  /// room's light (`room.ambient_lux`) plus the light of the projector's pixel that reaches it (Eq. 3 from
  /// T_world_projector, blocked by whatever stands nearer the projector; its brightness, response, distance
  /// and incidence). Throws TwinError when the frame is not the projector's size.
  SpectatorPicture see(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const Eigen::Matrix4d& T_world_projector,
                       const assets::Image& projector_frame) {
    return light(look(twin, T_world_spectator, T_world_projector), projector_frame);
  }
  /// see() in two halves: the geometry from the poses (renders and per-pixel light paths), then a frame's
  /// light on it (throws TwinError when the frame is not the projector's size).
  SpectatorScene look(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const Eigen::Matrix4d& T_world_projector);
  SpectatorPicture light(const SpectatorScene& scene, const assets::Image& projector_frame) const;
  /// Target `target` (index into Twin::targets()) where it stands now, as seen from T_world_spectator: its
  /// content, and where it is the nearest surface of `scene` (look() from the same place).
  ContentView content(Twin& twin, std::size_t target, const Eigen::Matrix4d& T_world_spectator, const SpectatorScene& scene);
  /// see()'s picture alone.
  assets::Image draw(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const Eigen::Matrix4d& T_world_projector,
                     const assets::Image& projector_frame) {
    return see(twin, T_world_spectator, T_world_projector, projector_frame).image;
  }

  const config::ProjectorConfig& pinhole() const { return pinhole_; }

 private:
  engine::Renderer& renderer_;
  config::ProjectorConfig projector_;
  config::ProjectorConfig pinhole_;  // the spectator's eye: 960 x 720, about 69 degrees across
  std::unique_ptr<engine::RenderTarget> colour_, depth_, projector_depth_;
  std::vector<Eigen::Vector3f> facet_normals(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const engine::DepthMap& depth);
};

}  // namespace projbot::twin
