// The base over ROS 2 topics on Cyclone DDS (issue 12): the robot's side commands the twin's youBot
// served on the same topics and reads its odometry.

#include "projbot/robot/ros2_base.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <random>
#include <thread>

#include "dds_loopback.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/localization.hpp"

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

namespace {

using projbot::robot::Pose2D;

// The twin's laser as a real scanner delivers it: a scan of the room from the base's true pose, at 40 Hz.
class TwinLaser final : public projbot::robot::LaserSource {
 public:
  TwinLaser(const projbot::robot::Ros2BaseServer& base, std::mutex& stepping, const projbot::robot::OccupancyMap& room)
      : base_(base), stepping_(stepping), room_(room) {}
  projbot::robot::LaserScan next(double) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
    Pose2D truth;
    {
      const std::lock_guard lock(stepping_);
      truth = base_.true_pose();
    }
    ++scans;
    return room_.simulate_scan(truth, {}, rng_);
  }
  int scans = 0;

 private:
  const projbot::robot::Ros2BaseServer& base_;
  std::mutex& stepping_;
  const projbot::robot::OccupancyMap& room_;
  std::mt19937_64 rng_{7};
};

// The room's map as a survey makes it: scans at known poses every 0.5 m.
projbot::robot::Localizer surveyed(const projbot::robot::OccupancyMap& room, const projbot::config::Room& c) {
  std::mt19937_64 rng(3);
  std::vector<std::pair<Pose2D, projbot::robot::LaserScan>> keyframes;
  for (double y = 0.5; y < c.depth_m; y += 0.5)
    for (double x = 0.5; x < c.width_m; x += 0.5)
      if (room.is_free(x, y) && room.is_free(x + 0.25, y))
        keyframes.emplace_back(Pose2D{x, y, 0.0}, room.simulate_scan({x, y, 0.0}, {}, rng));
  return projbot::robot::Localizer(keyframes);
}

double distance(const Pose2D& a, const Pose2D& b) { return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m); }

// The twin's youBot served over DDS, stepped in real time (100 Hz) until destroyed.
struct ServedBase {
  ServedBase(const projbot::config::BaseDevice& config, const Pose2D& truly, const projbot::config::OdometryDrift& errors)
      : server(config, truly, errors), simulation([this](const std::stop_token& stop) {
          const double dt = 0.01;
          for (int i = 0; !stop.stop_requested(); ++i) {
            {
              const std::lock_guard lock(stepping);
              server.step(i * dt, dt);
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
          }
        }) {}
  Pose2D truth() {
    const std::lock_guard lock(stepping);
    return server.true_pose();
  }
  projbot::robot::Ros2BaseServer server;
  std::mutex stepping;
  std::jthread simulation;  // last: stopped and joined first
};

}  // namespace

// A real base with a laser (devices.base and devices.laser): set down 6 cm and 2 degrees off its configured
// start, with drifting wheels, the laser's scans against the map find it and keep it found; odometry alone
// carries the start's error to the stop.
TEST(Ros2Navigator, LocalisesOnTheLaserWhereOdometryAloneIsOff) {
  const auto config = base_on_own_domain();
  projbot::config::Room room_config;
  room_config.width_m = 4.0;
  room_config.depth_m = 3.0;
  room_config.obstacles = {{2.6, 2.2, 3.2, 3.0}, {0.0, 2.0, 0.6, 3.0}};
  const auto room = projbot::robot::OccupancyMap::from_room(room_config);
  auto map = surveyed(room, room_config);
  const Pose2D start{1.0, 1.0, 0.0}, truly{1.05, 0.97, -0.035}, goal{2.0, 1.5, 0.5};
  ServedBase served(config, truly, projbot::config::OdometryDrift{});
  projbot::robot::Ros2Base base(config);
  projbot::robot::Ros2Navigator navigator(base, start, {}, 20.0, 30.0);
  TwinLaser laser(served.server, served.stepping, room);
  int heard = 0;  // what record writes to its rawlog: every scan matched
  navigator.on_scan([&](const projbot::robot::LaserScan& scan, const Pose2D&) { heard += scan.ranges_m.empty() ? 0 : 1; });
  navigator.use_laser(laser, &map);
  EXPECT_LT(distance(navigator.believed_pose(), truly), 0.01);  // found at once, from 6 cm off
  const projbot::robot::StopReport r = navigator.drive_to(goal, 0);
  const Pose2D truth = served.truth();
  std::cout << "at the stop: localised " << 1000 * distance(r.estimate, truth) << " mm off, odometry alone "
            << 1000 * distance(r.odometry, truth) << " mm; " << r.corrections << " scans matched (" << r.rejected
            << " rejected), " << r.correct_ms_mean << " ms each; drove " << r.drive_seconds << " s\n";
  EXPECT_TRUE(r.arrived);
  EXPECT_LT(distance(r.estimate, truth), 0.015);
  EXPECT_LT(std::abs(r.estimate.theta_rad - truth.theta_rad), projbot::config::radians(0.5));
  EXPECT_LT(distance(truth, goal), 0.03);
  EXPECT_GT(distance(r.odometry, truth), 0.06);  // the start's 6 cm and 2 degrees, carried along (9 cm)
  EXPECT_GE(r.corrections, 20);
  EXPECT_LE(r.rejected, r.corrections / 10);
  EXPECT_GT(r.correct_ms_mean, 0.0);
  EXPECT_EQ(heard, 3 + r.corrections);  // the start's three, then the drive's and the stop's
}

// A laser without a map (record's mapping run): its scans are handed on with the odometry read beside each,
// and the robot's belief stays odometry's.
TEST(Ros2Navigator, WithoutAMapTheLaserIsOnlyRecorded) {
  const auto config = base_on_own_domain();
  projbot::config::Room room_config;
  room_config.width_m = 4.0;
  room_config.depth_m = 3.0;
  const auto room = projbot::robot::OccupancyMap::from_room(room_config);
  ServedBase served(config, {1.05, 0.97, 0.0}, projbot::config::OdometryDrift::none());
  projbot::robot::Ros2Base base(config);
  projbot::robot::Ros2Navigator navigator(base, {1.0, 1.0, 0.0});
  TwinLaser laser(served.server, served.stepping, room);
  std::vector<Pose2D> odometry;
  navigator.on_scan([&](const projbot::robot::LaserScan& scan, const Pose2D& o) {
    EXPECT_EQ(scan.ranges_m.size(), 1081U);
    odometry.push_back(o);
  });
  navigator.use_laser(laser, nullptr);
  ASSERT_EQ(odometry.size(), 3U);
  EXPECT_NEAR(odometry[0].x_m, 1.05, 1e-9);               // the base's own odometry frame
  EXPECT_NEAR(navigator.believed_pose().x_m, 1.0, 1e-9);  // not moved by the scans: no map to match
  EXPECT_NEAR(navigator.believed_pose().y_m, 1.0, 1e-9);
}
