#include "projbot/robot/sim_tour.hpp"

#include <chrono>
#include <cmath>

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

std::vector<StopReport> run_sim_tour(const SimTourConfig& c) {
  const OccupancyMap map = OccupancyMap::from_room(c.room);
  std::mt19937_64 rng(c.errors.seed * 7919 + 17);

  // The environment map: a survey with scans at known poses (what a careful mapping run
  // produces), so that localisation is judged against ground truth, not against its own map.
  std::vector<std::pair<Pose2D, LaserScan>> survey;
  for (double y = c.survey_spacing_m / 2; y < c.room.depth_m; y += c.survey_spacing_m)
    for (double x = c.survey_spacing_m / 2; x < c.room.width_m; x += c.survey_spacing_m)
      if (map.is_free(x, y) && map.is_free(x + c.laser.sensor_on_base.x_m, y)) {
        const Pose2D p{x, y, 0.0};
        survey.emplace_back(p, map.simulate_scan(p, c.laser, rng));
      }
  Localizer localizer(survey, c.localizer);
  localizer.reset(c.start);

  SimulatedBase base(c.start, c.errors);
  WheelOdometry odometry(base.geometry(), c.start);
  odometry.update(base.read_encoders());
  BaseController controller(c.controller, base.geometry());
  double time_s = 0.0;

  std::vector<StopReport> reports;
  for (int i = 0; i < c.stop_count && !c.stops.empty(); ++i) {
    const Pose2D goal = c.stops[static_cast<std::size_t>(i) % c.stops.size()];
    StopReport r;
    r.index = i;
    r.goal = goal;
    controller.reset();
    double ms_total = 0.0;
    const auto scan_and_correct = [&] {
      LaserScan scan = map.simulate_scan(base.true_pose(), c.laser, rng);
      scan.timestamp_s = time_s;
      const auto t0 = std::chrono::steady_clock::now();
      const LocalizationUpdate u = localizer.correct(scan);
      ms_total += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      ++r.corrections;
      if (!u.accepted) ++r.rejected;
    };
    const double t_start = time_s;
    for (long step = 0;; ++step) {
      const Pose2D before = odometry.pose();
      const Pose2D& after = odometry.update(base.read_encoders());
      if (c.source == PoseSource::localized) {
        localizer.predict(between(before, after));
        if (step % c.localize_every == 0) scan_and_correct();
      }
      const Pose2D estimate = c.source == PoseSource::localized ? localizer.pose() : odometry.pose();
      const BaseTwist cmd = controller.update(estimate, goal, c.control_dt_s);
      if (controller.arrived()) break;
      if (time_s - t_start > c.max_seconds_per_stop) break;
      base.set_wheel_speeds(wheel_speeds_from_twist(cmd, base.geometry()));
      base.advance(c.control_dt_s);
      time_s += c.control_dt_s;
    }
    base.set_wheel_speeds({});
    r.arrived = controller.arrived();
    if (c.source == PoseSource::localized)
      for (int k = 0; k < c.settle_scans; ++k) scan_and_correct();
    r.drive_seconds = time_s - t_start;
    r.truth = base.true_pose();
    r.odometry = odometry.pose();
    r.estimate = c.source == PoseSource::localized ? localizer.pose() : odometry.pose();
    r.error_m = distance_m(r.estimate, r.truth);
    r.error_rad = heading_error_rad(r.estimate, r.truth);
    r.odometry_error_m = distance_m(r.odometry, r.truth);
    r.odometry_error_rad = heading_error_rad(r.odometry, r.truth);
    r.arrival_error_m = distance_m(r.truth, goal);
    r.correct_ms_mean = r.corrections > 0 ? ms_total / r.corrections : 0.0;
    reports.push_back(r);
  }
  return reports;
}

}  // namespace projbot::robot
