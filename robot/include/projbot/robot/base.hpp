#pragma once
// The mobile base boundary and the controller that drives it to a stop.
//
// Hardware adapters plug in here: a real youBot adapter implements MobileBase over EtherCAT
// (youbot_driver on SOEM, which Debian does not package), sending the four wheel velocities and
// reading the motor encoders. Everything above this interface (odometry, localisation, the
// controller, the tour) is the same for the twin and the robot.

#include <functional>

#include "projbot/robot/youbot.hpp"

namespace projbot::robot {

/// A wheeled base. Not thread-safe: one control thread owns it.
class MobileBase {
 public:
  virtual ~MobileBase() = default;
  /// Commands wheel velocities (rad/s of the wheels, youbot order); held until the next call.
  virtual void set_wheel_speeds(const WheelSpeeds& speeds) = 0;
  /// The motors' encoder counts now.
  virtual WheelTicks read_encoders() = 0;
  /// The base's geometry (for the kinematics above it).
  virtual const YoubotGeometry& geometry() const = 0;
};

/// Motion limits and arrival tolerances of the stop controller.
struct ControllerConfig {
  double max_speed_m_s = 0.4;             ///< translational speed limit
  double max_omega_rad_s = 0.8;           ///< rotational speed limit
  double max_accel_m_s2 = 0.5;            ///< translational acceleration limit
  double max_alpha_rad_s2 = 1.5;          ///< rotational acceleration limit
  double position_tolerance_m = 0.01;     ///< arrived when closer than this ...
  double heading_tolerance_rad = 0.0087;  ///< ... and within this heading (0.5 degrees)
  double slow_down_gain = 1.2;            ///< proportional gain near the goal, 1/s
  /// Laser scans matched against the map at rest after arrival, the stop's best fix (navigators with a
  /// laser and a map: the twin's and the ROS 2 base's).
  int settle_scans = 3;
};

/// Holonomic point-to-pose controller: a trapezoidal speed profile towards the goal with
/// velocity and acceleration limits, translation and rotation at once. It closes the loop on
/// whatever pose it is given: the localised pose, not odometry alone.
class BaseController {
 public:
  explicit BaseController(const ControllerConfig& config = {}, const YoubotGeometry& geometry = {});
  /// The next command for a base estimated at `estimate`, heading for `goal`, dt after the last call.
  BaseTwist update(const Pose2D& estimate, const Pose2D& goal, double dt_s);
  /// True once within both tolerances (set by update()).
  bool arrived() const { return arrived_; }
  /// Forgets the last command (call before a new goal from rest).
  void reset() {
    last_ = {};
    arrived_ = false;
  }

 private:
  ControllerConfig config_;
  YoubotGeometry geometry_;
  BaseTwist last_;
  bool arrived_ = false;
};

/// What differs between robots at each step of a drive to a stop (the twin's simulated base on its
/// simulated clock, a real base over ROS 2 on the wall clock); drive_loop() is the loop around them.
class DriveSteps {
 public:
  virtual ~DriveSteps() = default;
  /// Reads the odometry (and, when one is due at this step, a laser scan) into the believed pose.
  virtual void sense(long step) = 0;
  virtual Pose2D believed_pose() const = 0;
  /// Seconds since the last control step (the controller's dt).
  virtual double step_s() = 0;
  /// Seconds since the drive began.
  virtual double elapsed_s() const = 0;
  /// Sends `twist` to the base and waits out the control period.
  virtual void command(const BaseTwist& twist) = 0;
  /// Stops the base.
  virtual void halt() = 0;
  /// At rest after the drive: the stop's last corrections (laser scans against the map).
  virtual void settle() = 0;
};

/// The drive to a stop: sense, ask `controller`, command, until it says arrived or `timeout_s` has passed;
/// then halt and settle. Returns whether it arrived. `watch` (when set) is told the believed pose at
/// every step.
bool drive_loop(BaseController& controller, DriveSteps& steps, const Pose2D& goal, double timeout_s,
                const std::function<void(const Pose2D&)>& watch = {});

}  // namespace projbot::robot
