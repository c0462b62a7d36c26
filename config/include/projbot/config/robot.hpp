#pragma once
// The robot's calibrated geometry: the pan-tilt mount, the camera on it and the projector
// beside the camera. Defaults describe the simulated youBot rig; a scene's `robot:` section
// overrides them.

#include <Eigen/Core>

namespace projbot::config {

/// Pan-tilt unit and the sensor head. Frames: base (x forward, y left, z up), pan (the mount
/// rotated by pan about its z), head (the tilt axis frame rotated by tilt; x along the ideal
/// optical axis), camera and projector (OpenCV: x right, y down, z forward).
struct PanTiltConfig {
  /// T_base_mount: where the pan axis stands on the base (z is the pan axis). Rigid.
  Eigen::Matrix4d T_base_mount = Eigen::Matrix4d::Identity();
  /// From the pan frame's origin to the tilt axis, in the pan frame, metres.
  Eigen::Vector3d tilt_axis_offset_m{0.0, 0.0, 0.06};
  /// T_head_camera: the camera's optical frame in the head frame. Rigid. In a scene file give the
  /// whole rotation: rpy_deg [-90, 0, -90] is a camera looking along the head's x axis.
  Eigen::Matrix4d T_head_camera = Eigen::Matrix4d::Identity();
  /// T_projector_camera: camera-projector extrinsics (R_cp, T_cp of the paper's Eq. 2). Rigid.
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();
  double pan_min_rad = -2.7733;  ///< PTU-D46-17: -3090 positions of 185.1428 arc-seconds
  double pan_max_rad = 2.7733;
  double tilt_min_rad = -0.8140;  ///< -907 positions (down)
  double tilt_max_rad = 0.5417;   ///< +604 positions (up)
  double step_rad = 8.9759e-4;    ///< 185.1428 arc-seconds per position
};

/// The default simulated rig: the mount 0.55 m above the base origin, 0.15 m forward; the camera
/// 4 cm ahead of the tilt axis; the projector 8 cm above the camera, parallel to it.
PanTiltConfig default_pan_tilt();

}  // namespace projbot::config
