// Trajectories on disk (`timestamp x y phi` lines) and the names of a map folder's files: plain text and
// names, no MRPT, so that a build without MRPT (tools/bundle.sh) keeps them.
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

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

}  // namespace projbot::robot
