#pragma once
// The mobile base as the projection session drives it (issue 12): to a stop under closed-loop control,
// then where the robot believes it is. The twin's simulated robot is one implementation; a real base
// over ROS 2 topics, on its odometry (Ros2Navigator), is another.

#include <functional>

#include "projbot/robot/pose2d.hpp"

namespace projbot::robot {

/// One drive to a stop, as the robot measured it (truth fields only where a simulation knows them).
struct StopReport {
  int index = 0;
  Pose2D goal, truth, estimate, odometry;
  double error_m = 0.0, error_rad = 0.0;                    ///< estimate (what the robot believes) vs truth
  double odometry_error_m = 0.0, odometry_error_rad = 0.0;  ///< raw wheel odometry vs truth
  double arrival_error_m = 0.0;                             ///< truth vs goal
  bool arrived = false;
  double drive_seconds = 0.0;  ///< time to reach the stop and settle (simulated in the twin, real on a base)
  int corrections = 0, rejected = 0;
  double correct_ms_mean = 0.0;  ///< wall time per localisation update
};

/// Where the robot believes it stands at a control step of a drive (map frame).
using DriveWatch = std::function<void(const Pose2D& believed)>;

class Navigator {
 public:
  virtual ~Navigator() = default;
  /// `watch` is called on the driving thread at every control step of each drive from now on, with where
  /// the robot then believes it stands (the operator's map follows it). It must be quick and not throw.
  void watch_drive(DriveWatch watch) { watch_ = std::move(watch); }
  /// Drives to `goal` in the map and settles there; `index` is copied into the report. Throws
  /// RobotError naming the device when the base cannot be driven.
  virtual StopReport drive_to(const Pose2D& goal, int index) = 0;
  /// Where the robot believes its base stands in the map (localisation, or odometry alone).
  virtual Pose2D believed_pose() const = 0;

 protected:
  DriveWatch watch_;  ///< for drive_loop: empty, none
};

}  // namespace projbot::robot
