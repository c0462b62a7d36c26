#include "marker_errors.hpp"

#include <algorithm>
#include <cmath>

namespace projbot::twin {

// Whether a point in the projector frame falls inside the projector's image (Eq. 3).
bool lit_by(const config::ProjectorConfig& k, const Eigen::Vector3d& p) {
  if (p.z() <= 0.0) return false;
  const Eigen::Vector2d x = k.project_lit(p);
  return x.x() >= 0.0 && x.y() >= 0.0 && x.x() < k.width_px && x.y() < k.height_px;
}

Errors marker_errors(const Twin& twin, std::size_t target, const ProjectorModels& projector,
                     const Eigen::Matrix4d& T_world_projector, const Eigen::Matrix4d& T_camera_target_estimated) {
  const Eigen::Matrix4d T_projector_target_estimated = projector.projector_from_target(T_camera_target_estimated);
  const Eigen::Matrix4d T_projector_world = alignment::rigid_inverse(T_world_projector);
  const auto scene = twin.true_scene(T_projector_world);
  const TwinTarget& t = twin.targets()[target];
  const Eigen::Matrix4d T_true = T_projector_world * t.T_world_target_true;
  Errors e;
  int visible = 0;
  for (const auto& m : t.config.markers_m) {
    const Eigen::Vector3d truth = (T_true * m.homogeneous()).head<3>();
    if (!lit_by(projector.truth, truth)) continue;  // outside the projector's image: it cannot be lit
    const auto first = cast_ray(scene, Eigen::Vector3d::Zero(), truth.normalized());
    if (!first || (*first - truth).norm() > 0.002) continue;
    if (seen_edge_on(scene, truth)) continue;  // a pose's error cannot be measured there
    e.markers.push_back(measure_marker(projector.believed, projector.truth, T_projector_target_estimated, T_true, m, scene));
    e.mean_mm += e.markers.back().error_mm;
    e.max_mm = std::max(e.max_mm, e.markers.back().error_mm);
    ++visible;
  }
  if (visible == 0)
    e.mean_mm = e.max_mm = std::nan("");
  else
    e.mean_mm /= visible;
  return e;
}

}  // namespace projbot::twin
