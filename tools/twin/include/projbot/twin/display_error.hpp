#pragma once
// Internal to the twin's tour: the error of a drawn pose at the target's markers, as the projector's
// light lands on them (the display error's one definition: which markers count, and how far off each is).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/twin/raycast.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

// The projector as the twin's light follows it (the scene's: the truth) and as the session believes it
// (a calibration's A_p and R_cp, T_cp when the tour is given one; else the truth): Eq. 2 and the
// drawing use what the session believes.
struct ProjectorModels {
  config::ProjectorConfig truth, believed;
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  // believed R_cp, T_cp
  Eigen::Matrix4d projector_from_target(const Eigen::Matrix4d& T_camera_target) const {
    return alignment::projector_from_target(T_projector_camera, T_camera_target);  // Eq. 2
  }
};

// One frame's markers as measured, their mean and largest error (mm; NaN where none was measured).
struct Errors {
  std::vector<MarkerError> markers;
  double mean_mm = 0.0, max_mm = 0.0;
};

/// Whether a point in the projector frame falls inside the projector's image (Eq. 3).
bool lit_by(const config::ProjectorConfig& k, const Eigen::Vector3d& p);

// The error at the target's markers. A marker the projector cannot light (outside its image, turned
// away, or hidden by the target itself or something in front), or lights edge-on (seen_edge_on), has no
// error to measure and is left out; mean and max are NaN when no marker is left (such frames are left
// out of the visit's statistics).
Errors marker_errors(const Twin& twin, std::size_t target, const ProjectorModels& projector,
                     const Eigen::Matrix4d& T_world_projector, const Eigen::Matrix4d& T_camera_target_estimated);

}  // namespace projbot::twin
