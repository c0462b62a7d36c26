#include "projbot/alignment/equations.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "projbot/config/angles.hpp"

namespace projbot::alignment {

Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& T) {
  Eigen::Matrix4d inv = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d Rt = T.topLeftCorner<3, 3>().transpose();
  inv.topLeftCorner<3, 3>() = Rt;
  inv.topRightCorner<3, 1>() = -Rt * T.topRightCorner<3, 1>();
  return inv;
}

Eigen::Matrix4d camera_from_target_initial(const Eigen::Matrix4d& T_world_camera, const Eigen::Matrix4d& T_world_target) {
  // Eq. 1: with R_wc = R_world_camera^T and X_c the camera position, R = R_wc R_t and X = R_wc (X_t - X_c).
  const Eigen::Matrix3d R_wc = T_world_camera.topLeftCorner<3, 3>().transpose();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R_wc * T_world_target.topLeftCorner<3, 3>();
  T.topRightCorner<3, 1>() = R_wc * (T_world_target.topRightCorner<3, 1>() - T_world_camera.topRightCorner<3, 1>());
  return T;
}

Eigen::Matrix4d projector_from_target(const Eigen::Matrix4d& T_projector_camera, const Eigen::Matrix4d& T_camera_target) {
  // Eq. 2: R_p = R_cp R_c, X_p = R_cp X_c + T_cp.
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = T_projector_camera.topLeftCorner<3, 3>() * T_camera_target.topLeftCorner<3, 3>();
  T.topRightCorner<3, 1>() = T_projector_camera.topLeftCorner<3, 3>() * T_camera_target.topRightCorner<3, 1>() +
                             T_projector_camera.topRightCorner<3, 1>();
  return T;
}

double rotation_angle_deg(const Eigen::Matrix4d& T) {
  const double c = std::clamp((T.topLeftCorner<3, 3>().trace() - 1.0) / 2.0, -1.0, 1.0);
  return config::degrees(std::acos(c));
}

double translation_norm_m(const Eigen::Matrix4d& T) { return T.topRightCorner<3, 1>().norm(); }

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w) {
  const double angle = w.norm();
  if (!(angle > 1e-12)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

}  // namespace projbot::alignment
