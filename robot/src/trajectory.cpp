// Trajectories on disk (`timestamp x y phi` lines), compared and dead-reckoned, a rawlog localised step by
// step, and the names of a map folder's files: no MRPT here, so that a build without MRPT (tools/bundle.sh)
// keeps them (the localiser itself says there that it is left out).
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <sstream>

#include "projbot/config/angles.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/robot/localization.hpp"

namespace projbot::robot {

void write_trajectory(const std::filesystem::path& path, const std::vector<TrajectoryPoint>& trajectory) {
  std::ostringstream out;
  out << std::fixed;
  for (const auto& p : trajectory)
    out << std::setprecision(6) << p.timestamp_s << ' ' << std::setprecision(5) << p.pose.x_m << ' ' << p.pose.y_m << ' '
        << p.pose.theta_rad << '\n';
  config::write_file_atomically(path, out.str());
}

std::vector<TrajectoryPoint> read_trajectory(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw RobotError(path.string() + ": cannot open the trajectory file");
  std::vector<TrajectoryPoint> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::istringstream fields(line);
    TrajectoryPoint p;
    std::string extra;
    if (!(fields >> p.timestamp_s >> p.pose.x_m >> p.pose.y_m >> p.pose.theta_rad) || (fields >> extra) ||
        !std::isfinite(p.timestamp_s + p.pose.x_m + p.pose.y_m + p.pose.theta_rad))
      throw RobotError(path.string() + ":" + std::to_string(number) + ": expected 'timestamp x y phi' (4 finite numbers)");
    // Checked, not only typed: x = 1e308 or time running backwards was once compared as if it were right.
    if (std::abs(p.pose.x_m) > 1e6 || std::abs(p.pose.y_m) > 1e6 || std::abs(p.pose.theta_rad) > 1e3)
      throw RobotError(path.string() + ":" + std::to_string(number) +
                       ": x and y must lie within 1000 km (|x|, |y| <= 1e6 m) and |phi| <= 1000 rad");
    if (!out.empty() && !(p.timestamp_s > out.back().timestamp_s))
      throw RobotError(path.string() + ":" + std::to_string(number) + ": timestamp " + std::to_string(p.timestamp_s) +
                       " does not come after the line before's (" + std::to_string(out.back().timestamp_s) +
                       "): timestamps must increase");
    out.push_back(p);
  }
  if (out.empty()) throw RobotError(path.string() + ": no trajectory lines");
  return out;
}

const std::set<std::string>& map_folder_files() {
  static const std::set<std::string> files{"map.simplemap.gz", "grid.png", "grid.yaml"};
  return files;
}

TrajectoryErrors trajectory_errors(const std::vector<TrajectoryPoint>& est, const std::vector<TrajectoryPoint>& truth) {
  TrajectoryErrors s;
  if (truth.empty()) return s;
  std::size_t j = 0;
  for (std::size_t i = 0; i < est.size(); ++i) {
    while (j + 1 < truth.size() && truth[j + 1].timestamp_s <= est[i].timestamp_s + 1e-3) ++j;
    const bool by_time = std::abs(truth[j].timestamp_s - est[i].timestamp_s) < 1e-3;
    const TrajectoryPoint* t = by_time ? &truth[j] : (i < truth.size() ? &truth[i] : nullptr);
    if (t == nullptr) continue;
    const double e = distance_m(est[i].pose, t->pose), a = config::degrees(heading_error_rad(est[i].pose, t->pose));
    s.mean_m += e, s.mean_deg += a, s.max_m = std::max(s.max_m, e), s.max_deg = std::max(s.max_deg, a), ++s.n;
  }
  if (s.n > 0) s.mean_m /= static_cast<double>(s.n), s.mean_deg /= static_cast<double>(s.n);
  return s;
}

std::vector<TrajectoryPoint> dead_reckoning(const std::vector<RawlogStep>& steps, const Pose2D& start) {
  std::vector<TrajectoryPoint> out;
  Pose2D p = start;
  for (const auto& s : steps) {
    if (s.odometry_increment) p = compose(p, *s.odometry_increment);
    out.push_back({s.timestamp_s, p});
  }
  return out;
}

RawlogLocalization localize_rawlog(Localizer& localizer, const std::vector<RawlogStep>& steps, const Pose2D& start,
                                   const std::function<bool(int done)>& keep_going) {
  RawlogLocalization r;
  localizer.reset(start);
  for (const auto& s : steps) {
    if (s.odometry_increment) localizer.predict(*s.odometry_increment);
    const auto u = localizer.correct(s.scan);
    r.accepted += u.accepted;
    r.correct_ms += u.time_ms;
    r.trajectory.push_back({s.timestamp_s, localizer.pose()});
    if (keep_going && !keep_going(static_cast<int>(r.trajectory.size()))) break;
  }
  return r;
}

}  // namespace projbot::robot
