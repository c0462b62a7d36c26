#pragma once
// The simulated projector's half of the twin: where a projector pixel's light lands on the true
// surfaces, and the paper's projection error at markers (sec. 4), measured automatically.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "projbot/assets/model.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::twin {

/// One model's triangles in its model frame, for ray casting: a bounding sphere, then a hierarchy of
/// axis-aligned boxes of at most 8 triangles each (run measures every frame's markers on its render
/// thread: brute force took 1.5-2 ms a frame over the Duck's 4200 triangles).
class MeshRaycaster {
 public:
  explicit MeshRaycaster(const assets::Model& model);
  /// Distance along the ray (origin, unit direction; model frame) to the nearest front or back face
  /// hit, or nothing.
  std::optional<double> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  /// The surface point nearest to `p` (model frame).
  Eigen::Vector3d closest_point(const Eigen::Vector3d& p) const;

 private:
  struct Node {
    Eigen::Vector3d lo, hi;              // the box of its triangles, padded
    std::uint32_t first = 0, count = 0;  // its triangles in order_ (a leaf)
    std::int32_t left = -1, right = -1;  // its children; -1: a leaf
  };
  std::int32_t build(std::uint32_t first, std::uint32_t count);
  std::optional<double> hit(std::size_t i, const Eigen::Vector3d& o, const Eigen::Vector3d& d) const;

  std::vector<Eigen::Vector3d> a_, e1_, e2_;  // triangle corner and two edges
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  double radius_ = 0.0;
  std::vector<Node> nodes_;           // nodes_[0] the root
  std::vector<std::uint32_t> order_;  // triangle indices, grouped by leaf
};

/// A mesh placed in some frame: T_frame_model.
struct PlacedMesh {
  const MeshRaycaster* mesh = nullptr;
  Eigen::Matrix4d T_frame_model = Eigen::Matrix4d::Identity();
};

/// The nearest hit of a ray (frame coordinates, unit direction) among the placed meshes.
std::optional<Eigen::Vector3d> cast_ray(std::span<const PlacedMesh> scene, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& direction);

/// More than this from the surface's normal, the light meets it edge-on (seen_edge_on).
constexpr double kEdgeOnDeg = 80.0;

/// Whether a ray from the origin meets the scene's surface at p (the ray's first hit) edge-on: more
/// than kEdgeOnDeg from its normal, or within 3 mm of where that surface ends in the ray's view. There
/// a sub-millimetre pose error slides projected light centimetres along the surface, or past the
/// silhouette onto whatever is behind (the duck turned at 180 deg/s, tracked 0.3 mm and 0.2 degrees
/// off: 2.5 m at one marker, the distance to the wall behind it): an error there measures the scene's
/// geometry, not the pose, and the tour leaves such a marker out of that frame. Looks only at the scene.
bool seen_edge_on(std::span<const PlacedMesh> scene, const Eigen::Vector3d& p);

/// Projection error at one marker.
struct MarkerError {
  Eigen::Vector3d marker_m = Eigen::Vector3d::Zero();  ///< model frame
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();     ///< the projector pixel that carries it (centre)
  bool in_image = false;                               ///< the pixel lies inside the projector image
  bool landed = false;                                 ///< its light hits a true surface
  /// Distance between where the light lands and where the marker truly is, mm. When the light hits
  /// nothing (or the pixel is outside the image), the distance from the marker to the pixel's ray.
  double error_mm = 0.0;
};

/// Eq. 3 with the estimated pose and the drawing's projector (`drawn`: what the session believes A_p and
/// its lens are; the renderer pre-distorts by that lens) gives the pixel that carries the marker (rounded
/// to the pixel centre, as content is drawn in pixels); that pixel's ray through the true lens (`light`)
/// is cast into `true_scene` (projector frame, true poses) and compared with the marker under the true pose.
MarkerError measure_marker(const config::ProjectorConfig& drawn, const config::ProjectorConfig& light,
                           const Eigen::Matrix4d& T_projector_target_estimated, const Eigen::Matrix4d& T_projector_target_true,
                           const Eigen::Vector3d& marker_m, std::span<const PlacedMesh> true_scene);

}  // namespace projbot::twin
