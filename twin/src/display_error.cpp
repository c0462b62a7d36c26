#include "projbot/twin/display_error.hpp"

#include <algorithm>
#include <cmath>

namespace projbot::twin {

bool lit_by(const config::ProjectorConfig& k, const Eigen::Vector3d& p) { return p.z() > 0.0 && k.contains(k.project_lit(p)); }

MarkerErrors marker_errors(std::span<const PlacedMesh> scene, const Eigen::Matrix4d& T_projector_target_true,
                           const std::vector<Eigen::Vector3d>& markers_m, const ProjectorModels& projector,
                           const Eigen::Matrix4d& T_camera_target_estimated) {
  const Eigen::Matrix4d T_projector_target_estimated = projector.projector_from_target(T_camera_target_estimated);
  MarkerErrors e;
  int visible = 0;
  for (const auto& m : markers_m) {
    const Eigen::Vector3d truth = (T_projector_target_true * m.homogeneous()).head<3>();
    if (!lit_by(projector.truth, truth)) continue;  // outside the projector's image: it cannot be lit
    const auto first = cast_ray(scene, Eigen::Vector3d::Zero(), truth.normalized());
    if (!first || (*first - truth).norm() > 0.002) continue;
    if (seen_edge_on(scene, truth)) continue;  // a pose's error cannot be measured there
    e.markers.push_back(
        measure_marker(projector.believed, projector.truth, T_projector_target_estimated, T_projector_target_true, m, scene));
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

MarkerErrors marker_errors(const Twin& twin, std::size_t target, const ProjectorModels& projector,
                           const Eigen::Matrix4d& T_world_projector, const Eigen::Matrix4d& T_camera_target_estimated) {
  const Eigen::Matrix4d T_projector_world = alignment::rigid_inverse(T_world_projector);
  const TwinTarget& t = twin.targets()[target];
  return marker_errors(twin.true_scene(T_projector_world), T_projector_world * t.T_world_target_true, t.config.markers_m,
                       projector, T_camera_target_estimated);
}

StopMeter::StopMeter(const Twin& twin, ProjectorModels projector, const Eigen::Matrix4d& T_world_projector)
    : meshes_(twin.meshes()),
      world_(twin.true_scene(Eigen::Matrix4d::Identity())),
      projector_(std::move(projector)),
      T_projector_world_(alignment::rigid_inverse(T_world_projector)) {
  for (std::size_t i = 0; i < twin.targets().size(); ++i) {
    const TwinTarget& t = twin.targets()[i];
    const auto placed =
        std::find_if(world_.begin(), world_.end(), [&](const PlacedMesh& p) { return p.mesh == t.raycaster.get(); });
    targets_.push_back({t.config, twin.home(i), placed == world_.end() ? -1 : placed - world_.begin()});
  }
}

MarkerErrors StopMeter::measure(std::size_t target, int target_visit, const Eigen::Matrix4d& T_camera_target, double t_s) const {
  const Target& t = targets_.at(target);
  const config::TargetMotion* motion = t.config.motion_on(target_visit);
  if (t.entry < 0 || (motion && motion->removed && t_s >= motion->end_s()))
    return {{}, std::nan(""), std::nan("")};  // carried away: nothing to measure
  const Eigen::Matrix4d T_world_true = scripted_pose(t.config, t.T_world_home, target_visit, t_s);
  std::vector<PlacedMesh> scene = world_;
  scene[static_cast<std::size_t>(t.entry)].T_frame_model = T_world_true;
  for (PlacedMesh& p : scene) p.T_frame_model = T_projector_world_ * p.T_frame_model;
  return marker_errors(scene, T_projector_world_ * T_world_true, t.config.markers_m, projector_, T_camera_target);
}

}  // namespace projbot::twin
