#include "projbot/robot/pan_tilt.hpp"

#include <algorithm>
#include <cmath>

namespace projbot::robot {
namespace {

Eigen::Isometry3d iso(const Eigen::Matrix4d& m) { return Eigen::Isometry3d(m); }

// T_base_head for the given angles: mount, pan about z, offset to the tilt axis, tilt about -y
// (so that positive tilt raises the head's x axis).
Eigen::Isometry3d base_from_head(const PanTiltAngles& a, const config::PanTiltConfig& rig) {
  Eigen::Isometry3d T = iso(rig.T_base_mount);
  T.rotate(Eigen::AngleAxisd(a.pan_rad, Eigen::Vector3d::UnitZ()));
  T.translate(rig.tilt_axis_offset_m);
  T.rotate(Eigen::AngleAxisd(-a.tilt_rad, Eigen::Vector3d::UnitY()));
  return T;
}

double quantise(double angle, double step) { return step > 0.0 ? std::round(angle / step) * step : angle; }

// Output shaft of a drive with a dead band: it moves only when the drive pushes against it.
double through_backlash(double output, double drive, double backlash) {
  const double half = backlash / 2.0;
  if (drive - output > half) return drive - half;
  if (output - drive > half) return drive + half;
  return output;
}

}  // namespace

HeadPoses head_poses(const Pose2D& T_world_base, const PanTiltAngles& angles, const config::PanTiltConfig& rig) {
  const Eigen::Isometry3d T_world_camera = to_isometry(T_world_base) * base_from_head(angles, rig) * iso(rig.T_head_camera);
  return {T_world_camera, T_world_camera * iso(rig.T_projector_camera).inverse()};
}

AimResult aim_at(const Pose2D& T_world_base, const Eigen::Vector3d& target_world, const config::PanTiltConfig& rig) {
  // Fixed point: look at where the target appears in the camera, turn by that much, repeat. Each
  // step removes the angular error up to a term of order (offset / range)^2.
  PanTiltAngles a;
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector3d p = head_poses(T_world_base, a, rig).T_world_camera.inverse() * target_world;
    const double d_pan = std::atan2(-p.x(), p.z());                      // camera x is right: positive x means turn right
    const double d_tilt = std::atan2(-p.y(), std::hypot(p.x(), p.z()));  // camera y is down
    a.pan_rad = wrap_angle(a.pan_rad + d_pan);
    a.tilt_rad += d_tilt;
    if (std::abs(d_pan) < 1e-12 && std::abs(d_tilt) < 1e-12) break;
  }
  AimResult r;
  r.within_limits = a.pan_rad >= rig.pan_min_rad && a.pan_rad <= rig.pan_max_rad && a.tilt_rad >= rig.tilt_min_rad &&
                    a.tilt_rad <= rig.tilt_max_rad;
  r.angles = {std::clamp(a.pan_rad, rig.pan_min_rad, rig.pan_max_rad),
              std::clamp(a.tilt_rad, rig.tilt_min_rad, rig.tilt_max_rad)};
  const Eigen::Vector3d p = head_poses(T_world_base, r.angles, rig).T_world_camera.inverse() * target_world;
  r.miss_rad = std::atan2(std::hypot(p.x(), p.y()), p.z());
  return r;
}

SimulatedPanTilt::SimulatedPanTilt(const config::PanTiltConfig& rig, double backlash_rad)
    : rig_(rig), backlash_rad_(backlash_rad) {}

PanTiltStatus SimulatedPanTilt::move_to(const PanTiltAngles& a) {
  if (!std::isfinite(a.pan_rad) || !std::isfinite(a.tilt_rad)) return {false, "pan-tilt: angles must be finite"};
  if (a.pan_rad < rig_.pan_min_rad || a.pan_rad > rig_.pan_max_rad)
    return {false, "pan-tilt: pan " + std::to_string(a.pan_rad) + " rad is outside the unit's limits"};
  if (a.tilt_rad < rig_.tilt_min_rad || a.tilt_rad > rig_.tilt_max_rad)
    return {false, "pan-tilt: tilt " + std::to_string(a.tilt_rad) + " rad is outside the unit's limits"};
  steps_ = {quantise(a.pan_rad, rig_.step_rad), quantise(a.tilt_rad, rig_.step_rad)};
  true_ = {through_backlash(true_.pan_rad, steps_.pan_rad, backlash_rad_),
           through_backlash(true_.tilt_rad, steps_.tilt_rad, backlash_rad_)};
  return {};
}

PanTiltStatus SimulatedPanTilt::position(PanTiltAngles& out) {
  out = steps_;
  return {};
}

}  // namespace projbot::robot
