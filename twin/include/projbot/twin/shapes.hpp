#pragma once
// Shape classes the real frames do not cover, made procedurally for the twin's datasets (issue 68): thin
// walls and hollows (a bowl, a cup, a plate), a cylinder, an elongated curved body. Closed meshes in
// metres, faces outward, in a frame whose +z is the shape's own up (a plate's, a bowl's) and whose origin
// lies on its axis.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "projbot/assets/model.hpp"

namespace projbot::twin {

/// A profile (radius, height) in metres, from the axis back to the axis, revolved about +z into a closed
/// solid with `segments` steps around. The profile runs so that the solid lies on its right: out along
/// the bottom, up the outside, back down the inside. One flat colour.
assets::Model revolve(const std::vector<Eigen::Vector2d>& profile, int segments, const std::array<float, 4>& rgba);

/// A tube of radius tapering from `radius_m` at its middle to 55 % at its ends, bent along an arc of
/// `bend_radius_m` through `angle_rad`, lying in the x-y plane, ends capped.
assets::Model bent_tube(double radius_m, double bend_radius_m, double angle_rad, const std::array<float, 4>& rgba);

/// One procedural object: its name and mesh, and the axis through the origin its shape turns onto itself
/// about (a body of revolution's), if any.
struct ProceduralShape {
  std::string name;
  assets::Model model;
  std::optional<Eigen::Vector3d> axis;
};

/// The twin's procedural shapes: a bowl (4 mm wall, concave), a cup without handle (3 mm wall), a plate
/// (3 mm thick), a closed cylinder along x, a bent tube (banana-like).
std::vector<ProceduralShape> procedural_shapes();

}  // namespace projbot::twin
