#include "projbot/live/devices.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>

#include "projbot/config/angles.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::live {
namespace {

// "640x480 depth, 87% valid, 0.62-3.90 m": what a first frame says about a camera that works.
std::string describe_depth(const alignment::DepthImage& d) {
  std::size_t valid = 0;
  float lo = 1e9F, hi = 0.0F;
  for (const float z : d.depth_m)
    if (alignment::has_depth(z)) {
      ++valid;
      lo = std::min(lo, z);
      hi = std::max(hi, z);
    }
  // Whole percents rounded down, as before; below 1 % one decimal rounded up, never "0%" for a frame with
  // valid pixels (the Dummy device's test pattern: 0.5 %).
  const double percent = d.depth_m.empty() ? 0.0 : 100.0 * static_cast<double>(valid) / static_cast<double>(d.depth_m.size());
  const bool below_one = valid > 0 && percent < 1.0;
  char share[32];
  std::snprintf(share, sizeof share, "%.*f", below_one ? 1 : 0,
                below_one ? std::ceil(10.0 * percent) / 10.0 : std::floor(percent));
  std::ostringstream out;
  out.precision(3);
  out << d.width << "x" << d.height << " depth, " << share << "% valid";
  if (valid > 0) out << ", " << lo << "-" << hi << " m";
  return out.str();
}

// An OpenNI2 device or recording as the session's camera: depth, and colour where it is registered to it,
// stamped on the host's clock.
class OpenNi2Camera final : public alignment::RgbdCamera {
 public:
  explicit OpenNi2Camera(const alignment::OpenNi2Options& o) : source_(o) {}
  alignment::RgbdFrame next() override { return source_.next_frame(); }
  alignment::ExposureHold hold_colour_exposure() override { return source_.hold_colour_exposure(); }

 private:
  alignment::OpenNi2Source source_;
};

std::string open_camera(const config::CameraDevice& c, Devices& out) {
  if (c.driver == "freenect") {
    alignment::FreenectOptions o;
    o.index = c.index;
    o.registered = c.registered;
    out.camera = std::make_unique<alignment::FreenectSource>(o);
  } else {
    alignment::OpenNi2Options o;
    o.uri = c.uri;
    o.colour_registered = c.colour_registered;
    out.camera = std::make_unique<OpenNi2Camera>(o);
  }
  const alignment::RgbdFrame f = out.camera->next();
  return describe_depth(f.depth) +
         (f.colour.rgba.empty() ? std::string(", no colour")
                                : " + " + std::to_string(f.colour.width) + "x" + std::to_string(f.colour.height) + " colour");
}

std::string open_pan_tilt(const config::PanTiltDevice& p, Devices& out) {
  out.pan_tilt = std::make_unique<robot::PtuD46>(p.port);
  robot::PanTiltAngles at;
  if (const auto status = out.pan_tilt->position(at); !status.ok) throw robot::RobotError(status.error);
  std::ostringstream s;
  s.precision(3);
  s << "at pan " << config::degrees(at.pan_rad) << " deg, tilt " << config::degrees(at.tilt_rad) << " deg";
  return s.str();
}

std::string open_laser(const config::LaserDevice& l, Devices& out) {
  out.laser = std::make_unique<robot::MrptLaser>(l.class_name, l.params);
  const robot::LaserScan scan = out.laser->next();
  return std::to_string(scan.ranges_m.size()) + " rays over " + std::to_string(std::lround(config::degrees(scan.aperture_rad))) +
         " deg";
}

std::string open_base(const config::BaseDevice& b, Devices& out) {
  out.base = std::make_unique<robot::Ros2Base>(b);
  const robot::Odometry2D odo = out.base->odometry(2.0);
  std::ostringstream s;
  s.precision(3);
  s << "odometry at x " << odo.pose.x_m << " m, y " << odo.pose.y_m << " m, heading " << config::degrees(odo.pose.theta_rad)
    << " deg";
  return s.str();
}

std::string check_monitor(const config::ProjectorDevice& p) {
  const auto monitors = engine::connected_monitors();
  if (p.monitor >= static_cast<int>(monitors.size()))
    throw DeviceError("monitor " + std::to_string(p.monitor) + " is not connected (" + std::to_string(monitors.size()) +
                      " connected: projbot devices lists them)");
  const auto& m = monitors[static_cast<std::size_t>(p.monitor)];
  return m.name + ", " + std::to_string(m.width_px) + "x" + std::to_string(m.height_px) +
         (m.refresh_hz > 0 ? " at " + std::to_string(m.refresh_hz) + " Hz" : std::string(", refresh unknown"));
}

}  // namespace

Devices open_devices(const config::DevicesConfig& config, std::vector<DeviceCheck>& checks, bool stop_at_first) {
  Devices out;
  const auto lines = config.describe();
  std::size_t line = 0;
  const auto attempt = [&](const char* role, auto&& open) {
    DeviceCheck check{role, lines[line++], false, ""};
    try {
      check.detail = open();
      check.ok = true;
    } catch (const std::exception& e) {  // AlignmentError, RobotError, EngineError, DeviceError
      check.detail = e.what();
    }
    checks.push_back(check);
    if (!check.ok && stop_at_first)
      throw DeviceError("devices." + check.role + " (" + check.config.substr(check.config.find(": ") + 2) + "): " + check.detail);
  };
  if (config.camera) attempt("camera", [&] { return open_camera(*config.camera, out); });
  if (config.pan_tilt) attempt("pan_tilt", [&] { return open_pan_tilt(*config.pan_tilt, out); });
  if (config.laser) attempt("laser", [&] { return open_laser(*config.laser, out); });
  if (config.base) attempt("base", [&] { return open_base(*config.base, out); });
  if (config.projector) attempt("projector", [&] { return check_monitor(*config.projector); });
  return out;
}

namespace {

// A laser localises a configured base against a map (a mapping run records it without one): without
// either, the config is incomplete (said before any device is opened).
void check_laser(const config::DevicesConfig& d, bool laser_needs_map) {
  if (d.laser && !d.base)
    throw DeviceError(
        "devices.laser localises the configured base, and devices.base is not configured (the twin's robot "
        "localises on the twin's laser): configure the base, or leave the laser out");
  if (laser_needs_map && d.laser && d.laser->map.empty())
    throw DeviceError(
        "devices.laser localises the base against a map, and devices.laser.map names none: map the site "
        "(projbot slam --out-map DIR) and name DIR there");
}

}  // namespace

bool configured_robot(const config::DevicesConfig& d) {
  if (!d.base && !d.pan_tilt) return false;
  std::string missing;
  for (const auto& [name, there] : {std::pair<const char*, bool>{"base", d.base.has_value()},
                                    {"pan_tilt", d.pan_tilt.has_value()},
                                    {"camera", d.camera.has_value()}})
    if (!there) missing += std::string(missing.empty() ? "" : " and ") + "devices." + name;
  if (!missing.empty())
    throw DeviceError("a real robot needs its base, pan_tilt and camera configured together, and " + missing +
                      (missing.find(" and ") != std::string::npos ? " are" : " is") +
                      " not (the twin cannot stand in for part of a real robot); configure it, or run the twin with --sim");
  return true;
}

Devices open_session_devices(const config::DevicesConfig& wanted, std::vector<DeviceCheck>& checks, bool& robot,
                             bool laser_needs_map) {
  robot = false;
  if (!wanted.any()) return {};
  check_laser(wanted, laser_needs_map);
  Devices devices = open_devices(wanted, checks, true);
  robot = configured_robot(wanted);  // after opening: an absent device is named before a missing one
  return devices;
}

Devices open_run_devices(const config::Scene& scene, bool headless, std::ostream& log) {
  config::DevicesConfig wanted = scene.devices;
  if (headless && wanted.projector) {  // drawn offscreen: no monitor to check
    log << "devices.projector is not used with --headless" << std::endl;
    wanted.projector.reset();
  }
  if (!wanted.any()) {
    if (!scene.devices.any())
      log << "no devices configured in " << scene.source.filename().string()
          << " (a `devices:` section; projbot devices lists what this machine has): running against the digital twin (--sim)"
          << std::endl;
    return {};
  }
  std::vector<DeviceCheck> checks;
  bool robot = false;
  Devices devices = open_session_devices(wanted, checks, robot);  // an absent device, part of a robot or a laser: refused
  for (const auto& c : checks) log << "opened " << c.config << ": " << c.detail << '\n';
  if (robot)
    log << "the configured base, pan-tilt and camera serve the session"
        << (wanted.laser ? ", the base localised on the laser against " + wanted.laser->map.string() : std::string())
        << ": no twin (nothing is measured against a truth)" << std::endl;
  else
    log << "the twin serves the robot" << (scene.devices.camera ? "" : " and the camera") << std::endl;
  return devices;
}

std::vector<std::string> serial_ports() {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/dev", ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("ttyUSB", 0) == 0 || name.rfind("ttyACM", 0) == 0) out.push_back(entry.path().string());
  }
  std::sort(out.begin(), out.end());
  for (const auto& entry : std::filesystem::directory_iterator("/dev/serial/by-id", ec)) {
    const auto target = std::filesystem::canonical(entry.path(), ec);
    for (auto& port : out)
      if (!ec && target.string() == port) port += " (" + entry.path().string() + ")";
  }
  return out;
}

void list_found(std::ostream& out, int dds_domain) {
  out << "RGB-D cameras (OpenNI2: PrimeSense, Xtion): ";
  try {
    const auto found = alignment::openni2_devices();
    if (found.empty()) out << "none found";
    for (std::size_t i = 0; i < found.size(); ++i)
      out << (i ? "; " : "") << found[i].vendor << " " << found[i].name << " (uri: " << found[i].uri << ")";
  } catch (const std::exception& e) {
    out << "cannot look: " << e.what();
  }
  out << "\nKinect v1 (libfreenect): ";
  try {
    const int n = alignment::FreenectSource::count_devices();
    out << (n == 0 ? std::string("none found") : std::to_string(n) + " found (index 0.." + std::to_string(n - 1) + ")");
  } catch (const std::exception& e) {
    out << "cannot look: " << e.what();
  }
  const auto ports = serial_ports();
  out << "\nserial ports (pan-tilt unit, laser): " << (ports.empty() ? "none found" : "");
  for (std::size_t i = 0; i < ports.size(); ++i) out << (i ? ", " : "") << ports[i];
  out << "\nmonitors (the projector is one): ";
  try {
    const auto monitors = engine::connected_monitors();
    if (monitors.empty()) out << "none connected";
    for (std::size_t i = 0; i < monitors.size(); ++i)
      out << (i ? "; " : "") << i << ": " << monitors[i].name << " " << monitors[i].width_px << "x" << monitors[i].height_px
          << (monitors[i].refresh_hz > 0 ? " at " + std::to_string(monitors[i].refresh_hz) + " Hz"
                                         : std::string(", refresh unknown"));
  } catch (const std::exception& e) {
    out << e.what();
  }
  out << "\nROS 2 / DDS on domain " << dds_domain << ": ";
  try {
    const auto seen = robot::survey_dds(dds_domain, 1.0);
    out << seen.participants << " other participant" << (seen.participants == 1 ? "" : "s") << " heard in 1 s";
    const auto list = [&](const char* what, const auto& topics) {
      if (topics.empty()) return;
      out << "; " << what << ": ";
      for (std::size_t i = 0; i < topics.size(); ++i)
        out << (i ? ", " : "") << topics[i].first << " (" << topics[i].second << ")";
    };
    list("published", seen.published);
    list("subscribed", seen.subscribed);
  } catch (const std::exception& e) {
    out << "cannot look: " << e.what();
  }
  out << "\n";
}

}  // namespace projbot::live
