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
#include "projbot/config/angles.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/devices.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/pose2d.hpp"
#include "projbot/robot/ros2_base.hpp"
#include "projbot/robot/urg_emulator.hpp"

namespace projbot::tools {
namespace {

// The scene's room and its box props: what a laser at this height sees.
config::Room laser_room(const config::Scene& scene) {
  config::Room r = scene.room;
  for (const auto& p : scene.props)
    if (p.is_box()) r.obstacles.push_back(p.box_footprint());
  return r;
}

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
  std::unique_ptr<robot::RoomUrg> laser;
  if (const auto link = args.get("laser")) {
    if (!scene) throw cli::UsageError("--laser needs --config: the laser's scans are ray-traced in its room");
    try {
      laser = std::make_unique<robot::RoomUrg>(laser_room(*scene), *link, T_room_odometry);
    } catch (const robot::RobotError& e) {
      throw cli::UsageError(std::string("--laser ") + e.what());
    }
  }
  robot::Ros2BaseServer server(base, start);
  std::cout << "serving the twin's youBot on DDS domain " << base.domain << ": rt/" << base.cmd_vel << " in, rt/" << base.odom
            << " out at " << rate << " Hz";
  if (laser) std::cout << "; its laser (Hokuyo UTM-30LX, SCIP 2.0) on " << *args.get("laser");
  std::cout << " (Ctrl-C stops)" << std::endl;
  const int steps = robot::serve(
      server, rate, seconds, [] { return !interrupted(); },
      [&] {
        if (laser) laser->stand_at(server.true_pose());
      });
  const auto& p = server.odometry_pose();
  const robot::Pose2D truth = robot::compose(T_room_odometry, server.true_pose());
  std::cout << "served " << steps << " odometry messages, " << server.commands_received() << " commands received; odometry at x "
            << p.x_m << " m, y " << p.y_m << " m, heading " << config::degrees(p.theta_rad) << " deg; truly at x " << truth.x_m
            << " m, y " << truth.y_m << " m, heading " << config::degrees(truth.theta_rad) << " deg";
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
                         live::list_found(std::cout, domain);
                         if (!scene) return 0;
                         std::cout << "\nconfigured in " << scene->source.string() << ":\n";
                         if (!scene->devices.any()) {
                           std::cout << "  no `devices:` section: every device is the digital twin's (projbot run --sim)\n";
                           return 0;
                         }
                         std::vector<live::DeviceCheck> checks;
                         live::open_devices(scene->devices, checks, false);
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
