#include "projbot/robot/pose2d.hpp"

#include <cmath>
#include <numbers>

namespace projbot::robot {

double wrap_angle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);  // [-pi, pi]
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

Pose2D compose(const Pose2D& a, const Pose2D& b) {
  const double c = std::cos(a.theta_rad), s = std::sin(a.theta_rad);
  return {a.x_m + c * b.x_m - s * b.y_m, a.y_m + s * b.x_m + c * b.y_m, wrap_angle(a.theta_rad + b.theta_rad)};
}

Pose2D inverse(const Pose2D& a) {
  const double c = std::cos(a.theta_rad), s = std::sin(a.theta_rad);
  return {-c * a.x_m - s * a.y_m, s * a.x_m - c * a.y_m, wrap_angle(-a.theta_rad)};
}

Pose2D between(const Pose2D& a, const Pose2D& b) { return compose(inverse(a), b); }

double distance_m(const Pose2D& a, const Pose2D& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

double heading_error_rad(const Pose2D& a, const Pose2D& b) { return std::abs(wrap_angle(a.theta_rad - b.theta_rad)); }

Eigen::Isometry3d to_isometry(const Pose2D& pose) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(pose.theta_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(pose.x_m, pose.y_m, 0.0);
  return T;
}

}  // namespace projbot::robot
