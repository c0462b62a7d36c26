#pragma once
// The `devices:` section of a scene file (issue 12): which real device serves each role. Every entry is
// optional; an absent one is simulated by the digital twin.

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace projbot::config {

/// The RGB-D camera (`devices.camera`): `{driver: openni2, uri: ...}` (PrimeSense / Xtion, an .oni
/// recording; "" opens the first device) or `{driver: freenect, index: 0}` (Kinect v1 through libfreenect).
struct CameraDevice {
  std::string driver;  ///< "openni2" or "freenect"
  std::string uri;     ///< openni2 only
  int index = 0;       ///< freenect only: which Kinect, 0-based
  /// freenect only: depth registered to colour in mm (the device's own tables; default), or raw 11-bit
  /// disparity in the depth camera's frame (`registered: false`; what a fakenect dump plays).
  bool registered = true;
  /// openni2 only: its colour is registered to its depth already, though the device offers no registration
  /// to switch on (`colour_registered: true`). A device that offers registration has it switched on;
  /// otherwise, and from an .oni recording, its colour is not read.
  bool colour_registered = false;
};

/// The pan-tilt unit (`devices.pan_tilt`): `{driver: ptu-d46, port: /dev/ttyUSB0, baud: 9600}`.
struct PanTiltDevice {
  std::string driver = "ptu-d46";
  std::string port;
  int baud = 9600;
};

/// A 2-D laser (`devices.laser`): `{driver: mrpt, class: CHokuyoURG, params: {COM_port_LIN: /dev/ttyACM0},
/// map: site-map}`, any MRPT sensor class by name with the keys of its own configuration section, and the
/// map the robot localises on with it (the folder `projbot slam --out-map` wrote, relative to the scene).
struct LaserDevice {
  std::string driver = "mrpt";
  std::string class_name;
  std::map<std::string, std::string> params;
  std::filesystem::path map;  ///< holds map.simplemap.gz (checked when the scene is read); empty: none given
};

/// The mobile base (`devices.base`): `{driver: ros2-dds, domain: 0, cmd_vel: cmd_vel, odom: odom}`,
/// geometry_msgs/Twist out and nav_msgs/Odometry in over Cyclone DDS with ROS 2's names on the wire.
struct BaseDevice {
  std::string driver = "ros2-dds";
  int domain = 0;
  std::string cmd_vel = "cmd_vel";
  std::string odom = "odom";
};

/// The projector's output (`devices.projector`): which monitor, fullscreen or not.
struct ProjectorDevice {
  int monitor = 0;
  bool fullscreen = true;
};

/// Every configured device; none configured means the twin serves all of them.
struct DevicesConfig {
  std::optional<CameraDevice> camera;
  std::optional<PanTiltDevice> pan_tilt;
  std::optional<LaserDevice> laser;
  std::optional<BaseDevice> base;
  std::optional<ProjectorDevice> projector;
  bool any() const { return camera || pan_tilt || laser || base || projector; }
  /// One line per configured device ("camera: freenect #0"), in the order above.
  std::vector<std::string> describe() const;
};

}  // namespace projbot::config
