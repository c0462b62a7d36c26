#pragma once
// The display error: how far from a target's markers the projector's light lands (mm), measured in the
// twin against the true scene. One definition for the tour and `run`: a marker counts only where the
// projector can light it (inside its image, not turned away, not hidden by the target or anything in
// front) and does not light it edge-on (seen_edge_on); a frame with no such marker has no error (NaN).

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/twin/raycast.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

/// The projector as the twin's light follows it (the scene's: the truth) and as the session believes it
/// (a calibration's A_p and R_cp, T_cp when the tour is given one; else the truth): Eq. 2 and the
/// drawing use what the session believes.
struct ProjectorModels {
  config::ProjectorConfig truth, believed;
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  ///< believed R_cp, T_cp
  Eigen::Matrix4d projector_from_target(const Eigen::Matrix4d& T_camera_target) const {
    return alignment::projector_from_target(T_projector_camera, T_camera_target);  // Eq. 2
  }
};

/// One frame's markers as measured, their mean and largest error (mm; NaN where none was measured).
struct MarkerErrors {
  std::vector<MarkerError> markers;
  double mean_mm = 0.0, max_mm = 0.0;
};

/// Whether a point in the projector frame falls inside the projector's image (Eq. 3).
bool lit_by(const config::ProjectorConfig& k, const Eigen::Vector3d& p);

/// The error at `markers_m` (model frame) of a target truly at T_projector_target_true among `scene` (the
/// true scene in the projector frame, the target included), drawn at T_camera_target_estimated.
MarkerErrors marker_errors(std::span<const PlacedMesh> scene, const Eigen::Matrix4d& T_projector_target_true,
                           const std::vector<Eigen::Vector3d>& markers_m, const ProjectorModels& projector,
                           const Eigen::Matrix4d& T_camera_target_estimated);
/// The same in the twin as it stands now, the projector truly at T_world_projector (the tour's).
MarkerErrors marker_errors(const Twin& twin, std::size_t target, const ProjectorModels& projector,
                           const Eigen::Matrix4d& T_world_projector, const Eigen::Matrix4d& T_camera_target_estimated);

/// The display error of one stop's frames, measured on any thread (run's render thread) while the twin
/// goes on: the true scene as the stop began and each target's motion script, so that a target is
/// measured where it truly is at a frame's display time. Shares the twin's meshes (their ray casters are
/// read-only), so it may outlive the twin.
class StopMeter {
 public:
  /// The twin as the stop begins, its projector truly at T_world_projector.
  StopMeter(const Twin& twin, ProjectorModels projector, const Eigen::Matrix4d& T_world_projector);
  /// Target `target` (the twin's index), on its `target_visit` (its motion script; 0: still), drawn at
  /// T_camera_target, `t_s` after the stop began. No marker measured (NaN) for a target not in the world.
  MarkerErrors measure(std::size_t target, int target_visit, const Eigen::Matrix4d& T_camera_target, double t_s) const;

 private:
  struct Target {
    config::TargetConfig config;
    Eigen::Matrix4d T_world_home = Eigen::Matrix4d::Identity();
    std::ptrdiff_t entry = -1;  ///< its mesh in world_; -1: not in the world
  };
  std::vector<std::shared_ptr<const MeshRaycaster>> meshes_;  ///< keeps world_'s meshes
  std::vector<PlacedMesh> world_;                             ///< the true scene as the stop began, world frame
  std::vector<Target> targets_;                               ///< by the twin's index
  ProjectorModels projector_;
  Eigen::Matrix4d T_projector_world_;
};

}  // namespace projbot::twin
