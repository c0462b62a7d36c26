#include "projbot/robot/youbot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace projbot::robot {

double YoubotGeometry::rad_per_tick() const { return 2.0 * std::numbers::pi * gear_ratio / ticks_per_motor_turn; }

// youbot_driver's FourSwedishWheelOmniBaseKinematic: with X = vx/r, Y = vy/r, W = omega g/r,
// wheels (lf, rf, lb, rb) = (-X + Y + W, X + Y + W, -X - Y + W, X - Y + W).
WheelSpeeds wheel_speeds_from_twist(const BaseTwist& t, const YoubotGeometry& g) {
  const double x = t.vx_m_s / g.wheel_radius_m;
  const double y = t.vy_m_s / g.wheel_radius_m;
  const double w = t.omega_rad_s * g.geometric_factor_m() / g.wheel_radius_m;
  return {-x + y + w, x + y + w, -x - y + w, x - y + w};
}

// The pseudo-inverse of the matrix above (its columns are orthogonal, each of norm 2).
BaseTwist twist_from_wheel_speeds(const WheelSpeeds& w, const YoubotGeometry& g) {
  const double r = g.wheel_radius_m;
  return {(-w[0] + w[1] - w[2] + w[3]) * r / 4.0, (w[0] + w[1] - w[2] - w[3]) * r / 4.0,
          (w[0] + w[1] + w[2] + w[3]) * r / (4.0 * g.geometric_factor_m())};
}

BaseTwist limit_twist(const BaseTwist& t, const YoubotGeometry& g) {
  const WheelSpeeds w = wheel_speeds_from_twist(t, g);
  double peak = 0.0;
  for (double s : w) peak = std::max(peak, std::abs(s));
  if (peak <= g.max_wheel_speed_rad_s) return t;
  const double k = g.max_wheel_speed_rad_s / peak;
  return {t.vx_m_s * k, t.vy_m_s * k, t.omega_rad_s * k};
}

Pose2D integrate_twist(const BaseTwist& t, double dt) {
  const double th = t.omega_rad_s * dt;
  const double vx = t.vx_m_s * dt, vy = t.vy_m_s * dt;
  // SE(2) exponential: V = [[sin th / th, -(1 - cos th) / th], [(1 - cos th) / th, sin th / th]].
  double a = 1.0, b = 0.0;
  if (std::abs(th) > 1e-9) {
    a = std::sin(th) / th;
    b = (1.0 - std::cos(th)) / th;
  } else {
    b = th / 2.0;
  }
  return {a * vx - b * vy, b * vx + a * vy, wrap_angle(th)};
}

WheelOdometry::WheelOdometry(const YoubotGeometry& geometry, const Pose2D& start) : geometry_(geometry), pose_(start) {}

const Pose2D& WheelOdometry::update(const WheelTicks& ticks) {
  if (has_last_) {
    WheelSpeeds delta_rad{};  // wheel angle change over the interval; as a "speed" over dt = 1
    for (std::size_t i = 0; i < 4; ++i) delta_rad[i] = static_cast<double>(ticks[i] - last_[i]) * geometry_.rad_per_tick();
    pose_ = compose(pose_, integrate_twist(twist_from_wheel_speeds(delta_rad, geometry_), 1.0));
  }
  last_ = ticks;
  has_last_ = true;
  return pose_;
}

}  // namespace projbot::robot
