#pragma once
// The configured devices serving a whole projection session (`run`, `record` with a robot configured):
// the base over ROS 2 topics, the pan-tilt, the camera and, when configured, the laser. No twin, so no truth.

#include <optional>
#include <vector>

#include "projbot/hardware/devices.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/robot/ros2_base.hpp"
#include "projbot/session/session.hpp"

namespace projbot::hardware {

/// The configured devices serving the whole session: the base over ROS 2 topics (closing the loop on its
/// odometry, started at the scene's robot.start), the PTU-D46 and the camera. No twin, so no truth.
class DeviceSession {
 public:
  /// `devices` (base, pan_tilt and camera opened; the laser when configured) outlive the rig. With a
  /// laser, the base localises on it against the scene's devices.laser.map (without a map its scans are
  /// only recorded: a mapping run). Throws RobotError when the
  /// base sends no odometry, the laser no scan or the map cannot be read.
  DeviceSession(const config::Scene& scene, const std::vector<session::Target>& targets, Devices& devices);
  session::Session& session() { return session_; }
  session::Dwell dwell(double dwell_s, bool lockstep);
  robot::Ros2Navigator& navigator() { return navigator_; }

 private:
  std::optional<robot::Localizer> map_;
  robot::Ros2Navigator navigator_;
  alignment::RgbdCamera& camera_;
  session::Session session_;
};

}  // namespace projbot::hardware
