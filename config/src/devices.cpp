// The scene's `devices:` section (the real devices a site runs on), read and checked once, and its
// one-line description per device.

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <string>
#include <vector>

#include "devices_reader.hpp"
#include "map_reader.hpp"

namespace projbot::config {
namespace {

// A ROS 2 topic name as the base driver's topics use: letters, digits, '_' and '/' separators.
bool ros_topic_name(const std::string& name) {
  if (name.empty() || name.back() == '/' || std::isdigit(static_cast<unsigned char>(name.front()))) return false;
  for (std::size_t i = 0; i < name.size(); ++i) {
    const char c = name[i];
    if (c == '/' && i > 0 && name[i - 1] == '/') return false;
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/')) return false;
  }
  return true;
}

CameraDevice read_camera_device(const YAML::Node& node, const std::string& file) {
  MapReader m(node, "devices.camera", file);
  CameraDevice c;
  c.driver = m.get<std::string>("driver", "", true);
  if (c.driver == "openni2") {
    c.uri = m.get<std::string>("uri", "");
    c.colour_registered = m.get<bool>("colour_registered", c.colour_registered);
  } else if (c.driver == "freenect") {
    c.index = m.get<int>("index", 0);
    if (c.index < 0 || c.index > 15) m.fail(node["index"], "devices.camera.index", "must be 0..15 (which Kinect)");
    c.registered = m.get<bool>("registered", c.registered);
  } else {
    m.fail(node["driver"], "devices.camera.driver",
           "must be openni2 (PrimeSense, Xtion, .oni files) or freenect (Kinect v1), not '" + c.driver + "'");
  }
  m.reject_unknown();
  return c;
}

PanTiltDevice read_pan_tilt_device(const YAML::Node& node, const std::string& file) {
  MapReader m(node, "devices.pan_tilt", file);
  PanTiltDevice p;
  p.driver = m.get<std::string>("driver", p.driver);
  if (p.driver != "ptu-d46") m.fail(node["driver"], "devices.pan_tilt.driver", "must be ptu-d46, not '" + p.driver + "'");
  p.port = m.get<std::string>("port", "", true);
  if (p.port.empty()) m.fail(node["port"], "devices.pan_tilt.port", "must name a serial port (/dev/ttyUSB0)");
  p.baud = m.get<int>("baud", p.baud);
  if (p.baud != 9600)
    m.fail(node["baud"], "devices.pan_tilt.baud", "must be 9600: MRPT's CPtuDPerception talks to the PTU-D46 at 9600 baud only");
  m.reject_unknown();
  return p;
}

LaserDevice read_laser_device(const YAML::Node& node, const std::string& file) {
  MapReader m(node, "devices.laser", file);
  LaserDevice l;
  l.driver = m.get<std::string>("driver", l.driver);
  if (l.driver != "mrpt")
    m.fail(node["driver"], "devices.laser.driver", "must be mrpt (any MRPT 2-D laser class), not '" + l.driver + "'");
  l.class_name = m.get<std::string>("class", "", true);
  if (l.class_name.empty()) m.fail(node["class"], "devices.laser.class", "must name an MRPT sensor class (CHokuyoURG)");
  if (YAML::Node params = m.child("params", false)) {
    if (!params.IsMap()) m.fail(params, "devices.laser.params", "expected a mapping of the driver's own keys");
    for (const auto& kv : params) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
      if (key.empty() || !kv.second.IsScalar()) m.fail(kv.first, "devices.laser.params", "each entry must be key: value");
      l.params[key] = kv.second.Scalar();
    }
  }
  // Optional here: `projbot devices` checks a laser before there is a map; a session that drives needs it.
  if (const std::string map = m.get<std::string>("map", ""); !map.empty()) {
    l.map = beside_scene(map, std::filesystem::path(file).parent_path());
    std::error_code ec;
    if (!std::filesystem::is_regular_file(l.map / "map.simplemap.gz", ec))
      m.fail(node["map"], "devices.laser.map",
             "'" + l.map.string() + "' holds no map.simplemap.gz (the folder `projbot slam --out-map` wrote)");
  }
  m.reject_unknown();
  return l;
}

BaseDevice read_base_device(const YAML::Node& node, const std::string& file) {
  MapReader m(node, "devices.base", file);
  BaseDevice b;
  b.driver = m.get<std::string>("driver", b.driver);
  if (b.driver != "ros2-dds")
    m.fail(node["driver"], "devices.base.driver", "must be ros2-dds (ROS 2 topics over Cyclone DDS), not '" + b.driver + "'");
  b.domain = m.get<int>("domain", b.domain);
  if (b.domain < 0 || b.domain > 232) m.fail(node["domain"], "devices.base.domain", "must be a DDS domain id 0..232");
  for (auto [key, topic] : {std::pair{"cmd_vel", &b.cmd_vel}, std::pair{"odom", &b.odom}}) {
    *topic = m.get<std::string>(key, *topic);
    if (!ros_topic_name(*topic))
      m.fail(node[key], std::string("devices.base.") + key,
             "'" + *topic + "' is not a ROS 2 topic name (letters, digits, _ and /)");
  }
  m.reject_unknown();
  return b;
}

}  // namespace

DevicesConfig read_devices(MapReader& root) {
  DevicesConfig d;
  YAML::Node node = root.child("devices", false);
  if (!node || node.IsNull()) return d;
  MapReader m(node, "devices", root.file());
  if (YAML::Node n = m.child("camera", false)) d.camera = read_camera_device(n, root.file());
  if (YAML::Node n = m.child("pan_tilt", false)) d.pan_tilt = read_pan_tilt_device(n, root.file());
  if (YAML::Node n = m.child("laser", false)) d.laser = read_laser_device(n, root.file());
  if (YAML::Node n = m.child("base", false)) d.base = read_base_device(n, root.file());
  if (YAML::Node n = m.child("projector", false)) {
    MapReader p(n, "devices.projector", root.file());
    ProjectorDevice out;
    out.monitor = p.get<int>("monitor", out.monitor);
    if (out.monitor < 0 || out.monitor > 63) p.fail(n["monitor"], "devices.projector.monitor", "must be 0..63");
    out.fullscreen = p.get<bool>("fullscreen", out.fullscreen);
    p.reject_unknown();
    d.projector = out;
  }
  m.reject_unknown();
  return d;
}

std::vector<std::string> DevicesConfig::describe() const {
  std::vector<std::string> out;
  if (camera)
    out.push_back("camera: " + camera->driver +
                  (camera->driver == "freenect" ? " #" + std::to_string(camera->index)
                                                : (camera->uri.empty() ? std::string(" (first device)") : " " + camera->uri)));
  if (pan_tilt)
    out.push_back("pan_tilt: " + pan_tilt->driver + " on " + pan_tilt->port + " at " + std::to_string(pan_tilt->baud) + " baud");
  if (laser)
    out.push_back("laser: " + laser->driver + " " + laser->class_name +
                  (laser->map.empty() ? std::string() : ", localising against " + laser->map.string()));
  if (base)
    out.push_back("base: " + base->driver + " (domain " + std::to_string(base->domain) + ", rt/" + base->cmd_vel + " out, rt/" +
                  base->odom + " in)");
  if (projector)
    out.push_back("projector: monitor " + std::to_string(projector->monitor) +
                  (projector->fullscreen ? ", fullscreen" : ", windowed"));
  return out;
}

}  // namespace projbot::config
