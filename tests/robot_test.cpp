// youBot kinematics and odometry, the stop controller, pan-tilt aiming and the simulated units.
#include "projbot/config/robot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "projbot/robot/base.hpp"
#include "projbot/robot/pan_tilt.hpp"
#include "projbot/robot/sim_base.hpp"
#include "projbot/robot/youbot.hpp"

namespace {

using namespace projbot::robot;
constexpr double kPi = std::numbers::pi;
double deg(double d) { return d * kPi / 180.0; }

TEST(YoubotKinematics, KnownCases) {
  const YoubotGeometry g;
  EXPECT_DOUBLE_EQ(g.geometric_factor_m(), 0.385);
  // Forward at 0.1 m/s: every wheel at 0.1 / 0.0475 rad/s, the left ones negative.
  const WheelSpeeds fwd = wheel_speeds_from_twist({0.1, 0.0, 0.0});
  const double s = 0.1 / 0.0475;
  EXPECT_NEAR(fwd[0], -s, 1e-12);
  EXPECT_NEAR(fwd[1], s, 1e-12);
  EXPECT_NEAR(fwd[2], -s, 1e-12);
  EXPECT_NEAR(fwd[3], s, 1e-12);
  // Sideways to the left: front wheels +, back wheels -.
  const WheelSpeeds left = wheel_speeds_from_twist({0.0, 0.1, 0.0});
  EXPECT_NEAR(left[0], s, 1e-12);
  EXPECT_NEAR(left[1], s, 1e-12);
  EXPECT_NEAR(left[2], -s, 1e-12);
  EXPECT_NEAR(left[3], -s, 1e-12);
  // Turning at 1 rad/s: all wheels at 0.385 / 0.0475 rad/s.
  for (double w : wheel_speeds_from_twist({0.0, 0.0, 1.0})) EXPECT_NEAR(w, 0.385 / 0.0475, 1e-12);
  // One encoder tick is 2 pi * 364/9405 / 4000 rad of the wheel.
  EXPECT_NEAR(g.rad_per_tick(), 2 * kPi * 364.0 / 9405.0 / 4000.0, 1e-15);
}

TEST(YoubotKinematics, RoundTripAndLeastSquares) {
  for (const BaseTwist t : {BaseTwist{0.3, -0.2, 0.7}, BaseTwist{-0.05, 0.4, -1.2}, BaseTwist{0, 0, 0}}) {
    const BaseTwist back = twist_from_wheel_speeds(wheel_speeds_from_twist(t));
    EXPECT_NEAR(back.vx_m_s, t.vx_m_s, 1e-12);
    EXPECT_NEAR(back.vy_m_s, t.vy_m_s, 1e-12);
    EXPECT_NEAR(back.omega_rad_s, t.omega_rad_s, 1e-12);
  }
  // Inconsistent wheel speeds (one wheel slipping): the least-squares twist, not a wheel's own.
  const BaseTwist t = twist_from_wheel_speeds({-2.0, 2.0, -2.0, 3.0});
  EXPECT_NEAR(t.vx_m_s, 9.0 * 0.0475 / 4.0, 1e-12);
}

TEST(YoubotKinematics, WheelLimitScalesUniformly) {
  const YoubotGeometry g;
  const BaseTwist fast{2.0, 1.0, 1.0};
  const BaseTwist limited = limit_twist(fast, g);
  double peak = 0;
  for (double w : wheel_speeds_from_twist(limited, g)) peak = std::max(peak, std::abs(w));
  EXPECT_NEAR(peak, g.max_wheel_speed_rad_s, 1e-9);
  EXPECT_NEAR(limited.vx_m_s / limited.vy_m_s, 2.0, 1e-12);  // direction kept
  const BaseTwist slow{0.1, 0.0, 0.0};
  EXPECT_EQ(limit_twist(slow, g).vx_m_s, 0.1);
}

TEST(YoubotKinematics, IntegrateTwistIsExactOnArcs) {
  // 1 m/s forward while turning pi/2 rad/s for 1 s: a quarter circle of radius 2/pi.
  const Pose2D p = integrate_twist({1.0, 0.0, kPi / 2}, 1.0);
  EXPECT_NEAR(p.x_m, 2.0 / kPi, 1e-12);
  EXPECT_NEAR(p.y_m, 2.0 / kPi, 1e-12);
  EXPECT_NEAR(p.theta_rad, kPi / 2, 1e-12);
}

TEST(Pose2D, ComposeInverseBetween) {
  const Pose2D a{1.0, 2.0, deg(90)}, b{0.5, 0.0, deg(-30)};
  const Pose2D ab = compose(a, b);
  EXPECT_NEAR(ab.x_m, 1.0, 1e-12);
  EXPECT_NEAR(ab.y_m, 2.5, 1e-12);
  EXPECT_NEAR(ab.theta_rad, deg(60), 1e-12);
  const Pose2D back = between(a, ab);
  EXPECT_NEAR(back.x_m, b.x_m, 1e-12);
  EXPECT_NEAR(back.y_m, b.y_m, 1e-12);
  EXPECT_NEAR(back.theta_rad, b.theta_rad, 1e-12);
  EXPECT_NEAR(wrap_angle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrap_angle(-kPi), kPi, 1e-12);
}

// Drives a simulated base through a square (1 m forward, turn 90 degrees, four times) by
// commanded twists; returns {truth, odometry} at the end.
std::pair<Pose2D, Pose2D> drive_square(const projbot::config::OdometryDrift& errors) {
  SimulatedBase base({0, 0, 0}, errors);
  WheelOdometry odo(base.geometry());
  odo.update(base.read_encoders());
  const double dt = 0.01;
  for (int side = 0; side < 4; ++side) {
    base.set_wheel_speeds(wheel_speeds_from_twist({0.25, 0.0, 0.0}));
    for (int i = 0; i < 400; ++i) {
      base.advance(dt);
      odo.update(base.read_encoders());
    }
    base.set_wheel_speeds(wheel_speeds_from_twist({0.0, 0.0, kPi / 4}));
    for (int i = 0; i < 200; ++i) {
      base.advance(dt);
      odo.update(base.read_encoders());
    }
  }
  return {base.true_pose(), odo.pose()};
}

TEST(WheelOdometry, SquareClosesOnAnIdealBase) {
  const auto [truth, odo] = drive_square(projbot::config::OdometryDrift::none());
  // Encoder quantisation (61 urad of wheel per tick, 3 um at the rim) is all that remains.
  EXPECT_NEAR(truth.x_m, 0.0, 1e-6);
  EXPECT_NEAR(truth.y_m, 0.0, 1e-6);
  EXPECT_NEAR(odo.x_m, 0.0, 1e-4);
  EXPECT_NEAR(odo.y_m, 0.0, 1e-4);
  EXPECT_NEAR(wrap_angle(odo.theta_rad), 0.0, 1e-4);
}

TEST(WheelOdometry, DriftsFromTruthOnASlippingBase) {
  projbot::config::OdometryDrift errors;  // defaults: 2 % slip, 1 % wheel radii, yaw bias
  errors.seed = 3;
  const auto [truth, odo] = drive_square(errors);
  // Odometry still believes it closed the square, within its own wheel-radius errors ...
  EXPECT_LT(std::hypot(odo.x_m, odo.y_m), 0.12);
  // ... while the base really ended elsewhere: the drift a localiser must remove.
  EXPECT_GT(distance_m(truth, odo), 0.02);
  EXPECT_GT(heading_error_rad(truth, odo), deg(0.5));
}

TEST(BaseController, ReachesAGoalWithinLimitsAndTolerance) {
  ControllerConfig cfg;
  SimulatedBase base({0, 0, 0}, projbot::config::OdometryDrift::none());
  BaseController ctl(cfg);
  const Pose2D goal{2.0, -1.0, deg(120)};
  const double dt = 0.02;
  BaseTwist last;
  double peak_speed = 0, peak_accel = 0;
  int steps = 0;
  for (; steps < 5000; ++steps) {
    const BaseTwist cmd = ctl.update(base.true_pose(), goal, dt);
    if (ctl.arrived()) break;
    peak_speed = std::max(peak_speed, std::hypot(cmd.vx_m_s, cmd.vy_m_s));
    peak_accel = std::max(peak_accel, std::hypot(cmd.vx_m_s - last.vx_m_s, cmd.vy_m_s - last.vy_m_s) / dt);
    last = cmd;
    base.set_wheel_speeds(wheel_speeds_from_twist(cmd));
    base.advance(dt);
  }
  ASSERT_TRUE(ctl.arrived()) << "not arrived after " << steps * dt << " s";
  EXPECT_LT(distance_m(base.true_pose(), goal), cfg.position_tolerance_m);
  EXPECT_LT(heading_error_rad(base.true_pose(), goal), cfg.heading_tolerance_rad);
  EXPECT_LE(peak_speed, cfg.max_speed_m_s + 1e-9);
  EXPECT_LE(peak_accel, cfg.max_accel_m_s2 * std::sqrt(2.0) + 1e-6);  // per axis limit
  EXPECT_LT(steps * dt, 15.0);                                        // 2.2 m at 0.4 m/s with ramps: about 7 s
}

// drive_loop's steps on a simulated base that believes the truth, counting what the loop asked of them.
class CountingSteps final : public DriveSteps {
 public:
  explicit CountingSteps(double dt) : base_({0, 0, 0}, projbot::config::OdometryDrift::none()), dt_(dt) {}
  void sense(long step) override { sensed.push_back(step); }
  Pose2D believed_pose() const override { return base_.true_pose(); }
  double step_s() override { return dt_; }
  double elapsed_s() const override { return t_; }
  void command(const BaseTwist& twist) override {
    ASSERT_EQ(halts, 0) << "commanded after the halt";
    base_.set_wheel_speeds(wheel_speeds_from_twist(twist));
    base_.advance(dt_);
    t_ += dt_;
    ++commands;
  }
  void halt() override {
    base_.set_wheel_speeds({});
    ++halts;
  }
  void settle() override {
    EXPECT_EQ(halts, 1) << "settled before the halt";
    ++settles;
  }
  const SimulatedBase& base() const { return base_; }
  std::vector<long> sensed;
  int commands = 0, halts = 0, settles = 0;

 private:
  SimulatedBase base_;
  double dt_, t_ = 0.0;
};

TEST(DriveLoop, SensesEachStepStopsOnArrivalThenHaltsAndSettlesOnce) {
  BaseController ctl;
  CountingSteps steps(0.025);
  const Pose2D goal{1.0, 0.5, deg(45)};
  ASSERT_TRUE(drive_loop(ctl, steps, goal, 60.0));
  EXPECT_LT(distance_m(steps.base().true_pose(), goal), ControllerConfig{}.position_tolerance_m);
  EXPECT_EQ(steps.halts, 1);
  EXPECT_EQ(steps.settles, 1);
  // One sense per step, numbered from 0; every step but the arriving one commanded.
  ASSERT_FALSE(steps.sensed.empty());
  for (std::size_t i = 0; i < steps.sensed.size(); ++i) ASSERT_EQ(steps.sensed[i], static_cast<long>(i));
  EXPECT_EQ(steps.commands + 1, static_cast<int>(steps.sensed.size()));
  EXPECT_TRUE(steps.base().commanded() == WheelSpeeds{}) << "the base was left moving";
}

TEST(DriveLoop, GivesUpAtTheTimeoutNotArrivedAndStillHalts) {
  BaseController ctl;
  CountingSteps steps(0.025);
  EXPECT_FALSE(drive_loop(ctl, steps, {5.0, 0.0, 0.0}, 1.0));  // 5 m cannot be driven in 1 s
  EXPECT_NEAR(steps.commands * 0.025, 1.0, 0.03);
  EXPECT_EQ(steps.halts, 1);
  EXPECT_EQ(steps.settles, 1);
  EXPECT_TRUE(steps.base().commanded() == WheelSpeeds{});
}

projbot::config::PanTiltConfig bare_rig() {
  projbot::config::PanTiltConfig rig = projbot::config::default_pan_tilt();
  rig.T_base_mount = Eigen::Matrix4d::Identity();
  rig.tilt_axis_offset_m.setZero();
  rig.T_head_camera.block<3, 1>(0, 3).setZero();
  rig.T_projector_camera = Eigen::Matrix4d::Identity();
  return rig;
}

TEST(PanTiltAiming, HandComputedWithoutOffsets) {
  const auto rig = bare_rig();
  auto a = aim_at({0, 0, 0}, {2, 2, 0}, rig);
  EXPECT_TRUE(a.within_limits);
  EXPECT_NEAR(a.angles.pan_rad, deg(45), 1e-9);
  EXPECT_NEAR(a.angles.tilt_rad, 0.0, 1e-9);
  a = aim_at({0, 0, 0}, {1, 0, 0.5}, rig);
  EXPECT_NEAR(a.angles.pan_rad, 0.0, 1e-9);
  EXPECT_NEAR(a.angles.tilt_rad, std::atan(0.5), 1e-9);
  // The base's heading counts: facing +y, a target on +y needs no pan; one at -x needs +90.
  a = aim_at({0, 0, deg(90)}, {0, 3, 0}, rig);
  EXPECT_NEAR(a.angles.pan_rad, 0.0, 1e-9);
  a = aim_at({1, 1, deg(90)}, {-2, 1, -3}, rig);
  EXPECT_NEAR(a.angles.pan_rad, deg(90), 1e-9);
  EXPECT_NEAR(a.angles.tilt_rad, deg(-45), 1e-9);
  EXPECT_LT(a.miss_rad, 1e-9);
}

TEST(PanTiltAiming, CameraOffsetFromTheAxes) {
  // Camera 0.1 m to the left of the pan axis: to see a point 2 m ahead on its optical axis the
  // head turns right by asin(0.1 / 2).
  auto rig = bare_rig();
  rig.T_head_camera.block<3, 1>(0, 3) = Eigen::Vector3d(0.0, 0.1, 0.0);
  const auto a = aim_at({0, 0, 0}, {2, 0, 0}, rig);
  EXPECT_NEAR(a.angles.pan_rad, -std::asin(0.1 / 2.0), 1e-9);
  EXPECT_NEAR(a.angles.tilt_rad, 0.0, 1e-9);
  EXPECT_LT(a.miss_rad, 1e-9);
  // The default rig (mount, tilt axis and camera offsets) still lands the point on the axis.
  const auto full = projbot::config::default_pan_tilt();
  const Pose2D base{3.0, -1.0, deg(30)};
  const Eigen::Vector3d target(4.2, 0.5, 0.4);
  const auto b = aim_at(base, target, full);
  ASSERT_TRUE(b.within_limits);
  const Eigen::Vector3d p = head_poses(base, b.angles, full).T_world_camera.inverse() * target;
  EXPECT_NEAR(p.x(), 0.0, 1e-9);
  EXPECT_NEAR(p.y(), 0.0, 1e-9);
  EXPECT_GT(p.z(), 0.0);
}

TEST(PanTiltAiming, LimitsAreReported) {
  const auto rig = bare_rig();
  // Straight behind: pan 180 degrees, beyond the PTU-D46's +-159.
  auto a = aim_at({0, 0, 0}, {-2, 0.01, 0}, rig);
  EXPECT_FALSE(a.within_limits);
  EXPECT_NEAR(a.angles.pan_rad, rig.pan_max_rad, 1e-12);
  EXPECT_GT(a.miss_rad, deg(20));
  // Steeply down: tilt -80 degrees, below the -46.6 limit.
  a = aim_at({0, 0, 0}, {0.2, 0, -1.2}, rig);
  EXPECT_FALSE(a.within_limits);
  EXPECT_NEAR(a.angles.tilt_rad, rig.tilt_min_rad, 1e-12);
}

TEST(PanTiltKinematics, ForwardChainOnTheDefaultRig) {
  const auto rig = projbot::config::default_pan_tilt();
  const HeadPoses h = head_poses({1.0, 2.0, deg(90)}, {0.0, 0.0}, rig);
  // Mount 0.15 m ahead and 0.55 m up, tilt axis 0.06 m higher, camera 0.04 m ahead of it.
  EXPECT_NEAR((h.T_world_camera.translation() - Eigen::Vector3d(1.0, 2.19, 0.61)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((h.T_world_camera.linear().col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-12);   // looks along +y
  EXPECT_NEAR((h.T_world_camera.linear().col(1) - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);  // image y down
  // The projector sits 8 cm above the camera.
  EXPECT_NEAR((h.T_world_projector.translation() - Eigen::Vector3d(1.0, 2.19, 0.69)).norm(), 0.0, 1e-12);
  // Tilting up by 30 degrees raises the optical axis.
  const HeadPoses up = head_poses({0, 0, 0}, {0.0, deg(30)}, rig);
  EXPECT_NEAR(up.T_world_camera.linear().col(2).z(), std::sin(deg(30)), 1e-12);
}

TEST(SimulatedPanTilt, StepsBacklashAndLimits) {
  const auto rig = projbot::config::default_pan_tilt();
  SimulatedPanTilt ptu(rig, deg(0.1));
  ASSERT_TRUE(ptu.move_to({deg(20), deg(-10)}).ok);
  PanTiltAngles reported;
  ASSERT_TRUE(ptu.position(reported).ok);
  EXPECT_NEAR(std::remainder(reported.pan_rad, rig.step_rad), 0.0, 1e-12);  // whole steps
  EXPECT_NEAR(reported.pan_rad, deg(20), rig.step_rad / 2);
  // Approached from below, the output lags by half the dead band.
  EXPECT_NEAR(ptu.true_angles().pan_rad, reported.pan_rad - deg(0.05), 1e-12);
  // Reversing: the first 0.1 degree of drive motion is taken up by the dead band.
  ASSERT_TRUE(ptu.move_to({deg(19.95), deg(-10)}).ok);
  EXPECT_NEAR(ptu.true_angles().pan_rad, reported.pan_rad - deg(0.05), 1e-12);
  ASSERT_TRUE(ptu.move_to({deg(10), deg(-10)}).ok);
  ptu.position(reported);
  EXPECT_NEAR(ptu.true_angles().pan_rad, reported.pan_rad + deg(0.05), 1e-12);
  // Out of range and NaN are refused, and the unit stays where it was.
  const auto refused = ptu.move_to({deg(170), 0.0});
  EXPECT_FALSE(refused.ok);
  EXPECT_NE(refused.error.find("pan"), std::string::npos);
  EXPECT_FALSE(ptu.move_to({0.0, std::nan("")}).ok);
  PanTiltAngles after;
  ptu.position(after);
  EXPECT_EQ(after.pan_rad, reported.pan_rad);
}

}  // namespace
