#pragma once
// The real devices a scene's `devices:` section names (issue 12): opened at start, each checked by
// reading from it once, so a configured device that is absent fails before any work with a message that
// names it.

#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/alignment/openni2_source.hpp"
#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/config/devices.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/robot/mrpt_laser.hpp"
#include "projbot/robot/ptu_d46.hpp"
#include "projbot/robot/ros2_base.hpp"

namespace projbot::live {

/// A configured device that could not be opened or read: "devices.camera (freenect #0): not found ...".
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The opened devices; each null where the config names none (the twin serves it).
struct Devices {
  std::unique_ptr<alignment::RgbdCamera> camera;
  std::unique_ptr<robot::PtuD46> pan_tilt;
  std::unique_ptr<robot::MrptLaser> laser;
  std::unique_ptr<robot::Ros2Base> base;
};

/// What checking one configured device found.
struct DeviceCheck {
  std::string role;    ///< "camera", "pan_tilt", ...
  std::string config;  ///< the config's line for it (DevicesConfig::describe)
  bool ok = false;
  std::string detail;  ///< what it read, or why it failed
};

/// Opens and reads each configured device in turn (camera: one depth frame; pan-tilt: its position;
/// laser: one scan; base: one odometry message; projector: its monitor is connected). `stop_at_first` throws DeviceError at the
/// first failure; otherwise every device is tried and `checks` says how each went.
Devices open_devices(const config::DevicesConfig& config, std::vector<DeviceCheck>& checks, bool stop_at_first);

/// Whether the config's devices make up the whole robot: a base, a pan-tilt and a camera, configured
/// together (the session then drives them, and no twin). False when none of the base and pan-tilt is
/// configured (the twin serves the robot). Throws DeviceError naming what is missing for part of a robot
/// (the twin's camera cannot see where a real base went).
bool configured_robot(const config::DevicesConfig& devices);

/// The config's devices for a session, each opened and read once (the first that fails a DeviceError
/// naming it), then checked to make a whole robot or a camera alone (configured_robot): `robot` says which.
/// None configured: no device, `robot` false. A laser needs a base, and a map unless `laser_needs_map` is
/// false (record's mapping run).
Devices open_session_devices(const config::DevicesConfig& wanted, std::vector<DeviceCheck>& checks, bool& robot,
                             bool laser_needs_map = true);

/// Serial devices a PTU-D46 or a Hokuyo / SICK laser appears as (ttyUSB*, ttyACM*), each with its
/// stable /dev/serial/by-id name beside it where there is one.
std::vector<std::string> serial_ports();

/// What this machine offers, one line per kind (`projbot devices`): the RGB-D cameras OpenNI2 and
/// libfreenect see, the serial ports, the monitors, and the DDS participants heard on `dds_domain` in 1 s.
/// A kind that cannot be looked at says why on its line.
void list_found(std::ostream& out, int dds_domain);

/// `run`'s devices: the scene's (less the projector with `headless`: drawn offscreen), opened as
/// open_session_devices opens them, with what each read and who serves the robot said on `log`. None
/// configured: no device, and `log` says the twin runs.
Devices open_run_devices(const config::Scene& scene, bool headless, std::ostream& log);

}  // namespace projbot::live
