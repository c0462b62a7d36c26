#pragma once
// The configured devices serving a whole projection session (`run`, `record` with a robot configured):
// the base over ROS 2 topics, the pan-tilt, the camera and, when configured, the laser. No twin, so no truth.

#include <optional>
#include <vector>

#include "projbot/live/devices.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/robot/ros2_base.hpp"

namespace projbot::live {

/// The configured devices serving the whole session: the base over ROS 2 topics (closing the loop on its
/// odometry, started at the scene's robot.start), the PTU-D46 and the camera. No twin, so no truth.
class DeviceRig final : public Rig {
 public:
  /// `devices` (base, pan_tilt and camera opened; the laser when configured) outlive the rig. With a
  /// laser, the base localises on it against the scene's devices.laser.map (without a map its scans are
  /// only recorded: a mapping run). Throws RobotError when the
  /// base sends no odometry, the laser no scan or the map cannot be read.
  /// `lockstep`: every frame tracked before the next is read (record).
  DeviceRig(const config::Scene& scene, const std::vector<Target>& targets, Devices& devices, bool lockstep);
  StopSequence& session() override { return session_; }
  Dwell dwell(double dwell_s) override;
  void on_scan(ScanListener listener) override { navigator_.on_scan(std::move(listener)); }

 private:
  std::optional<robot::Localizer> map_;
  robot::Ros2Navigator navigator_;
  alignment::RgbdCamera& camera_;
  bool lockstep_;
  StopSequence session_;
};

}  // namespace projbot::live
