// Opening the devices a site file names (live/devices.hpp), at the library: each device read once, an
// absent one named with what failed. (devices_cli_test goes through the executable.)

#include "projbot/live/devices.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using projbot::live::DeviceCheck;
using projbot::live::DeviceError;
using projbot::live::open_devices;

namespace {

projbot::config::DevicesConfig dummy_camera_and_absent_pan_tilt() {
  projbot::config::DevicesConfig c;
  projbot::config::CameraDevice camera;
  camera.driver = "openni2";
  camera.uri = "Dummy";  // OpenNI2's packaged test device: a 320x240 pattern
  c.camera = camera;
  projbot::config::PanTiltDevice pan_tilt;
  pan_tilt.port = "/dev/ttyUSB97";
  c.pan_tilt = pan_tilt;
  return c;
}

}  // namespace

// Every configured device is tried: the camera that is there opened and read, the pan-tilt that is not
// named with the port that failed, and left null.
TEST(Hardware, TriesEachDeviceAndSaysHowEachWent) {
  std::vector<DeviceCheck> checks;
  const auto devices = open_devices(dummy_camera_and_absent_pan_tilt(), checks, false);
  ASSERT_EQ(checks.size(), 2U);
  EXPECT_EQ(checks[0].role, "camera");
  EXPECT_TRUE(checks[0].ok) << checks[0].detail;
  EXPECT_NE(checks[0].detail.find("320x240 depth"), std::string::npos) << checks[0].detail;
  EXPECT_NE(devices.camera, nullptr);
  EXPECT_EQ(checks[1].role, "pan_tilt");
  EXPECT_FALSE(checks[1].ok);
  EXPECT_NE(checks[1].config.find("ptu-d46 on /dev/ttyUSB97 at 9600 baud"), std::string::npos) << checks[1].config;
  EXPECT_NE(checks[1].detail.find("PTU-D46 on /dev/ttyUSB97: cannot open"), std::string::npos) << checks[1].detail;
  EXPECT_EQ(devices.pan_tilt, nullptr);
  EXPECT_EQ(devices.laser, nullptr);
  EXPECT_EQ(devices.base, nullptr);
}

// Stopping at the first failure (run, record, calibrate): one error naming the device and its config.
TEST(Hardware, StopsAtTheFirstAbsentDeviceNamingIt) {
  std::vector<DeviceCheck> checks;
  try {
    open_devices(dummy_camera_and_absent_pan_tilt(), checks, true);
    FAIL() << "an absent pan-tilt was opened";
  } catch (const DeviceError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("devices.pan_tilt (ptu-d46 on /dev/ttyUSB97 at 9600 baud): PTU-D46 on /dev/ttyUSB97"), std::string::npos)
        << what;
  }
}

// Nothing configured: nothing opened, nothing checked.
TEST(Hardware, NothingConfiguredOpensNothing) {
  std::vector<DeviceCheck> checks;
  const auto devices = open_devices({}, checks, true);
  EXPECT_TRUE(checks.empty());
  EXPECT_EQ(devices.camera, nullptr);
  EXPECT_EQ(devices.pan_tilt, nullptr);
}

// A session's devices (run, record): part of a robot is refused naming what is missing, and a laser
// without the base it localises or without a map is refused before any device is opened (the absent
// base of the last case would otherwise be named first).
TEST(Hardware, ASessionNeedsAWholeRobotAndALaserItsBaseAndMap) {
  using projbot::live::configured_robot;
  using projbot::live::open_session_devices;
  projbot::config::DevicesConfig d;
  EXPECT_FALSE(configured_robot(d));  // nothing configured: the twin serves the robot
  d.camera = projbot::config::CameraDevice{};
  EXPECT_FALSE(configured_robot(d));  // a camera alone: the twin's robot, this camera
  d.base = projbot::config::BaseDevice{};
  const auto refusal = [](const auto& call) {
    try {
      call();
    } catch (const DeviceError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(refusal([&] { configured_robot(d); }).find("and devices.pan_tilt is not"), std::string::npos);
  d.pan_tilt = projbot::config::PanTiltDevice{};
  EXPECT_TRUE(configured_robot(d));
  d.camera.reset();
  EXPECT_NE(refusal([&] { configured_robot(d); }).find("and devices.camera is not"), std::string::npos);

  projbot::config::DevicesConfig laser_only;
  laser_only.laser = projbot::config::LaserDevice{};
  std::vector<DeviceCheck> checks;
  bool robot = true;
  EXPECT_NE(refusal([&] { open_session_devices(laser_only, checks, robot); }).find("devices.base is not configured"),
            std::string::npos);
  projbot::config::DevicesConfig no_map = laser_only;
  no_map.base = projbot::config::BaseDevice{};
  EXPECT_NE(refusal([&] { open_session_devices(no_map, checks, robot); }).find("devices.laser.map names none"),
            std::string::npos);
  EXPECT_TRUE(checks.empty());  // refused before anything was opened
  const auto none = open_session_devices({}, checks, robot);
  EXPECT_FALSE(robot);
  EXPECT_EQ(none.camera, nullptr);
}
