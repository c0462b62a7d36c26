#include "projbot/robot/base.hpp"

#include <algorithm>
#include <cmath>

namespace projbot::robot {
namespace {

// Speed that still allows stopping within `distance` at `decel`, capped by the limit and by
// a proportional term that makes the last centimetres smooth instead of bang-bang.
double profile_speed(double distance, double limit, double decel, double gain) {
  return std::min({limit, std::sqrt(2.0 * decel * distance), gain * distance});
}

double step_towards(double from, double to, double max_step) { return from + std::clamp(to - from, -max_step, max_step); }

}  // namespace

BaseController::BaseController(const ControllerConfig& config, const YoubotGeometry& geometry)
    : config_(config), geometry_(geometry) {}

BaseTwist BaseController::update(const Pose2D& estimate, const Pose2D& goal, double dt_s) {
  const double dx = goal.x_m - estimate.x_m, dy = goal.y_m - estimate.y_m;
  const double distance = std::hypot(dx, dy);
  const double dtheta = wrap_angle(goal.theta_rad - estimate.theta_rad);
  arrived_ = distance < config_.position_tolerance_m && std::abs(dtheta) < config_.heading_tolerance_rad;

  BaseTwist want;
  if (!arrived_) {
    const double speed = profile_speed(distance, config_.max_speed_m_s, config_.max_accel_m_s2, config_.slow_down_gain);
    const double omega =
        profile_speed(std::abs(dtheta), config_.max_omega_rad_s, config_.max_alpha_rad_s2, config_.slow_down_gain);
    // The goal direction in the base frame.
    const double c = std::cos(estimate.theta_rad), s = std::sin(estimate.theta_rad);
    const double bx = c * dx + s * dy, by = -s * dx + c * dy;
    if (distance > 1e-9) {
      want.vx_m_s = speed * bx / distance;
      want.vy_m_s = speed * by / distance;
    }
    want.omega_rad_s = std::copysign(omega, dtheta);
  }
  // Acceleration limits, then the wheels' own limit.
  const double dv = config_.max_accel_m_s2 * dt_s, dw = config_.max_alpha_rad_s2 * dt_s;
  BaseTwist cmd{step_towards(last_.vx_m_s, want.vx_m_s, dv), step_towards(last_.vy_m_s, want.vy_m_s, dv),
                step_towards(last_.omega_rad_s, want.omega_rad_s, dw)};
  cmd = limit_twist(cmd, geometry_);
  last_ = cmd;
  return cmd;
}

bool drive_loop(BaseController& controller, DriveSteps& steps, const Pose2D& goal, double timeout_s,
                const std::function<void(const Pose2D&)>& watch) {
  controller.reset();
  for (long step = 0;; ++step) {
    steps.sense(step);
    if (watch) watch(steps.believed_pose());
    const BaseTwist cmd = controller.update(steps.believed_pose(), goal, steps.step_s());
    if (controller.arrived() || steps.elapsed_s() > timeout_s) break;
    steps.command(cmd);
  }
  steps.halt();
  const bool arrived = controller.arrived();
  steps.settle();
  return arrived;
}

}  // namespace projbot::robot
