#include "projbot/alignment/pose_error.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace projbot::alignment {
namespace {

std::vector<Eigen::Vector3d> moved(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Matrix4d& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(vertices.size());
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  for (const auto& v : vertices) out.push_back(R * v.cast<double>() + t);
  return out;
}

// Nearest-neighbour distances by a uniform grid: each query searches outward ring by ring until the ring's
// nearest possible distance exceeds the best found.
class Grid {
 public:
  Grid(const std::vector<Eigen::Vector3d>& points, double cell) : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(index(points[i]))].push_back(i), box_.extend(points[i]);
  }
  double nearest(const Eigen::Vector3d& q) const {
    double best = std::numeric_limits<double>::infinity();
    if (box_.exteriorDistance(q) > 3.0 * cell_) {  // far outside (a gross error): every point, no rings
      for (const auto& p : points_) best = std::min(best, (p - q).norm());
      return best;
    }
    const Eigen::Vector3i c = index(q);
    const int rings = 2 + static_cast<int>(box_.sizes().maxCoeff() / cell_);
    for (int ring = 0; ring <= rings; ++ring) {
      if (std::isfinite(best) && (ring - 1) * cell_ > best) break;
      for (int x = -ring; x <= ring; ++x)
        for (int y = -ring; y <= ring; ++y)
          for (int z = -ring; z <= ring; ++z) {
            if (std::max({std::abs(x), std::abs(y), std::abs(z)}) != ring) continue;
            const auto it = cells_.find(key(c + Eigen::Vector3i(x, y, z)));
            if (it == cells_.end()) continue;
            for (std::size_t i : it->second) best = std::min(best, (points_[i] - q).norm());
          }
    }
    return best;
  }

 private:
  Eigen::Vector3i index(const Eigen::Vector3d& p) const { return (p / cell_).array().floor().cast<int>(); }
  static long long key(const Eigen::Vector3i& i) {
    return (static_cast<long long>(i.x() & 0x1FFFFF) << 42) | (static_cast<long long>(i.y() & 0x1FFFFF) << 21) |
           (i.z() & 0x1FFFFF);
  }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  Eigen::AlignedBox3d box_;
  std::unordered_map<long long, std::vector<std::size_t>> cells_;
};

}  // namespace

double add_error_m(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Matrix4d& T_est, const Eigen::Matrix4d& T_true) {
  if (vertices.empty()) return 0.0;
  const Eigen::Matrix4d d = T_est - T_true;
  double sum = 0.0;
  for (const auto& v : vertices) sum += (d * v.cast<double>().homogeneous()).head<3>().norm();
  return sum / static_cast<double>(vertices.size());
}

double adds_error_m(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Matrix4d& T_est, const Eigen::Matrix4d& T_true) {
  if (vertices.empty()) return 0.0;
  const std::vector<Eigen::Vector3d> truth = moved(vertices, T_true), est = moved(vertices, T_est);
  Eigen::AlignedBox3d box;
  for (const auto& p : truth) box.extend(p);
  // About 8 points a cell on a surface: the cell edge from the box's area over the vertex count.
  const Eigen::Vector3d size = box.sizes();
  const double area = 2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  const double cell = std::max(1e-4, std::sqrt(8.0 * area / static_cast<double>(truth.size())));
  const Grid grid(truth, cell);
  double sum = 0.0;
  for (const auto& p : est) sum += grid.nearest(p);
  return sum / static_cast<double>(est.size());
}

}  // namespace projbot::alignment
