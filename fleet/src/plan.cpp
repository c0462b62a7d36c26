#include "projbot/fleet/plan.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <utility>

namespace projbot::fleet {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

FloorMap::FloorMap(const config::Scene& scene, double robot_radius_m, double cell_m)
    : cell_m_(cell_m),
      width_(static_cast<int>(std::ceil(scene.room.width_m / cell_m))),
      depth_(static_cast<int>(std::ceil(scene.room.depth_m / cell_m))) {
  blocked_.assign(static_cast<std::size_t>(width_) * static_cast<std::size_t>(depth_), false);
  std::vector<config::Box2D> boxes = scene.room.obstacles;
  for (const config::PropConfig& p : scene.props)
    if (p.is_box()) boxes.push_back(p.box_footprint());
  for (int y = 0; y < depth_; ++y)
    for (int x = 0; x < width_; ++x) {
      const double cx = (x + 0.5) * cell_m, cy = (y + 0.5) * cell_m;
      bool near_wall = cx < robot_radius_m || cy < robot_radius_m || cx > scene.room.width_m - robot_radius_m ||
                       cy > scene.room.depth_m - robot_radius_m;
      for (const config::Box2D& b : boxes)
        near_wall = near_wall || (cx > b.min_x_m - robot_radius_m && cx < b.max_x_m + robot_radius_m &&
                                  cy > b.min_y_m - robot_radius_m && cy < b.max_y_m + robot_radius_m);
      blocked_[static_cast<std::size_t>(y * width_ + x)] = near_wall;
    }
}

int FloorMap::cell_of(const std::array<double, 2>& at) const {
  const int x = std::clamp(static_cast<int>(std::floor(at[0] / cell_m_)), 0, width_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor(at[1] / cell_m_)), 0, depth_ - 1);
  return y * width_ + x;
}

bool FloorMap::free(const std::array<double, 2>& at) const {
  return width_ > 0 && depth_ > 0 && !blocked_[static_cast<std::size_t>(cell_of(at))];
}

// A robot or stop a little inside an obstacle's margin (a stop beside a table) starts from the nearest
// free cell; -1 when none is free.
int FloorMap::nearest_free(int cell) const {
  int best = -1;
  double best_d = kInfinity;
  const int cx = cell % width_, cy = cell / width_;
  for (int i = 0; i < width_ * depth_; ++i) {
    if (blocked_[static_cast<std::size_t>(i)]) continue;
    const double d = std::hypot(i % width_ - cx, i / width_ - cy);
    if (d < best_d) best_d = d, best = i;
  }
  return best;
}

std::vector<double> FloorMap::lengths_from(const std::array<double, 2>& from) const {
  std::vector<double> length(blocked_.size(), kInfinity);
  if (blocked_.empty()) return length;
  int start = cell_of(from);
  if (blocked_[static_cast<std::size_t>(start)]) start = nearest_free(start);
  if (start < 0) return length;
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  length[static_cast<std::size_t>(start)] = 0.0;
  open.push({0.0, start});
  while (!open.empty()) {
    const auto [d, c] = open.top();
    open.pop();
    if (d > length[static_cast<std::size_t>(c)]) continue;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = c % width_ + dx, y = c / width_ + dy;
        if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= width_ || y >= depth_) continue;
        const int n = y * width_ + x;
        if (blocked_[static_cast<std::size_t>(n)]) continue;
        const double next = d + cell_m_ * std::hypot(dx, dy);
        if (next < length[static_cast<std::size_t>(n)]) length[static_cast<std::size_t>(n)] = next, open.push({next, n});
      }
  }
  return length;
}

double FloorMap::length_to(const std::vector<double>& lengths, const std::array<double, 2>& to) const {
  if (lengths.empty()) return kInfinity;
  int cell = cell_of(to);
  if (blocked_[static_cast<std::size_t>(cell)]) cell = nearest_free(cell);
  return cell < 0 ? kInfinity : lengths[static_cast<std::size_t>(cell)];
}

Plan make_plan(const config::Scene& scene, const FloorMap& floor, const std::vector<RobotSeen>& robots) {
  Plan plan;
  std::vector<RobotSeen> by_name = robots;  // the same plan whatever order the robots were heard in
  std::sort(by_name.begin(), by_name.end(), [](const RobotSeen& a, const RobotSeen& b) { return a.name < b.name; });
  std::vector<std::size_t> open;  // scene indices of the targets with a stop
  for (std::size_t t = 0; t < scene.targets.size(); ++t)
    if (scene.targets[t].stop) open.push_back(t);
  const auto stop_of = [&](std::size_t t) {
    return std::array<double, 2>{scene.targets[t].stop->x(), scene.targets[t].stop->y()};
  };
  std::vector<std::size_t> given(by_name.size(), 0);
  std::vector<std::vector<double>> from;  // each robot's lengths from where its route now ends
  for (const RobotSeen& r : by_name) {
    plan.targets_of[r.name];
    from.push_back(floor.lengths_from(r.at));
  }
  // Round by round, the nearest pair of a target and a robot among those given the fewest so far.
  while (!open.empty() && !by_name.empty()) {
    double best = kInfinity;
    std::size_t best_r = 0, best_k = 0;
    const std::size_t last_round = *std::max_element(given.begin(), given.end());
    for (std::size_t round = *std::min_element(given.begin(), given.end()); !std::isfinite(best) && round <= last_round; ++round)
      for (std::size_t r = 0; r < by_name.size(); ++r)
        for (std::size_t k = 0; given[r] == round && k < open.size(); ++k)
          if (const double length = floor.length_to(from[r], stop_of(open[k])); length < best)
            best = length, best_r = r, best_k = k;
    if (!std::isfinite(best)) break;
    const std::size_t t = open[best_k];
    plan.targets_of[by_name[best_r].name].push_back(scene.targets[t].name);
    ++given[best_r];
    from[best_r] = floor.lengths_from(stop_of(t));
    open.erase(open.begin() + static_cast<std::ptrdiff_t>(best_k));
  }
  if (!by_name.empty())
    for (const std::size_t t : open) plan.unreachable.push_back(scene.targets[t].name);
  return plan;
}

}  // namespace projbot::fleet
