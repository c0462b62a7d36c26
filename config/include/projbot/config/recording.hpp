#pragma once
// A session's recording (issue 12, item 4): recording.yaml in the recording's folder, beside one
// fakenect dump per stop (stopNN/) and the poses the session's trackers gave for every frame
// (poses.csv). `projbot record` writes it; `projbot run --replay` reads it back and runs the same
// session from it, with no device and no twin. Read errors are ConfigError with file:line.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"

namespace projbot::config {

/// One stop as the robot recorded it: what the session asked for and what the devices answered.
struct RecordedStop {
  int visit = 0;  ///< 0-based over the tour
  std::string target;
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();      ///< the stop driven to: x, y (m), heading (rad)
  Eigen::Vector3d believed = Eigen::Vector3d::Zero();  ///< where the robot then believed it stood: x, y, heading
  double pan_rad = 0.0, tilt_rad = 0.0;                ///< the pan-tilt's angles as it reported them after aiming
  double drive_s = 0.0;                                ///< how long the drive took
  bool arrived = false;
  std::string frames;  ///< the stop's fakenect dump, relative to the recording's folder
  int frame_count = 0;
};

struct Recording {
  std::filesystem::path source;  ///< recording.yaml
  std::filesystem::path scene;   ///< the scene recorded (absolute)
  std::string camera;            ///< which camera it was
  std::uint64_t seed = 0;
  double dwell_s = 0.0;
  bool interrupted = false;  ///< cut short: the stops listed are those recorded
  /// The robot's laser scans and wheel odometry as an MRPT rawlog, relative to the folder (empty: none;
  /// a configured robot's laser is not recorded yet).
  std::string laser;
  std::vector<RecordedStop> stops;
  /// Each target's reflectance as the session learnt it, by target name: a map over its model's texture
  /// coordinates (`texture`, a PNG relative to the folder), or for a model without them one `albedo`.
  /// `run --replay` compensates with it in place of the scene's `surface:`. Empty: none learnt (a
  /// configured camera's recording).
  std::map<std::string, TargetSurface> reflectance;
  /// The folder the recording's relative paths start from.
  std::filesystem::path folder() const { return source.parent_path(); }
};

/// `scene` with each target's `surface:` replaced by the reflectance `recording` learnt for it (a map, its
/// file in the recording's folder, or one albedo). Throws ConfigError for a target the scene does not hold.
void use_learnt_reflectance(Scene& scene, const Recording& recording);

/// recording.yaml's text for `r` (its source is not written).
std::string recording_yaml(const Recording& r);
/// Reads DIR/recording.yaml. Throws ConfigError naming the file (and line) for a missing or malformed one.
Recording load_recording(const std::filesystem::path& folder);

}  // namespace projbot::config
