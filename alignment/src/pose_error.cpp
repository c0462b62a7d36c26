#include "projbot/alignment/pose_error.hpp"

#include <Eigen/Geometry>
#include <limits>

#include "projbot/alignment/nearest_points.hpp"

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
  std::vector<Eigen::Vector3f> truth_f;
  truth_f.reserve(truth.size());
  for (const auto& p : truth) truth_f.push_back(p.cast<float>());
  const NearestPoints nearest(truth_f);  // found in float, the distance taken again in double
  double sum = 0.0;
  for (const auto& p : est) {
    const std::size_t i = nearest.nearest(p.cast<float>(), truth.size());
    if (i >= truth.size()) return std::numeric_limits<double>::infinity();
    sum += (truth[i] - p).norm();
  }
  return sum / static_cast<double>(est.size());
}

}  // namespace projbot::alignment
