#pragma once
// Planar poses of the base in the map (world) frame: x forward, y left, z up (REP-103).

#include <Eigen/Geometry>

namespace projbot::robot {

/// A pose in the plane: T_world_base as (x, y, theta). Metres and radians; theta in (-pi, pi].
struct Pose2D {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;
};

/// Wraps an angle into (-pi, pi].
double wrap_angle(double angle_rad);

/// a (+) b: b expressed in a's frame, moved into a's parent frame (T_w_a * T_a_b).
Pose2D compose(const Pose2D& a, const Pose2D& b);

/// The inverse transform.
Pose2D inverse(const Pose2D& a);

/// The motion from a to b in a's frame: inverse(a) (+) b.
Pose2D between(const Pose2D& a, const Pose2D& b);

/// Euclidean distance between the positions, metres.
double distance_m(const Pose2D& a, const Pose2D& b);

/// |theta_a - theta_b| wrapped, radians.
double heading_error_rad(const Pose2D& a, const Pose2D& b);

/// The 3-D rigid transform of a planar pose (rotation about z, z = 0).
Eigen::Isometry3d to_isometry(const Pose2D& pose);

}  // namespace projbot::robot
