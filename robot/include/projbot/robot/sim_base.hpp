#pragma once
// The youBot's simulated twin: true motion departs from commanded and measured motion.

#include <cstdint>
#include <random>

#include "projbot/robot/base.hpp"

namespace projbot::robot {

/// Error model of the simulated base. Systematic terms stay fixed for a run, as a real base's
/// do (wheel radius tolerance, carpet slip, a misaligned roller); random terms are per step.
struct BaseErrorModel {
  std::uint64_t seed = 1;
  double wheel_scale_sigma = 0.01;         ///< per-wheel effective radius error, relative (1 sigma, drawn once)
  double slip_scale = 0.02;                ///< ground motion short of wheel motion, relative (systematic)
  double heading_bias_rad_per_m = 0.01;    ///< systematic yaw drift per metre travelled
  double heading_bias_rad_per_rad = 0.01;  ///< systematic yaw drift per radian turned
  /// Random walks, independent of the step size: variance grows with the motion (per metre
  /// travelled plus radian turned), as for a real base.
  double random_translation_sigma = 0.003;  ///< metres per sqrt(metre + radian)
  double random_rotation_sigma = 0.003;     ///< radians per sqrt(metre + radian)
  /// An error-free base (odometry equals truth up to encoder quantisation).
  static BaseErrorModel none() { return {0, 0, 0, 0, 0, 0, 0}; }
};

/// Simulated base. Time advances only through advance(). Encoders count the wheels' true
/// rotation; the ground motion differs by slip and bias, so wheel odometry drifts.
class SimulatedBase final : public MobileBase {
 public:
  SimulatedBase(const Pose2D& true_start, const BaseErrorModel& errors = {}, const YoubotGeometry& geometry = {});
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
  BaseErrorModel errors_;
  std::mt19937_64 rng_;
  std::array<double, 4> wheel_scale_{1, 1, 1, 1};
  Pose2D true_pose_;
  WheelSpeeds command_{};
  std::array<double, 4> wheel_angle_rad_{};
};

}  // namespace projbot::robot
