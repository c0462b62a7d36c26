#pragma once
// The youBot's simulated twin: true motion departs from commanded and measured motion.

#include <cstdint>
#include <random>

#include "projbot/config/odometry_drift.hpp"
#include "projbot/robot/base.hpp"

namespace projbot::robot {

/// Simulated base. Time advances only through advance(). Encoders count the wheels' true
/// rotation; the ground motion differs by slip and bias, so wheel odometry drifts.
class SimulatedBase final : public MobileBase {
 public:
  SimulatedBase(const Pose2D& true_start, const config::OdometryDrift& errors = {}, const YoubotGeometry& geometry = {});
  void set_wheel_speeds(const WheelSpeeds& speeds) override;
  WheelTicks read_encoders() override;
  const YoubotGeometry& geometry() const override { return geometry_; }

  /// Moves the simulation forward by dt seconds under the last command.
  void advance(double dt_s);
  /// Ground truth T_world_base.
  const Pose2D& true_pose() const { return true_pose_; }
  /// The command currently held.
  const WheelSpeeds& commanded() const { return command_; }

 private:
  YoubotGeometry geometry_;
  config::OdometryDrift errors_;
  std::mt19937_64 rng_;
  std::array<double, 4> wheel_scale_{1, 1, 1, 1};
  Pose2D true_pose_;
  WheelSpeeds command_{};
  std::array<double, 4> wheel_angle_rad_{};
};

}  // namespace projbot::robot
