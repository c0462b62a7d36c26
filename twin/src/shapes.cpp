#include "projbot/twin/shapes.hpp"

#include <Eigen/Geometry>
#include <cmath>

#include "projbot/config/angles.hpp"

namespace projbot::twin {
namespace {

using assets::Vertex;

Vertex vertex(const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  Vertex v;
  v.position = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
  v.normal = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
  return v;
}

assets::Model one_colour(assets::Primitive p, const std::array<float, 4>& rgba, const std::string& source) {
  assets::Model m;
  m.source = source;
  m.primitives.push_back(std::move(p));
  assets::Material material;
  material.base_color_factor = rgba;
  m.materials.push_back(material);
  return m;
}

void add_triangle(assets::Primitive& p, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
  const auto at = [&](std::uint32_t i) {
    const auto& q = p.vertices[i].position;
    return Eigen::Vector3d(q[0], q[1], q[2]);
  };
  if ((at(b) - at(a)).cross(at(c) - at(a)).norm() < 1e-12) return;  // on the axis: no area
  p.indices.insert(p.indices.end(), {a, b, c});
}

// Cup-like profile through (0, 0) ... (0, top): a solid of revolution with thin walls.
std::vector<Eigen::Vector2d> walled(double outer_r, double height, double wall, double bottom) {
  return {{0.0, 0.0}, {outer_r, 0.0}, {outer_r, height}, {outer_r - wall, height}, {outer_r - wall, bottom}, {0.0, bottom}};
}

std::vector<Eigen::Vector2d> bowl_profile() {
  std::vector<Eigen::Vector2d> out{{0.0, 0.0}};
  const int n = 16;
  for (int i = 0; i <= n; ++i) {  // the outside: a foot 35 mm wide curving up to the rim
    const double t = M_PI / 2 * i / n;
    out.emplace_back(0.035 + 0.045 * std::sin(t), 0.055 * (1.0 - std::cos(t)));
  }
  for (int i = n; i >= 0; --i) {  // the inside, 4 mm in
    const double t = M_PI / 2 * i / n;
    out.emplace_back(0.031 + 0.045 * std::sin(t), 0.004 + 0.051 * (1.0 - std::cos(t)));
  }
  out.emplace_back(0.0, 0.004);
  return out;
}

}  // namespace

assets::Model revolve(const std::vector<Eigen::Vector2d>& profile, int segments, const std::array<float, 4>& rgba) {
  assets::Primitive p;
  for (std::size_t s = 0; s + 1 < profile.size(); ++s) {
    const Eigen::Vector2d a = profile[s], b = profile[s + 1];
    if ((b - a).norm() < 1e-9) continue;
    const Eigen::Vector2d d = (b - a).normalized();
    const Eigen::Vector2d n(d.y(), -d.x());  // the solid lies on the profile's right: its outside on the left
    const auto base = static_cast<std::uint32_t>(p.vertices.size());
    for (int j = 0; j <= segments; ++j) {
      const double phi = 2.0 * M_PI * j / segments, c = std::cos(phi), si = std::sin(phi);
      const Eigen::Vector3d normal(n.x() * c, n.x() * si, n.y());
      p.vertices.push_back(vertex({a.x() * c, a.x() * si, a.y()}, normal));
      p.vertices.push_back(vertex({b.x() * c, b.x() * si, b.y()}, normal));
    }
    for (int j = 0; j < segments; ++j) {
      const std::uint32_t a0 = base + 2 * j, b0 = a0 + 1, a1 = a0 + 2, b1 = a0 + 3;
      add_triangle(p, a0, a1, b0);
      add_triangle(p, a1, b1, b0);
    }
  }
  return one_colour(std::move(p), rgba, "revolved profile");
}

assets::Model bent_tube(double radius_m, double bend_radius_m, double angle_rad, const std::array<float, 4>& rgba) {
  const int rings = 40, around = 32;
  assets::Primitive p;
  const auto frame = [&](int i, double& rho, Eigen::Vector3d& centre, Eigen::Vector3d& tangent, Eigen::Vector3d& side) {
    const double u = static_cast<double>(i) / rings - 0.5, theta = angle_rad * u;
    rho = radius_m * (0.55 + 0.45 * std::cos(M_PI * u));
    centre = {bend_radius_m * std::sin(theta), bend_radius_m * (1.0 - std::cos(theta)), 0.0};
    tangent = {std::cos(theta), std::sin(theta), 0.0};
    side = {-std::sin(theta), std::cos(theta), 0.0};
  };
  for (int i = 0; i <= rings; ++i) {
    double rho = 0.0;
    Eigen::Vector3d c, t, side;
    frame(i, rho, c, t, side);
    for (int j = 0; j <= around; ++j) {
      const double alpha = 2.0 * M_PI * j / around;
      const Eigen::Vector3d n = std::cos(alpha) * side + std::sin(alpha) * Eigen::Vector3d::UnitZ();
      p.vertices.push_back(vertex(c + rho * n, n));
    }
  }
  const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(i * (around + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < around; ++j) {
      add_triangle(p, at(i, j), at(i, j + 1), at(i + 1, j));
      add_triangle(p, at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
    }
  for (const int end : {0, rings}) {  // flat caps, facing along the tube
    double rho = 0.0;
    Eigen::Vector3d c, t, side;
    frame(end, rho, c, t, side);
    const Eigen::Vector3d out = end == 0 ? Eigen::Vector3d(-t) : t;
    const auto centre = static_cast<std::uint32_t>(p.vertices.size());
    p.vertices.push_back(vertex(c, out));
    for (int j = 0; j <= around; ++j)
      p.vertices.push_back(vertex(
          c + rho * (std::cos(2.0 * M_PI * j / around) * side + std::sin(2.0 * M_PI * j / around) * Eigen::Vector3d::UnitZ()),
          out));
    for (int j = 0; j < around; ++j) {
      const std::uint32_t a = centre + 1 + j, b = a + 1;
      if (end == 0)
        add_triangle(p, centre, b, a);
      else
        add_triangle(p, centre, a, b);
    }
  }
  return one_colour(std::move(p), rgba, "bent tube");
}

std::vector<ProceduralShape> procedural_shapes() {
  std::vector<ProceduralShape> out;
  out.push_back({"bowl", revolve(bowl_profile(), 72, {0.85F, 0.85F, 0.80F, 1.0F}), Eigen::Vector3d::UnitZ()});
  out.push_back({"cup", revolve(walled(0.040, 0.095, 0.003, 0.006), 64, {0.20F, 0.35F, 0.70F, 1.0F}), Eigen::Vector3d::UnitZ()});
  out.push_back({"plate",
                 revolve({{0.0, 0.0}, {0.075, 0.0}, {0.120, 0.016}, {0.119, 0.019}, {0.074, 0.003}, {0.0, 0.003}}, 96,
                         {0.95F, 0.95F, 0.95F, 1.0F}),
                 Eigen::Vector3d::UnitZ()});
  // A cylinder made along x: its turns are about x.
  assets::Model cylinder = revolve({{0.0, 0.0}, {0.033, 0.0}, {0.033, 0.120}, {0.0, 0.120}}, 64, {0.70F, 0.20F, 0.15F, 1.0F});
  for (auto& v : cylinder.primitives.front().vertices) {
    const std::array<float, 3> p = v.position, n = v.normal;
    v.position = {p[2] - 0.060F, p[1], -p[0]};
    v.normal = {n[2], n[1], -n[0]};
  }
  out.push_back({"lying cylinder", std::move(cylinder), Eigen::Vector3d::UnitX()});
  out.push_back({"bent tube", bent_tube(0.018, 0.150, config::radians(70.0), {0.90F, 0.80F, 0.20F, 1.0F}), std::nullopt});
  for (auto& s : out) s.model.source = s.name + " (procedural)";
  return out;
}

}  // namespace projbot::twin
