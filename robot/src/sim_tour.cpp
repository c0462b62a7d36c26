#include "projbot/robot/sim_tour.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "projbot/config/clock.hpp"

namespace projbot::robot {

SimTourConfig default_sim_tour() {
  SimTourConfig c;
  c.room.width_m = 8.0;
  c.room.depth_m = 6.0;
  c.room.obstacles = {{2.0, 2.5, 2.6, 3.5}, {5.0, 0.0, 6.2, 0.6}, {5.5, 4.2, 6.0, 4.7}, {0.0, 5.2, 1.2, 6.0}};
  c.stops = {{1.5, 1.2, 0.0}, {4.0, 1.5, 1.57}, {6.8, 2.5, 3.14}, {4.0, 4.5, -1.57}, {1.8, 4.3, 0.78}};
  c.start = {1.0, 1.0, 0.0};
  return c;
}

namespace {

// The environment map: a survey with scans at known poses (what a careful mapping run produces),
// so that localisation is judged against ground truth, not against its own map.
Localizer surveyed_localizer(const SimTourConfig& c, const OccupancyMap& map, std::mt19937_64& rng) {
  std::vector<std::pair<Pose2D, LaserScan>> survey;
  // At most about kMaxSurveyScans scans (a room of up to 1000 m2 keeps its spacing): a 200 x 200 m room
  // once surveyed 40000 scans, 520 s of set-up.
  constexpr double kMaxSurveyScans = 1000.0;
  const double spacing = std::max(c.survey_spacing_m, std::sqrt(c.room.width_m * c.room.depth_m / kMaxSurveyScans));
  for (double y = spacing / 2; y < c.room.depth_m; y += spacing)
    for (double x = spacing / 2; x < c.room.width_m; x += spacing)
      if (map.is_free(x, y) && map.is_free(x + c.laser.sensor_on_base.x_m, y)) {
        if (c.stop_requested && c.stop_requested()) throw SetupInterrupted("stopped while surveying the simulated room's map");
        const Pose2D p{x, y, 0.0};
        survey.emplace_back(p, map.simulate_scan(p, c.laser, rng));
      }
  Localizer localizer(survey, c.localizer);
  localizer.reset(c.start);
  return localizer;
}

}  // namespace

SimRobot::SimRobot(const SimTourConfig& config)
    : c_(config),
      rng_(config.errors.seed * 7919 + 17),
      base_(config.start, config.errors),
      odometry_(base_.geometry(), config.start),
      controller_(config.controller, base_.geometry()) {
  if (c_.source == PoseSource::localized && !built_with_mrpt())
    throw RobotError(
        "the simulated robot's laser localisation needs MRPT, which this portable build leaves out "
        "(tools/bundle.sh): close the loop on odometry alone (tour --mode odometry) or use the full build");
  if (built_with_mrpt()) map_.emplace(OccupancyMap::from_room(config.room));  // also checks the room
  // The survey's scans draw on rng_; odometry mode draws nothing more from it, so leaving it out there changes nothing.
  if (c_.source == PoseSource::localized) localizer_.emplace(surveyed_localizer(c_, *map_, rng_));
  odometry_.update(base_.read_encoders());
}

Pose2D SimRobot::believed_pose() const { return localizer_ ? localizer_->pose() : odometry_.pose(); }

// A drive's steps on the simulated clock: wheel odometry every control period, localisation predicted
// with it and corrected with every localize_every-th scan (localized mode).
class SimRobot::Steps final : public DriveSteps {
 public:
  Steps(SimRobot& robot, StopReport& report) : r_(robot), report_(report), t_start_(robot.time_s_) {}
  void sense(long step) override {
    const Pose2D before = r_.odometry_.pose();
    const Pose2D& after = r_.odometry_.update(r_.base_.read_encoders());
    if (!r_.localizer_) return;
    r_.localizer_->predict(between(before, after));
    if (step % r_.c_.localize_every == 0) scan_and_correct();
  }
  Pose2D believed_pose() const override { return r_.believed_pose(); }
  double step_s() override { return r_.c_.control_dt_s; }
  double elapsed_s() const override { return r_.time_s_ - t_start_; }
  void command(const BaseTwist& twist) override {
    r_.base_.set_wheel_speeds(wheel_speeds_from_twist(twist, r_.base_.geometry()));
    r_.base_.advance(r_.c_.control_dt_s);
    r_.time_s_ += r_.c_.control_dt_s;
  }
  void halt() override { r_.base_.set_wheel_speeds({}); }
  void settle() override {
    if (!r_.localizer_) return;
    for (int k = 0; k < r_.c_.controller.settle_scans; ++k) {  // at rest, one scan per laser period (the control period)
      r_.time_s_ += r_.c_.control_dt_s;
      scan_and_correct();
    }
  }
  double correct_ms = 0.0;  ///< wall time of the corrections, together

 private:
  void scan_and_correct() {
    LaserScan scan = r_.map_->simulate_scan(r_.base_.true_pose(), r_.c_.laser, r_.rng_);
    scan.timestamp_s = r_.time_s_;
    if (r_.on_scan_) r_.on_scan_(scan, r_.odometry_.pose());
    const auto t0 = std::chrono::steady_clock::now();
    const LocalizationUpdate u = r_.localizer_->correct(scan);
    correct_ms += config::ms_since(t0);
    ++report_.corrections;
    if (!u.accepted) ++report_.rejected;
  }
  SimRobot& r_;
  StopReport& report_;
  double t_start_;
};

StopReport SimRobot::drive_to(const Pose2D& goal, int index) {
  StopReport r;
  r.index = index;
  r.goal = goal;
  Steps steps(*this, r);
  r.arrived = drive_loop(controller_, steps, goal, c_.max_seconds_per_stop, watch_);
  r.drive_seconds = steps.elapsed_s();
  r.truth = base_.true_pose();
  r.odometry = odometry_.pose();
  r.estimate = believed_pose();
  r.error_m = distance_m(r.estimate, r.truth);
  r.error_rad = heading_error_rad(r.estimate, r.truth);
  r.odometry_error_m = distance_m(r.odometry, r.truth);
  r.odometry_error_rad = heading_error_rad(r.odometry, r.truth);
  r.arrival_error_m = distance_m(r.truth, goal);
  r.correct_ms_mean = r.corrections > 0 ? steps.correct_ms / r.corrections : 0.0;
  return r;
}

std::vector<StopReport> run_sim_tour(const SimTourConfig& c, const std::function<bool()>& stop_requested) {
  SimRobot robot(c);
  std::vector<StopReport> reports;
  for (int i = 0; i < c.stop_count && !c.stops.empty() && !(stop_requested && stop_requested()); ++i)
    reports.push_back(robot.drive_to(c.stops[static_cast<std::size_t>(i) % c.stops.size()], i));
  return reports;
}

SimTourErrors tour_errors(const std::vector<StopReport>& reports) {
  SimTourErrors e;
  if (reports.empty()) return e;
  for (const auto& r : reports) {
    e.mean_m += r.error_m, e.max_m = std::max(e.max_m, r.error_m);
    e.mean_rad += r.error_rad, e.max_rad = std::max(e.max_rad, r.error_rad);
    e.correct_ms += r.correct_ms_mean;
  }
  const double k = static_cast<double>(reports.size());
  e.mean_m /= k, e.mean_rad /= k, e.correct_ms /= k;
  e.last_odometry_m = reports.back().odometry_error_m;
  e.last_odometry_rad = reports.back().odometry_error_rad;
  return e;
}

}  // namespace projbot::robot
