#pragma once
// MRPT ICP-SLAM (building the environment map) and scan-to-map ICP localisation with odometry
// prediction; rawlogs and trajectories on disk.

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "projbot/robot/laser.hpp"

namespace projbot::robot {

/// Whether this build has MRPT (the occupancy grid and simulated laser, localisation, mapping, rawlogs, the
/// real laser and pan-tilt drivers): false in the portable build (tools/bundle.sh), where each of those
/// throws RobotError saying so.
bool built_with_mrpt();

/// One step of a rawlog: an odometry increment (in the previous base frame) and a scan.
struct RawlogStep {
  double timestamp_s = 0.0;
  std::optional<Pose2D> odometry_increment;
  LaserScan scan;
};

/// Reads an MRPT rawlog (actions-observations format, plain or gzip). The first
/// CObservation2DRangeScan of each sensory frame is taken. Throws RobotError naming the file.
std::vector<RawlogStep> read_rawlog(const std::filesystem::path& path);
/// Writes steps as an MRPT rawlog (gzip), readable by MRPT's own tools.
void write_rawlog(const std::filesystem::path& path, const std::vector<RawlogStep>& steps);

/// A trajectory sample: `timestamp x y phi` per line on disk (seconds, metres, radians).
struct TrajectoryPoint {
  double timestamp_s = 0.0;
  Pose2D pose;
};
void write_trajectory(const std::filesystem::path& path, const std::vector<TrajectoryPoint>& trajectory);
/// Reads `timestamp x y phi` lines; throws RobotError naming file:line on anything else.
std::vector<TrajectoryPoint> read_trajectory(const std::filesystem::path& path);

/// How far an estimated trajectory lies from the truth: position (m) and heading (degrees), mean and
/// largest, over the estimates matched to a true pose by timestamp (nearest, within 1 ms), or by index
/// when the timestamps do not match at all.
struct TrajectoryErrors {
  double mean_m = 0.0, max_m = 0.0, mean_deg = 0.0, max_deg = 0.0;
  std::size_t n = 0;  ///< poses compared
};
TrajectoryErrors trajectory_errors(const std::vector<TrajectoryPoint>& estimate, const std::vector<TrajectoryPoint>& truth);
/// Odometry alone: each step's increment composed onto `start`, one point per step.
std::vector<TrajectoryPoint> dead_reckoning(const std::vector<RawlogStep>& steps, const Pose2D& start);

/// Result of a mapping run.
struct SlamResult {
  std::vector<TrajectoryPoint> trajectory;  ///< the corrected pose after every step
  std::size_t keyframes = 0;                ///< scans inserted into the map
  double seconds = 0.0;                     ///< wall time of the run
  bool interrupted = false;                 ///< stopped early: the map and trajectory of the steps done
};

/// Checks an icp-slam configuration strictly, before any work: every line a section, a comment or
/// `key = value`; every value of a key MRPT knows of the kind MRPT reads (whole number, number,
/// true/false, one of its names); [MappingApplication] and [ICP] present. Throws RobotError naming the
/// file, line and key; returns a warning per [ICP] key that MRPT does not know (a misspelling?).
std::vector<std::string> check_icp_slam_config(const std::filesystem::path& ini);

/// Builds the map with mrpt::slam::CMetricMapBuilderICP from rawlog steps. `ini` is an icp-slam
/// configuration ([MappingApplication] and [ICP] sections, as MRPT's icp-slam app reads);
/// without one, the defaults of MRPT's icp-slam_demo_classic.ini apply. Writes to `out_dir`:
/// map.simplemap.gz (keyframes: poses and scans), grid.png and grid.yaml (ROS map_server form).
/// `stop_requested`, asked before each step, ends the run there (Ctrl-C): the steps done are mapped and
/// written as for a whole run; stopped before the first step, nothing is written.
/// `out_dir` is replaced only when it is new, empty or holds only a map's files (map_folder_files());
/// anything else in it is refused (RobotError), before the work, never emptied.
/// `verbose` lets MRPT's own log lines (its map builder's, at info level) through to stderr.
/// `start` is where the rawlog's first pose lies in the map (its odometry holds increments only): the
/// map and the trajectory are in that frame, so a mapping run begun at the scene's robot.start gives a
/// map in the scene's world frame.
/// The files build_map() writes into its folder, and all it may find there to replace.
const std::set<std::string>& map_folder_files();

SlamResult build_map(const std::vector<RawlogStep>& steps, const std::optional<std::filesystem::path>& ini,
                     const std::filesystem::path& out_dir, const std::function<bool()>& stop_requested = {}, bool verbose = false,
                     const Pose2D& start = {});

/// Localiser settings.
struct LocalizerConfig {
  double icp_threshold_m = 0.3;  ///< initial correspondence distance (shrinks by alfa)
  double icp_smallest_threshold_m = 0.02;
  double min_goodness = 0.5;  ///< share of scan points paired; below it the scan is rejected
  unsigned max_iterations = 80;
  double max_correction_m = 0.5;  ///< a jump larger than this from the prediction is rejected
};

/// The outcome of one correction.
struct LocalizationUpdate {
  Pose2D pose;            ///< T_world_base after the update
  bool accepted = false;  ///< false: the scan did not match; `pose` is the odometry prediction
  double goodness = 0.0;  ///< CICP's share of paired points, [0, 1]
  unsigned iterations = 0;
  double time_ms = 0.0;
};

/// Scan-to-map localisation: the pose follows odometry between scans (predict) and is corrected
/// by mrpt::slam::CICP of each scan against the map's points (correct). Not thread-safe.
class Localizer {
 public:
  /// A map from keyframes: scans taken at known T_world_base poses.
  Localizer(const std::vector<std::pair<Pose2D, LaserScan>>& keyframes, const LocalizerConfig& config = {});
  /// Loads map.simplemap.gz from a directory written by build_map(). Throws RobotError.
  static Localizer load(const std::filesystem::path& map_dir, const LocalizerConfig& config = {});
  Localizer(Localizer&&) noexcept;
  Localizer& operator=(Localizer&&) noexcept;
  ~Localizer();

  void reset(const Pose2D& T_world_base);
  /// Moves the estimate by an odometry increment (in the current base frame).
  void predict(const Pose2D& odometry_increment);
  LocalizationUpdate correct(const LaserScan& scan);
  const Pose2D& pose() const;
  /// Number of points in the map.
  std::size_t map_points() const;

 private:
  struct Impl;
  explicit Localizer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A rawlog localised against the map: the pose after every step, the scans ICP accepted, and the time
/// spent correcting (ms, in all).
struct RawlogLocalization {
  std::vector<TrajectoryPoint> trajectory;
  int accepted = 0;
  double correct_ms = 0.0;
};
/// Starts `localizer` at `start`, then for each step lets odometry predict and the scan correct.
/// `keep_going(done)` is asked after each step; false stops there (the steps done are kept).
RawlogLocalization localize_rawlog(Localizer& localizer, const std::vector<RawlogStep>& steps, const Pose2D& start,
                                   const std::function<bool(int done)>& keep_going = {});

}  // namespace projbot::robot
