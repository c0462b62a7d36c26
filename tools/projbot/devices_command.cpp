// projbot devices: what this machine offers Projbot, and whether a scene's configured devices work.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "devices.hpp"
#include "interrupt.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::tools {
namespace {

// Serial devices a PTU-D46 or a Hokuyo / SICK laser appears as, with their stable by-id names.
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

}  // namespace

const Command kDevices{"devices",
                       "list the cameras, serial ports and monitors Projbot can use here; check a scene's configured devices",
                       "projbot devices [--config site.yaml]\n\n"
                       "A first step on a new machine: lists the RGB-D cameras OpenNI2 sees (PrimeSense, Xtion), the\n"
                       "Kinect v1 sensors libfreenect sees, the serial ports a PTU-D46 pan-tilt unit or a laser scanner can\n"
                       "sit on, the monitors (the projector is one; --monitor takes the index shown), and what ROS 2 / DDS\n"
                       "participants publish and subscribe on the base's domain (a base driver publishes rt/odom).\n"
                       "With --config, it then opens each device the scene's `devices:` section names and reads from it once\n"
                       "(a depth frame, the pan-tilt's position, a laser scan, the monitor), and says which work. Exit status\n"
                       "1 when a configured device fails. A `devices:` section, each entry optional (absent: the twin):\n"
                       "  devices:\n"
                       "    camera: {driver: freenect, index: 0}           # or {driver: openni2, uri: \"\"} (an .oni file too)\n"
                       "    pan_tilt: {driver: ptu-d46, port: /dev/ttyUSB0, baud: 9600}\n"
                       "    laser: {driver: mrpt, class: CHokuyoURG, params: {COM_port_LIN: /dev/ttyACM0}, map: site-map}\n"
                       "                                  # map: projbot slam's folder, which run localises against\n"
                       "    base: {driver: ros2-dds, domain: 0, cmd_vel: cmd_vel, odom: odom}\n"
                       "    projector: {monitor: 1, fullscreen: true}\n",
                       {{"config", "FILE", "a scene whose `devices:` section to check"},
                        {"domain", "N", "the DDS domain to listen on (default: devices.base.domain, else 0)"}},
                       [](const cli::Args& args) {
                         std::optional<config::Scene> scene;
                         if (const auto path = args.get("config"))
                           scene = config::load_scene(*path);  // a bad file fails before the listing
                         int domain = scene && scene->devices.base ? scene->devices.base->domain : 0;
                         domain = args.get_int("domain", domain, 0, 232);
                         list_found(std::cout, domain);
                         if (!scene) return 0;
                         std::cout << "\nconfigured in " << scene->source.string() << ":\n";
                         if (!scene->devices.any()) {
                           std::cout << "  no `devices:` section: every device is the digital twin's (projbot run --sim)\n";
                           return 0;
                         }
                         std::vector<DeviceCheck> checks;
                         open_devices(scene->devices, checks, false);
                         bool all_ok = true;
                         for (const auto& c : checks) {
                           std::cout << "  " << c.config << ": " << (c.ok ? "ok, " : "FAILED: ") << c.detail << "\n";
                           all_ok = all_ok && c.ok;
                         }
                         return all_ok ? 0 : 1;
                       }};

const Command kSimBase{"sim-base",
                       "serve the twin's youBot base on ROS 2 DDS topics (cmd_vel in, odom out), for trying a base driver",
                       "projbot sim-base [--config site.yaml] [--domain N] [--seconds S] [--rate HZ]\n\n"
                       "Runs the digital twin's youBot (wheel kinematics, encoders, wheel odometry; no drift) as a ROS 2 base\n"
                       "driver would: it follows the newest geometry_msgs/msg/Twist on rt/cmd_vel (stopping when none came\n"
                       "for 0.5 s) and publishes nav_msgs/msg/Odometry on rt/odom at --rate, over Cyclone DDS with ROS 2's\n"
                       "names on the wire, so `ros2 topic echo /odom` on another machine shows it and `projbot devices` or a\n"
                       "real session can drive it. The domain and topic names come from the config's `devices.base` (default\n"
                       "domain 0, cmd_vel, odom), the start pose from its `robot.start`. Runs until Ctrl-C or --seconds.\n",
                       {{"config", "FILE", "scene whose devices.base and robot.start to use"},
                        {"domain", "N", "DDS domain id 0..232 (overrides devices.base.domain)"},
                        {"seconds", "S", "stop after S seconds (default 0: until Ctrl-C)"},
                        {"rate", "HZ", "odometry messages per second (default 50)"}},
                       [](const cli::Args& args) {
                         catch_interrupts();
                         config::BaseDevice base;
                         robot::Pose2D start{1.0, 1.0, 0.0};
                         if (const auto path = args.get("config")) {
                           const config::Scene scene = config::load_scene(*path);
                           if (scene.devices.base) base = *scene.devices.base;
                           start = {scene.robot_start.x(), scene.robot_start.y(), scene.robot_start.z()};
                         }
                         base.domain = args.get_int("domain", base.domain, 0, 232);
                         const double seconds = args.get_double("seconds", 0.0);
                         if (!(seconds >= 0.0 && seconds <= 1e6))
                           throw cli::UsageError("--seconds must be 0 (until Ctrl-C) to 1e6");
                         const int rate = args.get_int("rate", 50, 1, 1000);
                         robot::Ros2BaseServer server(base, start);
                         std::cout << "serving the twin's youBot on DDS domain " << base.domain << ": rt/" << base.cmd_vel
                                   << " in, rt/" << base.odom << " out at " << rate << " Hz (Ctrl-C stops)" << std::endl;
                         const auto t0 = std::chrono::steady_clock::now();
                         const double dt = 1.0 / rate;
                         int steps = 0;
                         for (; !interrupted(); ++steps) {
                           const double t = steps * dt;
                           if (seconds > 0.0 && t >= seconds) break;
                           std::this_thread::sleep_until(t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                  std::chrono::duration<double>(t)));
                           server.step(t, dt);
                         }
                         const auto& p = server.odometry_pose();
                         std::cout << "served " << steps << " odometry messages, " << server.commands_received()
                                   << " commands received; odometry at x " << p.x_m << " m, y " << p.y_m << " m, heading "
                                   << p.theta_rad * 180.0 / M_PI << " deg\n";
                         return interrupted() ? interrupt_exit_code() : 0;
                       }};

}  // namespace projbot::tools
