#pragma once
// A simulated tour of stops: the base drives from stop to stop under the controller, closing the
// loop on MRPT localisation (or on odometry alone, the paper's set-up), and every arrival is
// compared with the ground truth. Used by the tests, `projbot bench localize` and the twin.

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <vector>

#include "projbot/robot/base.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/robot/navigator.hpp"
#include "projbot/robot/sim_base.hpp"

namespace projbot::robot {

/// What closes the loop.
enum class PoseSource { odometry, localized };

struct SimTourConfig {
  config::Room room;
  std::vector<Pose2D> stops;  ///< visited in order, `stop_count` in all (cycling)
  int stop_count = 10;
  Pose2D start;  ///< true and believed start pose
  config::OdometryDrift errors;
  LaserConfig laser;
  ControllerConfig controller;
  LocalizerConfig localizer;
  PoseSource source = PoseSource::localized;
  double control_dt_s = 0.025;  ///< control period (the laser's 40 Hz)
  int localize_every = 4;       ///< correct with every n-th scan while driving (10 Hz)
  double max_seconds_per_stop = 120.0;
  double survey_spacing_m = 1.0;  ///< the map: scans at true poses on this grid over free space
  /// Asked before each survey scan (the set-up's long part: about 13 ms a scan, one a square metre):
  /// true ends the construction with SetupInterrupted, so SIGTERM is heard within a scan.
  std::function<bool()> stop_requested;
};

/// The simulated robot of a tour, one stop at a time: the room and its map, the drifting base, wheel
/// odometry and the MRPT localiser (localized mode; a portable build without MRPT closes the loop on
/// odometry alone and refuses localized mode with RobotError). The twin drives it and asks where the robot believes it is.
/// Deterministic for a given config. Not thread-safe: one owner thread.
class SimRobot final : public Navigator {
 public:
  explicit SimRobot(const SimTourConfig& config);
  /// Drives to `goal` under the controller (closing the loop on config.source), then settles.
  /// `index` is copied into the report.
  StopReport drive_to(const Pose2D& goal, int index) override;
  /// What the robot believes (localisation or odometry, by config.source) and the ground truth.
  Pose2D believed_pose() const override;
  Pose2D true_pose() const { return base_.true_pose(); }
  Pose2D odometry_pose() const { return odometry_.pose(); }
  /// Called with every laser scan the robot takes (while driving and settling; localized mode) and the
  /// wheel odometry at that instant: what a recording keeps as its rawlog.
  void on_scan(std::function<void(const LaserScan&, const Pose2D& odometry)> listener) { on_scan_ = std::move(listener); }
  double time_s() const { return time_s_; }

 private:
  class Steps;  // a drive's steps, for drive_loop()
  SimTourConfig c_;
  std::optional<OccupancyMap> map_;  // the room's grid: the laser's world (none in a portable build)
  std::mt19937_64 rng_;
  std::optional<Localizer> localizer_;  // localized mode only
  SimulatedBase base_;
  WheelOdometry odometry_;
  BaseController controller_;
  double time_s_ = 0.0;
  std::function<void(const LaserScan&, const Pose2D&)> on_scan_;
};

/// Runs the tour. Deterministic for a given config (all noise is seeded). `stop_requested`, asked before
/// each stop, ends the tour there (Ctrl-C): the reports of the stops reached.
std::vector<StopReport> run_sim_tour(const SimTourConfig& config, const std::function<bool()>& stop_requested = {});

/// A tour's errors at its stops: what the robot believed against the truth (m, rad; mean and largest),
/// the mean localisation update time (ms), and wheel odometry's drift at the last stop.
struct SimTourErrors {
  double mean_m = 0.0, max_m = 0.0, mean_rad = 0.0, max_rad = 0.0, correct_ms = 0.0;
  double last_odometry_m = 0.0, last_odometry_rad = 0.0;
};
SimTourErrors tour_errors(const std::vector<StopReport>& reports);

/// The built-in demo room (8 x 6 m with furniture) and a ring of stops in it.
SimTourConfig default_sim_tour();

}  // namespace projbot::robot
