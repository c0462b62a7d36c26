// The PTU-D46 driver (MRPT's CPtuDPerception) end to end against the protocol emulator on a pty.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "projbot/config/angles.hpp"
#include "projbot/robot/ptu_d46.hpp"

namespace {

using namespace projbot::robot;
constexpr double kStep = projbot::config::radians(185.1428 / 3600.0);  // PTU-D46-17 resolution

TEST(PtuD46, InitialisesAndReadsTheResolution) {
  PtuD46Emulator unit;
  PtuD46 ptu(unit.port());
  EXPECT_NEAR(ptu.pan_step_rad(), kStep, 1e-9);
  EXPECT_NEAR(ptu.tilt_step_rad(), kStep, 1e-9);
  // CPtuDPerception's start-up: verbose replies, resolutions, echo, immediate execution.
  const auto cmds = unit.received();
  ASSERT_GE(cmds.size(), 5u);
  EXPECT_EQ(cmds[0], "FV");
  EXPECT_EQ(cmds[1], "PR");
  EXPECT_EQ(cmds[2], "TR");
  EXPECT_EQ(cmds[3], "EE");
  EXPECT_EQ(cmds[4], "I");
}

TEST(PtuD46, MovesToTheNearestStepAndReportsIt) {
  PtuD46Emulator unit;
  PtuD46 ptu(unit.port());
  const PanTiltAngles want{0.5, -0.3};
  const auto status = ptu.move_to(want);
  ASSERT_TRUE(status.ok) << status.error;
  EXPECT_EQ(unit.pan_steps(), std::lround(0.5 / kStep));
  EXPECT_EQ(unit.tilt_steps(), std::lround(-0.3 / kStep));
  PanTiltAngles got;
  ASSERT_TRUE(ptu.position(got).ok);
  EXPECT_NEAR(got.pan_rad, want.pan_rad, kStep / 2 + 1e-9);
  EXPECT_NEAR(got.tilt_rad, want.tilt_rad, kStep / 2 + 1e-9);
  const auto cmds = unit.received();
  EXPECT_NE(std::find(cmds.begin(), cmds.end(), "PP" + std::to_string(std::lround(0.5 / kStep))), cmds.end());
  EXPECT_NE(std::find(cmds.begin(), cmds.end(), "A"), cmds.end());  // waited for completion
}

TEST(PtuD46, LimitRepliesBecomeErrors) {
  PtuD46Emulator unit;
  PtuD46 ptu(unit.port());
  ASSERT_TRUE(ptu.move_to({0.2, 0.1}).ok);
  auto status = ptu.move_to({3.0, 0.0});  // 3342 positions > 3090
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.error.find("maximum"), std::string::npos) << status.error;
  EXPECT_EQ(unit.pan_steps(), std::lround(0.2 / kStep));  // the unit did not move
  status = ptu.move_to({0.0, -1.0});                      // -1114 positions < -907
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.error.find("minimum"), std::string::npos) << status.error;
  // The driver recovers: the next good command succeeds.
  EXPECT_TRUE(ptu.move_to({0.0, 0.0}).ok);
  EXPECT_EQ(unit.pan_steps(), 0);
  EXPECT_FALSE(ptu.move_to({std::nan(""), 0.0}).ok);
}

TEST(PtuD46, SilentUnitTimesOut) {
  PtuD46Emulator unit;
  PtuD46 ptu(unit.port());
  unit.set_silent(true);
  const auto t0 = std::chrono::steady_clock::now();
  const auto status = ptu.move_to({0.1, 0.1});
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.error.find("no reply"), std::string::npos) << status.error;
  EXPECT_LT(s, 10.0);  // CPtuDPerception's 1 s read timeout, not a hang
}

TEST(PtuD46, BadPortsAreNamed) {
  try {
    PtuD46 ptu("/dev/projbot-no-such-port");
    FAIL() << "opened a missing port";
  } catch (const RobotError& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/projbot-no-such-port"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
  }
  PtuD46Emulator unit;
  unit.set_silent(true);
  EXPECT_THROW(PtuD46 ptu(unit.port()), RobotError);
  // Not a serial port at all: said so, not "the unit did not answer" (issue 47).
  const std::filesystem::path file = std::filesystem::temp_directory_path() / ("projbot_ptu_" + std::to_string(::getpid()));
  std::ofstream(file) << "x";
  const std::vector<std::pair<std::string, std::string>> not_ports{
      {file.string(), "is a regular file, not a serial port"},
      {std::filesystem::temp_directory_path().string(), "is a folder, not a serial port"},
      {"/dev/null", "not a terminal"}};
  for (const auto& [port, message] : not_ports) {
    try {
      PtuD46 ptu(port);
      ADD_FAILURE() << "opened " << port;
    } catch (const RobotError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove(file);
}

}  // namespace
