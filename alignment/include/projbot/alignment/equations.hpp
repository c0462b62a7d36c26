#pragma once
// The paper's frame equations (sec. 3.3.2), with T_a_b mapping points in frame b into frame a.

#include <Eigen/Core>

namespace projbot::alignment {

/// Eq. 1: the target's initial pose in the camera frame from the map and the robot's self-localisation,
/// R = R_wc R_t, X = R_wc (X_t - X_c), i.e. T_camera_target = inverse(T_world_camera) * T_world_target.
/// (The paper's R_wc rotates world into camera coordinates: it is the rotation of inverse(T_world_camera).)
Eigen::Matrix4d camera_from_target_initial(const Eigen::Matrix4d& T_world_camera, const Eigen::Matrix4d& T_world_target);

/// Eq. 2: the refined pose moved to the projector frame, R_p = R_cp R_c, X_p = R_cp X_c + T_cp,
/// i.e. T_projector_target = T_projector_camera * T_camera_target.
Eigen::Matrix4d projector_from_target(const Eigen::Matrix4d& T_projector_camera, const Eigen::Matrix4d& T_camera_target);

/// The inverse of a rigid transform (R^T, -R^T t), exact for rotations.
Eigen::Matrix4d rigid_inverse(const Eigen::Matrix4d& T);

/// Rotation angle of T's rotation part, degrees, and its translation norm, metres.
double rotation_angle_deg(const Eigen::Matrix4d& T);
double translation_norm_m(const Eigen::Matrix4d& T);

/// The rotation by |w| radians about w (the exponential map of SO(3)); the identity for w = 0.
Eigen::Matrix3d exp_so3(const Eigen::Vector3d& w);
/// Its inverse: the rotation vector (axis times angle, radians, angle in [0, pi]) of R.
Eigen::Vector3d log_so3(const Eigen::Matrix3d& R);

}  // namespace projbot::alignment
