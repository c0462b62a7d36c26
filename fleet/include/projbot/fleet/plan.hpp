#pragma once
// The fleet's plan (issue 69, item 2): which robot visits which of the site's targets, in what order. The
// floor is a grid over the room with its obstacles grown by the robot's radius; path lengths are the
// shortest 8-connected paths on it. Round by round, each robot given the fewest targets so far takes
// the nearest target left from where its route ends (the nearest free robot first), so every reachable
// target is visited, the robots share the work, and a target is never given to two robots. The same
// robots at the same places give the same plan on any coordinator.

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"

namespace projbot::fleet {

/// Shortest path lengths on the room's floor.
class FloorMap {
 public:
  /// The room's outline and obstacles, and the scene's box props, grown by `robot_radius_m`, on cells of
  /// `cell_m`.
  explicit FloorMap(const config::Scene& scene, double robot_radius_m = 0.3, double cell_m = 0.1);
  /// Metres from `from` to every cell (Dijkstra; a blocked start is moved to the nearest free cell).
  std::vector<double> lengths_from(const std::array<double, 2>& from) const;
  /// The length at `to` in lengths_from's result; infinity where no path reaches it.
  double length_to(const std::vector<double>& lengths, const std::array<double, 2>& to) const;
  bool free(const std::array<double, 2>& at) const;

 private:
  int cell_of(const std::array<double, 2>& at) const;
  int nearest_free(int cell) const;
  double cell_m_;
  int width_ = 0, depth_ = 0;
  std::vector<bool> blocked_;
};

/// A robot the coordinator hears, where it last said it stood (map frame, metres).
struct RobotSeen {
  std::string name;
  std::array<double, 2> at{};
};

struct Plan {
  /// Each robot's targets in the order to visit them (scene target names); a robot heard with nothing to
  /// do has an empty list.
  std::map<std::string, std::vector<std::string>> targets_of;
  std::vector<std::string> unreachable;  ///< targets with a stop no robot heard can drive to
  bool operator==(const Plan&) const = default;
};

/// Assigns the scene's targets that have a stop to `robots` (none: every target unassigned).
Plan make_plan(const config::Scene& scene, const FloorMap& floor, const std::vector<RobotSeen>& robots);

}  // namespace projbot::fleet
