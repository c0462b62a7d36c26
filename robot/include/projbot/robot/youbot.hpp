#pragma once
// KUKA youBot omnidirectional base: mecanum-wheel kinematics and wheel odometry.
// Parameters are youbot_driver's published ones (FourSwedishWheelOmniBaseKinematicConfiguration).

#include <array>
#include <cstdint>

#include "projbot/robot/pose2d.hpp"

namespace projbot::robot {

/// Base velocity in the base frame: x forward, y left, counter-clockwise omega.
struct BaseTwist {
  double vx_m_s = 0.0;
  double vy_m_s = 0.0;
  double omega_rad_s = 0.0;
};

/// Four wheel angular velocities (rad/s of the wheel, after the gearbox), ordered
/// left-front, right-front, left-back, right-back; youbot_driver's sign convention (the left
/// wheels turn negative to drive forward).
using WheelSpeeds = std::array<double, 4>;

/// Encoder counts of the four motors, same order; 4000 ticks per motor turn.
using WheelTicks = std::array<std::int64_t, 4>;

/// youBot geometry.
struct YoubotGeometry {
  double wheel_radius_m = 0.0475;
  double front_rear_m = 0.47;          ///< distance between front and rear axles
  double left_right_m = 0.30;          ///< distance between left and right wheels
  double gear_ratio = 364.0 / 9405.0;  ///< wheel turns per motor turn
  double ticks_per_motor_turn = 4000.0;
  double max_wheel_speed_rad_s = 14.0;  ///< about 0.66 m/s at the rim; a software limit, not the motor's
  /// (front_rear + left_right) / 2 = 0.385 m: lever arm of rotation for mecanum wheels.
  double geometric_factor_m() const { return (front_rear_m + left_right_m) / 2.0; }
  /// Wheel angle per encoder tick, radians.
  double rad_per_tick() const;
};

/// Inverse kinematics: the wheel speeds that produce `twist`.
WheelSpeeds wheel_speeds_from_twist(const BaseTwist& twist, const YoubotGeometry& geometry = {});

/// Forward kinematics: the base twist that wheel speeds produce (least squares for the
/// over-determined four-wheel case; exact when the speeds are consistent).
BaseTwist twist_from_wheel_speeds(const WheelSpeeds& wheels, const YoubotGeometry& geometry = {});

/// Scales a twist down uniformly so that no wheel exceeds the wheel-speed limit.
BaseTwist limit_twist(const BaseTwist& twist, const YoubotGeometry& geometry = {});

/// Pose change of a constant twist held for dt, in the frame the motion started from
/// (exact SE(2) exponential, not Euler).
Pose2D integrate_twist(const BaseTwist& twist, double dt_s);

/// Wheel odometry from encoder ticks. The first reading sets the reference; each later one
/// moves the pose by the forward kinematics of the tick differences.
class WheelOdometry {
 public:
  explicit WheelOdometry(const YoubotGeometry& geometry = {}, const Pose2D& start = {});
  /// Feeds a reading; returns the odometry pose (world frame of the odometry, which drifts).
  const Pose2D& update(const WheelTicks& ticks);
  const Pose2D& pose() const { return pose_; }

 private:
  YoubotGeometry geometry_;
  Pose2D pose_;
  WheelTicks last_{};
  bool has_last_ = false;
};

}  // namespace projbot::robot
