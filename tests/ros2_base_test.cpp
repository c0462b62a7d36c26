// The base over ROS 2 topics on Cyclone DDS (issue 12): the robot's side commands the twin's youBot
// served on the same topics and reads its odometry.

#include "projbot/robot/ros2_base.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <thread>

#include "dds_loopback.hpp"

namespace {

// A domain of this process's own, so suites running side by side do not hear each other.
projbot::config::BaseDevice base_on_own_domain() {
  use_loopback_dds();
  projbot::config::BaseDevice c;
  c.domain = 150 + static_cast<int>(::getpid() % 50);
  return c;
}

}  // namespace

TEST(Ros2Base, DrivesTheTwinsBaseAndReadsItsOdometry) {
  const auto config = base_on_own_domain();
  projbot::robot::Ros2BaseServer server(config, {1.0, 2.0, 0.5});
  projbot::robot::Ros2Base base(config);
  // 1 s at 0.2 m/s forward, 20 ms steps paced in real time (DDS delivers in the background).
  const double dt = 0.02;
  for (int i = 0; i < 50; ++i) {
    base.send({0.2, 0.0, 0.0});
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    server.step(i * dt, dt);
  }
  EXPECT_GT(server.commands_received(), 25);
  const auto& truth = server.true_pose();
  const double moved = std::hypot(truth.x_m - 1.0, truth.y_m - 2.0);
  EXPECT_GT(moved, 0.15);  // commands arrive within a few steps of being sent
  EXPECT_LT(moved, 0.2 + 1e-6);
  EXPECT_NEAR(std::atan2(truth.y_m - 2.0, truth.x_m - 1.0), 0.5, 1e-3);  // forward is along its heading
  // The odometry read is the last one published (the error-free twin: odometry equals the wheels' motion).
  projbot::robot::Odometry2D odo;
  for (int tries = 0; tries < 100; ++tries) {
    odo = base.odometry(1.0);
    if (std::abs(odo.stamp_s - 49 * dt) < 1e-6) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  EXPECT_NEAR(odo.stamp_s, 49 * dt, 1e-6);
  EXPECT_NEAR(odo.pose.x_m, server.odometry_pose().x_m, 1e-9);
  EXPECT_NEAR(odo.pose.y_m, server.odometry_pose().y_m, 1e-9);
  EXPECT_NEAR(odo.pose.theta_rad, server.odometry_pose().theta_rad, 1e-9);
  EXPECT_NEAR(odo.pose.x_m, truth.x_m, 0.002);
  EXPECT_NEAR(odo.twist.vx_m_s, 0.2, 1e-9);
  // Commands stop: the base stops by itself 0.5 s after the last one.
  for (int i = 50; i < 100; ++i) server.step(i * dt, dt);
  const auto stopped = server.true_pose();
  server.step(100 * dt, dt);
  EXPECT_NEAR(server.true_pose().x_m, stopped.x_m, 1e-12);
}

TEST(Ros2Base, NoBaseDriverIsAnErrorNamingTheTopic) {
  auto config = base_on_own_domain();
  config.odom = "youbot/odom";
  projbot::robot::Ros2Base base(config);
  try {
    base.odometry(0.3);
    FAIL() << "odometry from nobody";
  } catch (const projbot::robot::RobotError& e) {
    EXPECT_NE(std::string(e.what()).find("base (ros2-dds, domain " + std::to_string(config.domain) +
                                         ", rt/youbot/odom): no odometry within 300 ms"),
              std::string::npos)
        << e.what();
  }
}
