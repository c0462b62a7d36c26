// projbot devices: what this machine offers Projbot, and whether a scene's configured devices work.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/hardware/devices.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/pose2d.hpp"
#include "projbot/robot/ros2_base.hpp"
#include "projbot/robot/urg_emulator.hpp"

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

// sim-base's laser: a Hokuyo UTM-30LX on a pseudo-terminal linked at `link`, its scans ray-traced in the
// scene's room from where the base truly stands (T_room_odometry composed with the server's pose, which
// starts at robot.start). The link is removed when it is done.
class SimBaseLaser {
 public:
  SimBaseLaser(const config::Scene& scene, std::filesystem::path link, const robot::Pose2D& T_room_odometry)
      : map_(robot::OccupancyMap::from_room(room(scene))),
        unit_(std::vector<std::uint32_t>(robot::UrgEmulator::kSteps, 0)),
        link_(std::move(link)),
        T_room_odometry_(T_room_odometry) {
    std::error_code ec;
    if (std::filesystem::is_symlink(link_, ec)) std::filesystem::remove(link_, ec);
    std::filesystem::create_symlink(unit_.port(), link_, ec);
    if (ec)
      throw cli::UsageError("--laser " + link_.string() + ": cannot link the laser's pseudo-terminal there: " + ec.message());
    laser_.rays = robot::UrgEmulator::kSteps;  // the UTM-30LX: 270 degrees in 0.25 degree steps
  }
  ~SimBaseLaser() {
    std::error_code ec;
    std::filesystem::remove(link_, ec);
  }
  SimBaseLaser(const SimBaseLaser&) = delete;
  SimBaseLaser& operator=(const SimBaseLaser&) = delete;

  // The scans from now on: from the base at `pose` (the server's frame).
  void stand_at(const robot::Pose2D& pose) {
    const robot::LaserScan scan = map_.simulate_scan(robot::compose(T_room_odometry_, pose), laser_, rng_);
    std::vector<std::uint32_t> mm(scan.ranges_m.size(), 0);
    for (std::size_t i = 0; i < mm.size(); ++i)
      if (scan.valid[i]) mm[i] = static_cast<std::uint32_t>(std::lround(1000.0 * scan.ranges_m[i]));
    unit_.set_ranges(std::move(mm));
  }
  int scans_sent() const { return unit_.scans_sent(); }

 private:
  // The scene's room and its box props: what a laser at this height sees.
  static config::Room room(const config::Scene& scene) {
    config::Room r = scene.room;
    for (const auto& p : scene.props)
      if (p.is_box()) r.obstacles.push_back(p.box_footprint());
    return r;
  }
  robot::OccupancyMap map_;
  robot::UrgEmulator unit_;
  std::filesystem::path link_;
  robot::Pose2D T_room_odometry_;
  robot::LaserConfig laser_;
  std::mt19937_64 rng_{7};
};

int serve_sim_base(const cli::Args& args) {
  catch_interrupts();
  config::BaseDevice base;
  robot::Pose2D start{1.0, 1.0, 0.0};
  std::optional<config::Scene> scene;
  if (const auto path = args.get("config")) {
    scene = config::load_scene(*path);
    if (scene->devices.base) base = *scene->devices.base;
    start = {scene->robot_start.x(), scene->robot_start.y(), scene->robot_start.z()};
  }
  base.domain = args.get_int("domain", base.domain, 0, 232);
  const double seconds = args.get_double("seconds", 0.0);
  if (!(seconds >= 0.0 && seconds <= 1e6)) throw cli::UsageError("--seconds must be 0 (until Ctrl-C) to 1e6");
  const int rate = args.get_int("rate", 50, 1, 1000);
  const robot::Pose2D true_start = args.get("true-start") ? parse_pose(*args.get("true-start"), "--true-start") : start;
  const robot::Pose2D T_room_odometry = robot::compose(true_start, robot::inverse(start));  // where the base was set down
  std::unique_ptr<SimBaseLaser> laser;
  if (const auto link = args.get("laser")) {
    if (!scene) throw cli::UsageError("--laser needs --config: the laser's scans are ray-traced in its room");
    laser = std::make_unique<SimBaseLaser>(*scene, *link, T_room_odometry);
  }
  robot::Ros2BaseServer server(base, start);
  std::cout << "serving the twin's youBot on DDS domain " << base.domain << ": rt/" << base.cmd_vel << " in, rt/" << base.odom
            << " out at " << rate << " Hz";
  if (laser) std::cout << "; its laser (Hokuyo UTM-30LX, SCIP 2.0) on " << *args.get("laser");
  std::cout << " (Ctrl-C stops)" << std::endl;
  const auto t0 = std::chrono::steady_clock::now();
  const double dt = 1.0 / rate;
  int steps = 0;
  for (; !interrupted(); ++steps) {
    const double t = steps * dt;
    if (seconds > 0.0 && t >= seconds) break;
    std::this_thread::sleep_until(
        t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(t)));
    server.step(t, dt);
    if (laser) laser->stand_at(server.true_pose());
  }
  const auto& p = server.odometry_pose();
  const robot::Pose2D truth = robot::compose(T_room_odometry, server.true_pose());
  std::cout << "served " << steps << " odometry messages, " << server.commands_received() << " commands received; odometry at x "
            << p.x_m << " m, y " << p.y_m << " m, heading " << p.theta_rad * 180.0 / M_PI << " deg; truly at x " << truth.x_m
            << " m, y " << truth.y_m << " m, heading " << truth.theta_rad * 180.0 / M_PI << " deg";
  if (laser) std::cout << "; " << laser->scans_sent() << " laser scans sent";
  std::cout << "\n";
  return interrupted() ? interrupt_exit_code() : 0;
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
                       {{"config", "FILE", "a scene whose `devices:` section to check", cli::PathRole::input_file},
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
                         std::vector<hardware::DeviceCheck> checks;
                         hardware::open_devices(scene->devices, checks, false);
                         bool all_ok = true;
                         for (const auto& c : checks) {
                           std::cout << "  " << c.config << ": " << (c.ok ? "ok, " : "FAILED: ") << c.detail << "\n";
                           all_ok = all_ok && c.ok;
                         }
                         return all_ok ? 0 : 1;
                       }};

const Command kSimBase{"sim-base",
                       "serve the twin's youBot base on ROS 2 DDS topics (cmd_vel in, odom out), for trying a base driver",
                       "projbot sim-base [--config site.yaml] [--domain N] [--seconds S] [--rate HZ] [--laser LINK]\n"
                       "                 [--true-start \"x y phi\"]\n\n"
                       "Runs the digital twin's youBot (wheel kinematics, encoders, wheel odometry; no drift) as a ROS 2 base\n"
                       "driver would: it follows the newest geometry_msgs/msg/Twist on rt/cmd_vel (stopping when none came\n"
                       "for 0.5 s) and publishes nav_msgs/msg/Odometry on rt/odom at --rate, over Cyclone DDS with ROS 2's\n"
                       "names on the wire, so `ros2 topic echo /odom` on another machine shows it and `projbot devices` or a\n"
                       "real session can drive it. The domain and topic names come from the config's `devices.base` (default\n"
                       "domain 0, cmd_vel, odom), the start pose from its `robot.start`. Runs until Ctrl-C or --seconds.\n\n"
                       "With --laser it also serves the robot's laser: a Hokuyo UTM-30LX speaking SCIP 2.0 on a pseudo-terminal\n"
                       "linked at LINK (what `devices.laser` names as COM_port_LIN, class CHokuyoURG), its scans ray-traced\n"
                       "in the config's room (walls, obstacles and box props; not the targets) from where the base truly\n"
                       "stands, the scanner 0.25 m ahead of the base (pose_x: 0.25). With --true-start the base truly starts\n"
                       "there (metres, metres, radians) while its odometry starts at robot.start: a robot set down off its\n"
                       "place, which only the laser can tell.\n",
                       {{"config", "FILE", "scene whose devices.base, robot.start and room to use", cli::PathRole::input_file},
                        {"domain", "N", "DDS domain id 0..232 (overrides devices.base.domain)"},
                        {"seconds", "S", "stop after S seconds (default 0: until Ctrl-C)"},
                        {"rate", "HZ", "odometry messages per second (default 50)"},
                        {"laser", "LINK", "serve the laser on a pseudo-terminal linked at LINK (needs --config)"},
                        {"true-start", "\"x y phi\"", "where the base truly starts (default: robot.start)"}},
                       serve_sim_base};

}  // namespace projbot::tools
