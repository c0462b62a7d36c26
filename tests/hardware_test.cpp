// Opening the devices a site file names (projbot::hardware), at the library: each device read once, an
// absent one named with what failed. (devices_cli_test goes through the executable.)

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "projbot/hardware/devices.hpp"

using projbot::hardware::DeviceCheck;
using projbot::hardware::DeviceError;
using projbot::hardware::open_devices;

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
