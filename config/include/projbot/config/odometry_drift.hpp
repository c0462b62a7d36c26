#pragma once
// How a wheeled base's odometry departs from its true motion: the one model of it, read from a scene's
// `robot.drift:` and driven by the simulated base (robot::SimulatedBase).

#include <cstdint>

namespace projbot::config {

/// Systematic terms stay fixed for a run, as a real base's do (wheel radius tolerance, carpet slip, a
/// misaligned roller); random terms are per step. The defaults are a worn base on carpet (the robot
/// benches'); good_floor() is a scene's default.
struct OdometryDrift {
  std::uint64_t seed = 1;                  ///< the simulated base's random draws
  double wheel_scale_sigma = 0.01;         ///< per-wheel effective radius error, relative (1 sigma, drawn once)
  double slip_scale = 0.02;                ///< ground motion short of wheel motion, relative (systematic)
  double heading_bias_rad_per_m = 0.01;    ///< systematic yaw drift per metre travelled
  double heading_bias_rad_per_rad = 0.01;  ///< systematic yaw drift per radian turned
  /// Random walks, independent of the step size: variance grows with the motion (per metre travelled
  /// plus radian turned), as for a real base.
  double random_translation_sigma = 0.003;  ///< metres per sqrt(metre + radian)
  double random_rotation_sigma = 0.003;     ///< radians per sqrt(metre + radian)

  /// An error-free base (odometry equals truth up to encoder quantisation).
  static OdometryDrift none() { return {0, 0, 0, 0, 0, 0, 0}; }
  /// A base on a good floor: half the defaults' systematic terms, two thirds of their random walk.
  static OdometryDrift good_floor() { return {1, 0.005, 0.01, 0.005, 0.005, 0.002, 0.002}; }
};

}  // namespace projbot::config
