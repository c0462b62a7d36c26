#include "projbot/config/robot.hpp"

#include <Eigen/Geometry>

namespace projbot::config {

PanTiltConfig default_pan_tilt() {
  PanTiltConfig c;
  c.T_base_mount.block<3, 1>(0, 3) = Eigen::Vector3d(0.15, 0.0, 0.55);
  // The optical frame looks along head x: z_cam = x_head, x_cam = -y_head, y_cam = -z_head.
  Eigen::Matrix3d R_head_camera;
  R_head_camera << 0, 0, 1,  //
      -1, 0, 0,              //
      0, -1, 0;
  c.T_head_camera.block<3, 3>(0, 0) = R_head_camera;
  c.T_head_camera.block<3, 1>(0, 3) = Eigen::Vector3d(0.04, 0.0, 0.0);
  // Projector 8 cm above the camera (camera y points down): X_p = X_c + (0, 0.08, 0).
  c.T_projector_camera.block<3, 1>(0, 3) = Eigen::Vector3d(0.0, 0.08, 0.0);
  return c;
}

}  // namespace projbot::config
