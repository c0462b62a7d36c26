#pragma once
// The room a tour runs in: one type for a scene's `room:`, the twin's walls and the laser's map.

#include <vector>

namespace projbot::config {

/// An axis-aligned rectangle on the floor, metres, map frame.
struct Box2D {
  double min_x_m, min_y_m, max_x_m, max_y_m;
};

/// A rectangular room from (0, 0) to (width, depth), metres, map frame, with box obstacles standing on
/// its floor.
struct Room {
  double width_m = 8.0;
  double depth_m = 6.0;
  std::vector<Box2D> obstacles;
  /// The outline and the obstacles stand this high in the twin's depth and projector light.
  double wall_height_m = 2.5;
  /// The room's own light on every surface while projecting, lux (`room.ambient_lux`, 0..100000): a
  /// dimmed shop or museum room.
  double ambient_lux = 20.0;
  /// The laser's occupancy grid: the walls' thickness and the cell size. MRPT's ray tracer reads walls
  /// about one cell too far (1.2-1.6 cm at 1 cm cells, measured), the same for the map and live scans.
  double wall_thickness_m = 0.1;
  double resolution_m = 0.01;
};

}  // namespace projbot::config
