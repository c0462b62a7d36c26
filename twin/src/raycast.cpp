#include "projbot/twin/raycast.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "projbot/config/angles.hpp"
#include "projbot/config/stop_request.hpp"
#include "projbot/engine/projection.hpp"

namespace projbot::twin {

MeshRaycaster::MeshRaycaster(const assets::Model& model) {
  std::size_t n = 0;
  for (const auto& p : model.primitives) {
    for (std::size_t i = 0; i + 2 < p.indices.size(); i += 3) {
      if (n % config::kStopCheckEvery == 0)
        config::stop_if_requested("preparing a model of " + std::to_string(p.indices.size() / 3) +
                                  " triangles for the twin's ray-caster");
      const auto v = [&](std::size_t k) {
        const auto& q = p.vertices[p.indices[i + k]].position;
        return Eigen::Vector3d(q[0], q[1], q[2]);
      };
      a_.push_back(v(0));
      e1_.push_back(v(1) - v(0));
      e2_.push_back(v(2) - v(0));
      centre_ += v(0);
      ++n;
    }
  }
  if (n > 0) centre_ /= static_cast<double>(n);
  for (std::size_t i = 0; i < a_.size(); ++i)
    for (const Eigen::Vector3d& c : {a_[i], Eigen::Vector3d(a_[i] + e1_[i]), Eigen::Vector3d(a_[i] + e2_[i])})
      radius_ = std::max(radius_, (c - centre_).norm());
  order_.resize(a_.size());
  for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
  if (!a_.empty()) build(0, static_cast<std::uint32_t>(a_.size()));
}

// The node over order_[first, first + count): a leaf of at most 8 triangles, else split at the median of
// their centroids along the widest axis. Boxes are padded so that rounding never hides a hit on their faces.
std::int32_t MeshRaycaster::build(std::uint32_t first, std::uint32_t count) {
  if (count >= config::kStopCheckEvery)
    config::stop_if_requested("building the twin's ray-caster over a model of " + std::to_string(a_.size()) + " triangles");
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  Eigen::Vector3d clo = lo, chi = hi;
  for (std::uint32_t k = first; k < first + count; ++k) {
    const std::uint32_t i = order_[k];
    for (const Eigen::Vector3d& c : {a_[i], Eigen::Vector3d(a_[i] + e1_[i]), Eigen::Vector3d(a_[i] + e2_[i])})
      lo = lo.cwiseMin(c), hi = hi.cwiseMax(c);
    const Eigen::Vector3d centroid = a_[i] + (e1_[i] + e2_[i]) / 3.0;
    clo = clo.cwiseMin(centroid), chi = chi.cwiseMax(centroid);
  }
  const double pad = 1e-6 * (1.0 + (hi - lo).maxCoeff());
  nodes_[static_cast<std::size_t>(index)].lo = lo.array() - pad;
  nodes_[static_cast<std::size_t>(index)].hi = hi.array() + pad;
  if (count <= 8) {
    nodes_[static_cast<std::size_t>(index)].first = first;
    nodes_[static_cast<std::size_t>(index)].count = count;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const auto centroid = [&](std::uint32_t i) { return (a_[i] + (e1_[i] + e2_[i]) / 3.0)[axis]; };
  const auto begin = order_.begin() + first, mid = begin + count / 2, end = begin + count;
  std::nth_element(begin, mid, end, [&](std::uint32_t x, std::uint32_t y) { return centroid(x) < centroid(y); });
  const std::int32_t left = build(first, count / 2);
  const std::int32_t right = build(first + count / 2, count - count / 2);
  nodes_[static_cast<std::size_t>(index)].left = left;
  nodes_[static_cast<std::size_t>(index)].right = right;
  return index;
}

// Moeller-Trumbore: the distance along the ray to triangle i, front or back face.
std::optional<double> MeshRaycaster::hit(std::size_t i, const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  const Eigen::Vector3d p = d.cross(e2_[i]);
  const double det = e1_[i].dot(p);
  if (std::abs(det) < 1e-15) return std::nullopt;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = o - a_[i];
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return std::nullopt;
  const Eigen::Vector3d q = s.cross(e1_[i]);
  const double v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return std::nullopt;
  const double t = e2_[i].dot(q) * inv;
  if (!(t > 1e-9)) return std::nullopt;
  return t;
}

std::optional<double> MeshRaycaster::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  // Skip the mesh when the ray passes outside its bounding sphere.
  const Eigen::Vector3d oc = centre_ - o;
  const double along = oc.dot(d);
  if (nodes_.empty() || (oc - along * d).squaredNorm() > radius_ * radius_ || along < -radius_) return std::nullopt;
  const Eigen::Vector3d inv = d.cwiseInverse();  // +-inf along an axis the ray does not move on
  double best = std::numeric_limits<double>::infinity();
  std::array<std::int32_t, 64> stack{0};
  std::size_t depth = 1;
  while (depth > 0) {
    const Node& n = nodes_[static_cast<std::size_t>(stack[--depth])];
    // The slab test: where the ray is inside the box along every axis (nothing when it never is).
    double enter = 0.0, leave = best;
    for (int a = 0; a < 3 && enter <= leave; ++a) {
      if (d[a] == 0.0) {
        if (o[a] < n.lo[a] || o[a] > n.hi[a]) leave = -1.0;
        continue;
      }
      const double t0 = (n.lo[a] - o[a]) * inv[a], t1 = (n.hi[a] - o[a]) * inv[a];
      enter = std::max(enter, std::min(t0, t1));
      leave = std::min(leave, std::max(t0, t1));
    }
    if (enter > leave) continue;
    if (n.left < 0) {
      for (std::uint32_t k = n.first; k < n.first + n.count; ++k)
        if (const auto t = hit(order_[k], o, d); t && *t < best) best = *t;
      continue;
    }
    stack[depth++] = n.left;
    stack[depth++] = n.right;
  }
  if (!std::isfinite(best)) return std::nullopt;
  return best;
}

Eigen::Vector3d MeshRaycaster::closest_point(const Eigen::Vector3d& x) const {
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d best_point = x;
  const auto consider = [&](const Eigen::Vector3d& q) {
    const double d = (x - q).norm();
    if (d < best) best = d, best_point = q;
  };
  for (std::size_t i = 0; i < a_.size(); ++i) {
    // Closest point on the triangle: inside the face, else on one of its edges.
    const Eigen::Vector3d n = e1_[i].cross(e2_[i]);
    const double area2 = n.squaredNorm();
    if (area2 < 1e-24) continue;
    const Eigen::Vector3d w = x - a_[i];
    const Eigen::Vector3d on_plane = x - n * (w.dot(n) / area2);
    const Eigen::Vector3d r = on_plane - a_[i];
    // Barycentric coordinates of on_plane.
    const double d00 = e1_[i].dot(e1_[i]), d01 = e1_[i].dot(e2_[i]), d11 = e2_[i].dot(e2_[i]);
    const double d20 = r.dot(e1_[i]), d21 = r.dot(e2_[i]);
    const double den = d00 * d11 - d01 * d01;
    const double v = (d11 * d20 - d01 * d21) / den, w2 = (d00 * d21 - d01 * d20) / den;
    if (v >= 0.0 && w2 >= 0.0 && v + w2 <= 1.0) {
      consider(on_plane);
      continue;
    }
    const auto segment = [&](const Eigen::Vector3d& p0, const Eigen::Vector3d& p1) {
      const Eigen::Vector3d e = p1 - p0;
      const double t = std::clamp((x - p0).dot(e) / e.squaredNorm(), 0.0, 1.0);
      consider(p0 + t * e);
    };
    const Eigen::Vector3d b = a_[i] + e1_[i], c = a_[i] + e2_[i];
    segment(a_[i], b), segment(b, c), segment(c, a_[i]);
  }
  return best_point;
}

std::optional<Eigen::Vector3d> cast_ray(std::span<const PlacedMesh> scene, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& direction) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& placed : scene) {
    // Into the model frame; rigid, so distances along the ray are kept.
    const Eigen::Matrix3d R = placed.T_frame_model.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = placed.T_frame_model.topRightCorner<3, 1>();
    const auto hit = placed.mesh->cast(R.transpose() * (origin - t), R.transpose() * direction);
    if (hit && *hit < best) best = *hit;
  }
  if (!std::isfinite(best)) return std::nullopt;
  return Eigen::Vector3d(origin + best * direction);
}

MarkerError measure_marker(const config::ProjectorConfig& k, const config::ProjectorConfig& light, const Eigen::Matrix4d& T_est,
                           const Eigen::Matrix4d& T_true, const Eigen::Vector3d& marker_m,
                           std::span<const PlacedMesh> true_scene) {
  MarkerError e;
  e.marker_m = marker_m;
  const Eigen::Vector3d truth = (T_true * marker_m.homogeneous()).head<3>();
  const Eigen::Vector3d drawn = (T_est * marker_m.homogeneous()).head<3>();
  // Eq. 3: x = A_p X through the believed lens, the content's pixel, then the centre of the pixel that shows it.
  Eigen::Vector3d ray = drawn;
  if (drawn.z() > 0.0) {
    e.pixel = k.project_lit(drawn).array().round();
    e.in_image = k.contains(e.pixel);
    if (const auto r = light.panel_ray(e.pixel.x(), e.pixel.y()))
      ray = *r;
    else
      e.in_image = false;  // a lens validate_projector refuses; measured as the distance to the drawn ray
  }
  const Eigen::Vector3d d = ray.normalized();
  if (e.in_image) {
    if (const auto hit = cast_ray(true_scene, Eigen::Vector3d::Zero(), d)) {
      e.landed = true;
      e.error_mm = 1000.0 * (*hit - truth).norm();
      return e;
    }
  }
  e.error_mm = 1000.0 * (truth - truth.dot(d) * d).norm();
  return e;
}

bool seen_edge_on(std::span<const PlacedMesh> scene, const Eigen::Vector3d& p) {
  // Four rays 3 mm beside the one to p: each must land within 3 cm of p (else it went past an edge),
  // and the surface they span must face the origin within kEdgeOnDeg.
  constexpr double kStep = 0.003;
  const Eigen::Vector3d d = p.normalized(), a = d.unitOrthogonal(), b = d.cross(a);
  const std::array<Eigen::Vector3d, 4> offsets{kStep * a, -kStep * a, kStep * b, -kStep * b};
  std::array<Eigen::Vector3d, 4> hits;
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const auto hit = cast_ray(scene, Eigen::Vector3d::Zero(), (p + offsets[i]).normalized());
    if (!hit || (*hit - p).norm() > 10.0 * kStep) return true;
    hits[i] = *hit;
  }
  const Eigen::Vector3d n = (hits[0] - hits[1]).cross(hits[2] - hits[3]);
  return !(std::abs(n.normalized().dot(d)) >= std::cos(config::radians(kEdgeOnDeg)));
}

}  // namespace projbot::twin
