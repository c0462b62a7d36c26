#pragma once
// Pan-tilt kinematics and aiming, the PanTilt boundary, and its simulated unit.

#include <Eigen/Geometry>
#include <string>

#include "projbot/config/robot.hpp"
#include "projbot/robot/pose2d.hpp"

namespace projbot::robot {

/// Pan and tilt angles, radians. Pan turns left (counter-clockwise seen from above) for positive
/// values; tilt looks up for positive values.
struct PanTiltAngles {
  double pan_rad = 0.0;
  double tilt_rad = 0.0;
};

/// Where the head's frames are for a base pose and the pan-tilt angles.
struct HeadPoses {
  Eigen::Isometry3d T_world_camera;
  Eigen::Isometry3d T_world_projector;
};

/// Forward kinematics: base pose (T_world_base) and angles to the camera and projector frames.
HeadPoses head_poses(const Pose2D& T_world_base, const PanTiltAngles& angles, const config::PanTiltConfig& rig);

/// Result of aiming at a point.
struct AimResult {
  PanTiltAngles angles;        ///< the angles to command, clamped into the limits
  bool within_limits = false;  ///< false when the exact solution lies outside the unit's range
  double miss_rad = 0.0;       ///< angle between the optical axis and the target direction at `angles`
};

/// The pan and tilt that put `target_world` (metres) on the camera's optical axis for a base at
/// T_world_base. Accounts for the mount and camera offsets (solved by fixed-point iteration,
/// which converges while the offsets are small against the range).
AimResult aim_at(const Pose2D& T_world_base, const Eigen::Vector3d& target_world, const config::PanTiltConfig& rig);

/// Outcome of a pan-tilt command: expected failures are values (STYLE.md).
struct PanTiltStatus {
  bool ok = true;
  std::string error;  ///< empty when ok
};

/// A pan-tilt unit. Not thread-safe: the robot thread owns it.
class PanTilt {
 public:
  virtual ~PanTilt() = default;
  /// Moves both axes to absolute angles and waits until they arrive.
  virtual PanTiltStatus move_to(const PanTiltAngles& angles) = 0;
  /// The unit's own report of where it is (its step counters).
  virtual PanTiltStatus position(PanTiltAngles& out) = 0;
};

/// Simulated unit: positions are whole steps; the output shaft has backlash (a dead band of
/// `backlash_rad` that the drive must cross when it reverses), so the true angle can differ
/// from the reported one by up to half of it.
class SimulatedPanTilt final : public PanTilt {
 public:
  explicit SimulatedPanTilt(const config::PanTiltConfig& rig, double backlash_rad = 0.0005);
  PanTiltStatus move_to(const PanTiltAngles& angles) override;
  PanTiltStatus position(PanTiltAngles& out) override;
  /// Ground truth: where the head really points.
  PanTiltAngles true_angles() const { return true_; }

 private:
  config::PanTiltConfig rig_;
  double backlash_rad_;
  PanTiltAngles steps_;  ///< commanded, quantised
  PanTiltAngles true_;   ///< after backlash
};

}  // namespace projbot::robot
