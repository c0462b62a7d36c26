#pragma once
// A mobile base driven through ROS 2 topics over Eclipse Cyclone DDS (issue 12, `devices.base`), with no
// ROS 2 installed: geometry_msgs/msg/Twist published on `cmd_vel`, nav_msgs/msg/Odometry read from
// `odom`, with ROS 2's names on the wire (topics `rt/<name>`, types `<pkg>::msg::dds_::<Type>_`, CDR),
// so any ROS 2 base driver (the youBot's through a bridge) answers it and `ros2 topic echo` shows it.
// Also the other side: the twin's simulated youBot served on the same topics, for tests and for
// trying a ROS 2 tool without a robot. Cyclone DDS types stay in src/.

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "projbot/config/devices.hpp"
#include "projbot/robot/base.hpp"
#include "projbot/robot/error.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/robot/navigator.hpp"
#include "projbot/robot/pose2d.hpp"
#include "projbot/robot/sim_base.hpp"
#include "projbot/robot/youbot.hpp"

namespace projbot::robot {

/// A planar odometry reading: nav_msgs/Odometry's pose (x, y, yaw) and twist, stamped by its sender.
struct Odometry2D {
  double stamp_s = 0.0;
  Pose2D pose;
  BaseTwist twist;
};

/// The robot's side: commands a base and reads its odometry.
class Ros2Base {
 public:
  /// Joins DDS domain `config.domain` and creates the writer and reader. Throws RobotError naming the
  /// domain when DDS cannot start.
  explicit Ros2Base(const config::BaseDevice& config);
  ~Ros2Base();
  Ros2Base(const Ros2Base&) = delete;
  Ros2Base& operator=(const Ros2Base&) = delete;

  /// Publishes a velocity command (base frame: x forward, y left, yaw counter-clockwise).
  void send(const BaseTwist& twist);
  /// The newest odometry received, waiting up to timeout_s for the first. Throws RobotError naming the
  /// topic when none arrives (no base driver running, or another domain).
  Odometry2D odometry(double timeout_s);
  /// What this base is, for messages: "base (ros2-dds, domain 0, rt/odom)".
  const std::string& name() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The base over ROS 2 topics as the session's Navigator: drives to a stop under the stop controller,
/// closing the loop on the base's odometry in real time, placed in the map where the config says the
/// robot starts (the odometry frame's pose is fixed at the first message: a driver whose odometry starts at
/// zero and one that publishes map poses both work). On wheel odometry alone it drifts as the paper's did;
/// use_laser() adds a laser, whose scans matched against the map move the odometry frame's place in it.
class Ros2Navigator final : public Navigator {
 public:
  /// `base` outlives the navigator. Reads the first odometry (RobotError naming the base when none comes).
  Ros2Navigator(Ros2Base& base, const Pose2D& start_in_map, const ControllerConfig& controller = {}, double rate_hz = 20.0,
                double timeout_s = 120.0);
  /// Drives until the controller says arrived (or timeout_s passes: arrived false), stops the base and
  /// lets it settle. Throws RobotError naming the base when its odometry stops for a second.
  /// The report's `odometry` is where odometry alone (from the configured start) puts the robot,
  /// `estimate` where it believes it stands, with the laser's corrections counted and timed.
  StopReport drive_to(const Pose2D& goal, int index) override;
  Pose2D believed_pose() const override { return compose(T_map_odom_, last_.pose); }
  /// Reads `laser` from now on: a scan at every control step while driving and settle_scans (3) once
  /// stopped (and as many now). With a `map`, each is matched against it (from the configured start at first: a robot set
  /// down a few centimetres off it is found); without, the scans are only handed to on_scan (a mapping run,
  /// recorded for projbot slam). Both outlive the navigator. Throws RobotError naming the laser when it
  /// sends no scan.
  void use_laser(LaserSource& laser, Localizer* map);
  /// Called with each scan read and the wheel odometry read with it (record writes them as a rawlog).
  void on_scan(std::function<void(const LaserScan&, const Pose2D& odometry)> listener) { on_scan_ = std::move(listener); }

 private:
  struct Corrections {
    int count = 0, rejected = 0;
    double ms = 0.0;
  };
  class Steps;  // a drive's steps, for drive_loop()
  Odometry2D fresh(double& last_change_s);
  /// One scan matched against the map (with the newest odometry); stops the base when the laser fails.
  void correct(double& last_change_s, Corrections& c);
  Ros2Base& base_;
  BaseController controller_;
  int settle_scans_;
  double rate_hz_, timeout_s_;
  Pose2D T_map_odom_, T_map_odom_start_;
  Odometry2D last_;
  LaserSource* laser_ = nullptr;
  Localizer* map_ = nullptr;
  std::function<void(const LaserScan&, const Pose2D&)> on_scan_;
};

/// The twin's side: a simulated youBot (SimulatedBase, wheel odometry) that follows the newest cmd_vel
/// (stopping when none came for 0.5 s, as base drivers do) and publishes its wheel odometry on `odom`.
class Ros2BaseServer {
 public:
  Ros2BaseServer(const config::BaseDevice& config, const Pose2D& start,
                 const config::OdometryDrift& errors = config::OdometryDrift::none());
  ~Ros2BaseServer();
  Ros2BaseServer(const Ros2BaseServer&) = delete;
  Ros2BaseServer& operator=(const Ros2BaseServer&) = delete;

  /// Takes the newest command, moves the simulation dt_s forward (at clock time now_s) and publishes
  /// the odometry.
  void step(double now_s, double dt_s);
  /// Ground truth and the odometry as published.
  const Pose2D& true_pose() const;
  const Pose2D& odometry_pose() const;
  /// Velocity commands received so far.
  int commands_received() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Runs `server` at `rate_hz` on the steady clock (each step at its own time) until `seconds` have
/// passed (0: no limit) or `keep_going` says no; `each_step` is called after every step (a laser standing
/// where the base now truly is). Returns the steps run.
int serve(Ros2BaseServer& server, int rate_hz, double seconds, const std::function<bool()>& keep_going,
          const std::function<void()>& each_step = {});

/// What DDS shows on a domain after listening a while: the other participants, and the topics they
/// publish and subscribe (name and type as on the wire: "rt/odom", "nav_msgs::msg::dds_::Odometry_").
struct DdsSurvey {
  int participants = 0;                                         ///< not counting the one that listened
  std::vector<std::pair<std::string, std::string>> published;   ///< topic, type; sorted, once each
  std::vector<std::pair<std::string, std::string>> subscribed;  ///< topic, type; sorted, once each
};
/// Joins `domain`, listens `listen_s` seconds and reports what it saw. Throws RobotError when DDS cannot start.
DdsSurvey survey_dds(int domain, double listen_s);

}  // namespace projbot::robot
