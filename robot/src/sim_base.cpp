#include "projbot/robot/sim_base.hpp"

#include <cmath>

namespace projbot::robot {

SimulatedBase::SimulatedBase(const Pose2D& true_start, const config::OdometryDrift& errors, const YoubotGeometry& geometry)
    : geometry_(geometry), errors_(errors), rng_(errors.seed), true_pose_(true_start) {
  std::normal_distribution<double> n(0.0, 1.0);
  for (double& s : wheel_scale_) s = 1.0 + errors_.wheel_scale_sigma * n(rng_);
}

void SimulatedBase::set_wheel_speeds(const WheelSpeeds& speeds) { command_ = speeds; }

WheelTicks SimulatedBase::read_encoders() {
  WheelTicks t{};
  for (std::size_t i = 0; i < 4; ++i) t[i] = std::llround(std::floor(wheel_angle_rad_[i] / geometry_.rad_per_tick()));
  return t;
}

void SimulatedBase::advance(double dt_s) {
  if (!(dt_s > 0.0)) return;
  // The velocity-controlled motors turn as commanded: that is what the encoders see.
  WheelSpeeds effective{};
  for (std::size_t i = 0; i < 4; ++i) {
    wheel_angle_rad_[i] += command_[i] * dt_s;
    effective[i] = command_[i] * wheel_scale_[i];  // the ground sees each wheel's true radius
  }
  const BaseTwist nominal = twist_from_wheel_speeds(effective, geometry_);
  const double travel = std::hypot(nominal.vx_m_s, nominal.vy_m_s) * dt_s;
  const double turn = std::abs(nominal.omega_rad_s) * dt_s;
  std::normal_distribution<double> n(0.0, 1.0);
  const double walk = std::sqrt(travel + turn);
  double scale = 1.0 - errors_.slip_scale;
  if (travel > 0.0) scale += errors_.random_translation_sigma * walk * n(rng_) / travel;
  BaseTwist truth{nominal.vx_m_s * scale, nominal.vy_m_s * scale, nominal.omega_rad_s};
  truth.omega_rad_s += (errors_.heading_bias_rad_per_m * travel + errors_.heading_bias_rad_per_rad * turn +
                        errors_.random_rotation_sigma * walk * n(rng_)) /
                       dt_s;
  true_pose_ = compose(true_pose_, integrate_twist(truth, dt_s));
}

}  // namespace projbot::robot
