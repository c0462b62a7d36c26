#include "projbot/alignment/motion_model.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <vector>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/angles.hpp"

namespace projbot::alignment {
namespace {

Eigen::Vector3d clamp_norm(const Eigen::Vector3d& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Eigen::Vector3d(v * (max_norm / n)) : v;
}

// The two-point start of a constant-velocity filter: value measured (variance r^2), rate from the
// difference of two measurements dt apart (variance 2 r^2 / dt^2), correlated.
Eigen::Matrix2d two_point_covariance(double r, double dt) {
  const double r2 = r * r;
  Eigen::Matrix2d P;
  P << r2, r2 / dt, r2 / dt, 2.0 * r2 / (dt * dt);
  return P;
}

// Kalman prediction of (value, rate) under white acceleration of spectral density q^2.
Eigen::Matrix2d propagate(const Eigen::Matrix2d& P, double dt, double q) {
  Eigen::Matrix2d F;
  F << 1.0, dt, 0.0, 1.0;
  Eigen::Matrix2d Q;
  Q << dt * dt * dt / 3.0, dt * dt / 2.0, dt * dt / 2.0, dt;
  return F * P * F.transpose() + q * q * Q;
}

}  // namespace

Eigen::Matrix4d predict_pose(const MotionState& state, double t_s) {
  if (!state.moving()) return state.T;
  const double h = std::clamp(t_s - state.time_s, 0.0, state.max_horizon_s);
  Eigen::Matrix4d T = state.T;
  T.topLeftCorner<3, 3>() = exp_so3(state.angular_velocity_rad_s * h) * state.T.topLeftCorner<3, 3>();
  T.topRightCorner<3, 1>() += state.velocity_m_s * h;
  return T;
}

MotionFilter::MotionFilter(MotionModelConfig config)
    : cfg_(config), position_noise_(cfg_.position_noise_m), rotation_noise_(cfg_.rotation_noise_rad) {}

void MotionFilter::reset() {
  count_ = 0;
  confirmed_ = true;
  measured_ = filtered_ = Eigen::Matrix4d::Identity();
  window_.clear();
  history_.clear();
  position_noise_ = cfg_.position_noise_m;
  rotation_noise_ = cfg_.rotation_noise_rad;
  translation_ = {};
  rotation_ = {};
}

void MotionFilter::restart_velocity(const Eigen::Matrix4d& T, double dt) {
  translation_.rate = (T.topRightCorner<3, 1>() - measured_.topRightCorner<3, 1>()) / dt;
  rotation_.rate = log_so3(T.topLeftCorner<3, 3>() * measured_.topLeftCorner<3, 3>().transpose()) / dt;
  translation_.P = two_point_covariance(position_noise_, dt);
  rotation_.P = two_point_covariance(rotation_noise_, dt);
  filtered_ = T;
}

bool MotionFilter::jumped(const Eigen::Matrix4d& T, double dt) const {
  const Eigen::Matrix4d step = rigid_inverse(measured_) * T;  // its length and angle are the move's and turn's
  return translation_norm_m(step) > cfg_.jump_factor * cfg_.max_speed_m_s * dt ||
         rotation_angle_deg(step) > cfg_.jump_factor * cfg_.max_rate_deg_s * dt;
}

void MotionFilter::predict_to(double dt) {
  filtered_.topLeftCorner<3, 3>() = exp_so3(rotation_.rate * dt) * filtered_.topLeftCorner<3, 3>();
  filtered_.topRightCorner<3, 1>() += translation_.rate * dt;
  translation_.P = propagate(translation_.P, dt, cfg_.accel_noise);
  rotation_.P = propagate(rotation_.P, dt, cfg_.angular_accel_noise);
}

void MotionFilter::update(const Eigen::Matrix4d& T, double t_s) {
  const double dt = t_s - t_;
  if (count_ > 0 && !(dt > 0.0 && dt <= cfg_.max_gap_s)) reset();
  if (count_ > 0 && jumped(T, dt)) {
    ++jumps_;
    reset();
  }
  if (count_ == 0) {
    filtered_ = T;
  } else if (count_ == 1) {
    restart_velocity(T, dt);
  } else {
    correct(T, dt);
  }
  measured_ = T;
  t_ = t_s;
  ++count_;
  window_.push_back({t_s, T});
  while (window_.size() > 2 && t_s - window_[1].t_s >= cfg_.stillness_window_s) window_.pop_front();
  history_.push_back({t_s, T});
  while (history_.size() > static_cast<std::size_t>(std::max(cfg_.noise_window, 0))) history_.pop_front();
  measure_noise();
}

// The filter's correction by a pose dt after the last: a Kalman update, or a restart of the velocity from
// the last two poses when the pose breaks the prediction (a start or a stop), which is not confirmed
// until a later pose agrees with the motion restarted from it.
void MotionFilter::correct(const Eigen::Matrix4d& T, double dt) {
  predict_to(dt);
  // Innovations: the measured pose against the predicted one (rotation as a rotation vector).
  const Eigen::Vector3d y_t = T.topRightCorner<3, 1>() - filtered_.topRightCorner<3, 1>();
  const Eigen::Vector3d y_r = log_so3(T.topLeftCorner<3, 3>() * filtered_.topLeftCorner<3, 3>().transpose());
  const double s_t = translation_.P(0, 0) + position_noise_ * position_noise_;
  const double s_r = rotation_.P(0, 0) + rotation_noise_ * rotation_noise_;
  const bool outside = y_t.squaredNorm() / s_t > cfg_.maneuver_gate || y_r.squaredNorm() / s_r > cfg_.maneuver_gate;
  confirmed_ = !outside;
  if (outside) {
    ++maneuvers_;
    restart_velocity(T, dt);  // a start or a stop: what the last frame interval says, nothing older
    return;
  }
  const Eigen::Vector2d k_t = translation_.P.col(0) / s_t, k_r = rotation_.P.col(0) / s_r;
  filtered_.topRightCorner<3, 1>() += k_t(0) * y_t;
  translation_.rate += k_t(1) * y_t;
  filtered_.topLeftCorner<3, 3>() = exp_so3(k_r(0) * y_r) * filtered_.topLeftCorner<3, 3>();
  rotation_.rate += k_r(1) * y_r;
  translation_.P -= k_t * translation_.P.row(0);
  rotation_.P -= k_r * rotation_.P.row(0);
}

void MotionFilter::measure_noise() {
  // Second differences, a - b - r (b - c) with r the ratio of the frame intervals: zero for a steady
  // motion, 1 + (1 + r)^2 + r^2 times the per-frame variance for noise (6 at even intervals). The norm of
  // a 3-D normal vector with sigma s per axis has median 1.538 s.
  if (history_.size() < static_cast<std::size_t>(kNoisePoses)) return;
  std::vector<double> moves, turns;
  for (std::size_t i = 2; i < history_.size(); ++i) {
    const Stamped &a = history_[i], &b = history_[i - 1], &c = history_[i - 2];
    const double r = (a.t_s - b.t_s) / (b.t_s - c.t_s);
    const double spread = std::sqrt(1.0 + (1.0 + r) * (1.0 + r) + r * r);
    const Eigen::Vector3d move =
        a.T.topRightCorner<3, 1>() - b.T.topRightCorner<3, 1>() - r * (b.T.topRightCorner<3, 1>() - c.T.topRightCorner<3, 1>());
    const Eigen::Vector3d turn = log_so3(a.T.topLeftCorner<3, 3>() * b.T.topLeftCorner<3, 3>().transpose()) -
                                 r * log_so3(b.T.topLeftCorner<3, 3>() * c.T.topLeftCorner<3, 3>().transpose());
    moves.push_back(move.norm() / spread);
    turns.push_back(turn.norm() / spread);
  }
  const auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  position_noise_ = std::max(cfg_.position_noise_m, median(moves) / 1.538);
  rotation_noise_ = std::max(cfg_.rotation_noise_rad, median(turns) / 1.538);
}

// The window's motion: how far the newest pose is from the oldest, and the least-squares velocity of its
// poses with the spread of their times (a slope's variance is the pose noise's over it).
MotionFilter::WindowMotion MotionFilter::window_motion() const {
  WindowMotion m;
  const Eigen::Matrix4d& oldest = window_.front().T;
  const Eigen::Matrix3d R_inv = measured_.topLeftCorner<3, 3>().transpose();
  m.span_s = t_ - window_.front().t_s;
  m.moved_m = (measured_.topRightCorner<3, 1>() - oldest.topRightCorner<3, 1>()).norm();
  m.turned_rad = log_so3(oldest.topLeftCorner<3, 3>() * R_inv).norm();
  double mean_t = 0.0;
  for (const auto& w : window_) mean_t += w.t_s / static_cast<double>(window_.size());
  for (const auto& w : window_) {
    const double d = w.t_s - mean_t;
    m.time_spread_s2 += d * d;
    m.velocity_m_s += d * w.T.topRightCorner<3, 1>();
    m.angular_velocity_rad_s += d * log_so3(w.T.topLeftCorner<3, 3>() * R_inv);
  }
  if (m.time_spread_s2 > 0.0) {
    m.velocity_m_s /= m.time_spread_s2;
    m.angular_velocity_rad_s /= m.time_spread_s2;
  }
  return m;
}

// A part of the motion (translation or rotation) stands out of the noise when the newest pose is
// farther from the oldest than still_sigmas times their difference's noise (sqrt(2) times a pose's) and
// than the minimum speed over the window, and the window's velocity is farther from zero than
// velocity_gate allows its noise to take it.
bool MotionFilter::stands_out(double moved, const Eigen::Vector3d& velocity, double noise, double min_rate,
                              const WindowMotion& m) const {
  if (moved <= std::max(cfg_.still_sigmas * M_SQRT2 * noise, min_rate * m.span_s)) return false;
  return m.time_spread_s2 > 0.0 && velocity.squaredNorm() * m.time_spread_s2 > cfg_.velocity_gate * noise * noise;
}

MotionState MotionFilter::state() const {
  MotionState s;
  s.T = measured_;
  s.time_s = t_;
  s.max_horizon_s = cfg_.max_horizon_s;
  if (count_ < std::max(2, cfg_.min_poses)) return s;
  // Each part of the motion is used only when it stands out of the measurement noise over the window;
  // the other part stays as measured, so a target that only turns is not also slid by noise.
  const WindowMotion m = window_motion();
  const bool translating = stands_out(m.moved_m, m.velocity_m_s, position_noise_, cfg_.min_speed_m_s, m);
  const bool turning =
      stands_out(m.turned_rad, m.angular_velocity_rad_s, rotation_noise_, config::radians(cfg_.min_rate_deg_s), m);
  // A still part whose measured noise is well above the configured one: the mean of the window's poses.
  if (!translating && position_noise_ > cfg_.average_above * cfg_.position_noise_m) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& w : window_) sum += w.T.topRightCorner<3, 1>();
    s.T.topRightCorner<3, 1>() = sum / static_cast<double>(window_.size());
  }
  if (!turning && rotation_noise_ > cfg_.average_above * cfg_.rotation_noise_rad) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const auto& w : window_) sum += log_so3(w.T.topLeftCorner<3, 3>() * measured_.topLeftCorner<3, 3>().transpose());
    s.T.topLeftCorner<3, 3>() = exp_so3(sum / static_cast<double>(window_.size())) * measured_.topLeftCorner<3, 3>();
  }
  if (translating) {
    s.T.topRightCorner<3, 1>() = filtered_.topRightCorner<3, 1>();
    s.velocity_m_s = clamp_norm(translation_.rate, cfg_.max_speed_m_s);
  }
  if (turning) {
    s.T.topLeftCorner<3, 3>() = filtered_.topLeftCorner<3, 3>();
    s.angular_velocity_rad_s = clamp_norm(rotation_.rate, config::radians(cfg_.max_rate_deg_s));
  }
  return s;
}

MotionState MotionFilter::drawn_state() const {
  if (cfg_.noise_window >= kNoisePoses && history_.size() < static_cast<std::size_t>(kNoisePoses)) {
    MotionState s;
    s.T = measured_;
    s.time_s = t_;
    s.max_horizon_s = cfg_.max_horizon_s;
    return s;
  }
  return state();
}

}  // namespace projbot::alignment
