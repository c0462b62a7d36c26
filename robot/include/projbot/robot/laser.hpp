#pragma once
// 2-D laser scans, the room's occupancy grid and the simulated scanner (MRPT's ray tracer).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <vector>

#include "projbot/config/room.hpp"
#include "projbot/robot/error.hpp"
#include "projbot/robot/pose2d.hpp"

namespace projbot::robot {

/// A planar laser scanner. Defaults: Hokuyo UTM-30LX (270 degrees in 0.25 degree steps, 30 m,
/// +-30 mm up to 10 m read as 1 sigma of 10 mm, 40 Hz), mounted 0.25 m ahead of the base origin.
struct LaserConfig {
  double aperture_rad = 4.71238898;  ///< 270 degrees, centred on the sensor's x axis
  int rays = 1081;
  double max_range_m = 30.0;
  double range_noise_m = 0.01;            ///< Gaussian sigma added to every range
  Pose2D sensor_on_base{0.25, 0.0, 0.0};  ///< T_base_laser
  double rate_hz = 40.0;
};

/// One scan: ray i looks at -aperture/2 + i * aperture / (rays - 1) in the sensor frame.
struct LaserScan {
  double timestamp_s = 0.0;
  Pose2D sensor_on_base;
  double aperture_rad = 0.0;
  double max_range_m = 0.0;
  std::vector<float> ranges_m;
  std::vector<std::uint8_t> valid;  ///< 0 where the ray saw nothing within range
};

/// Where scans come from: a real scanner (MrptLaser) or a simulated one.
class LaserSource {
 public:
  virtual ~LaserSource() = default;
  /// The next scan (waits at most timeout_s). Throws RobotError naming the scanner when none comes.
  virtual LaserScan next(double timeout_s) = 0;
};

/// An occupancy grid (mrpt::maps::COccupancyGridMap2D underneath). Copyable, not thread-safe.
class OccupancyMap {
 public:
  /// Rasterises a room.
  static OccupancyMap from_room(const config::Room& room);
  OccupancyMap(const OccupancyMap& other);
  OccupancyMap& operator=(const OccupancyMap& other);
  ~OccupancyMap();

  /// Writes the grid as a PNG (black occupied, white free, grey unknown).
  void save_png(const std::filesystem::path& path) const;
  /// True when the cell at (x, y) is known free.
  bool is_free(double x_m, double y_m) const;
  /// Simulates a scan from a base at T_world_base (ray tracing the grid, then seeded noise).
  LaserScan simulate_scan(const Pose2D& T_world_base, const LaserConfig& laser, std::mt19937_64& rng) const;

 private:
  struct Impl;
  explicit OccupancyMap(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::robot
