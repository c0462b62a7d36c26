// The occupancy grid and the simulated scanner: mrpt::maps, one translation unit.
#include <mrpt/maps/COccupancyGridMap2D.h>

#include <cmath>

#include "mrpt_convert.hpp"

namespace projbot::robot {

struct OccupancyMap::Impl {
  mrpt::maps::COccupancyGridMap2D grid;
};

OccupancyMap::OccupancyMap(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OccupancyMap::OccupancyMap(const OccupancyMap& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
OccupancyMap& OccupancyMap::operator=(const OccupancyMap& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
OccupancyMap::~OccupancyMap() = default;

OccupancyMap OccupancyMap::from_room(const config::Room& room) {
  if (!(room.width_m > 0.5) || !(room.depth_m > 0.5) || !(room.resolution_m > 0.001) || !(room.wall_thickness_m > 0))
    throw RobotError("room: width and depth must be > 0.5 m, resolution > 1 mm, walls thicker than 0");
  const double margin = room.wall_thickness_m + 0.2;
  auto impl = std::make_unique<Impl>();
  auto& g = impl->grid;
  g.setSize(static_cast<float>(-margin), static_cast<float>(room.width_m + margin), static_cast<float>(-margin),
            static_cast<float>(room.depth_m + margin), static_cast<float>(room.resolution_m), 0.5f);
  const auto fill_box = [&](double x0, double y0, double x1, double y1, float value) {
    for (int cy = g.y2idx(y0); cy <= g.y2idx(y1); ++cy)
      for (int cx = g.x2idx(x0); cx <= g.x2idx(x1); ++cx)
        if (cx >= 0 && cy >= 0 && cx < static_cast<int>(g.getSizeX()) && cy < static_cast<int>(g.getSizeY()))
          g.setCell(cx, cy, value);
  };
  const double t = room.wall_thickness_m, w = room.width_m, d = room.depth_m;
  fill_box(-t, -t, w + t, d + t, 0.0f);  // walls (value = probability of free)
  fill_box(0.0, 0.0, w - 1e-9, d - 1e-9, 1.0f);
  for (const config::Box2D& b : room.obstacles) {
    if (!(b.max_x_m > b.min_x_m) || !(b.max_y_m > b.min_y_m))
      throw RobotError("room: an obstacle box needs min < max on both axes");
    fill_box(b.min_x_m, b.min_y_m, b.max_x_m - 1e-9, b.max_y_m - 1e-9, 0.0f);
  }
  return OccupancyMap(std::move(impl));
}

void OccupancyMap::save_png(const std::filesystem::path& path) const {
  if (!impl_->grid.saveAsBitmapFile(path.string())) throw RobotError(path.string() + ": cannot write the grid image");
}

bool OccupancyMap::is_free(double x, double y) const {
  const auto& g = impl_->grid;
  const int cx = g.x2idx(x), cy = g.y2idx(y);
  if (cx < 0 || cy < 0 || cx >= static_cast<int>(g.getSizeX()) || cy >= static_cast<int>(g.getSizeY())) return false;
  return g.getCell(cx, cy) > 0.6f;
}

LaserScan OccupancyMap::simulate_scan(const Pose2D& T_world_base, const LaserConfig& laser, std::mt19937_64& rng) const {
  LaserScan s;
  s.sensor_on_base = laser.sensor_on_base;
  s.aperture_rad = laser.aperture_rad;
  s.max_range_m = laser.max_range_m;
  auto obs = detail::to_mrpt(s);
  // MRPT's ray tracer with its noise off: the noise is ours, seeded, so runs repeat.
  impl_->grid.laserScanSimulator(*obs, detail::to_mrpt(T_world_base), 0.5f, static_cast<std::size_t>(laser.rays), 0.0f);
  s = detail::from_mrpt(*obs);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(laser.range_noise_m));
  for (std::size_t i = 0; i < s.ranges_m.size(); ++i) {
    if (s.ranges_m[i] >= laser.max_range_m * 0.999) s.valid[i] = 0;
    if (s.valid[i]) s.ranges_m[i] += noise(rng);
  }
  return s;
}

}  // namespace projbot::robot
