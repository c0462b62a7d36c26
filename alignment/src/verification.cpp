#include "projbot/alignment/verification.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace projbot::alignment {

namespace {

// The nearest front-facing model sample per pixel under T_camera_model: (depth, sample index), +inf
// where none lands.
std::vector<std::pair<float, std::size_t>> nearest_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model,
                                                           const CameraIntrinsics& k) {
  std::vector<std::pair<float, std::size_t>> nearest(static_cast<std::size_t>(k.width_px) * k.height_px,
                                                     {std::numeric_limits<float>::infinity(), 0});
  const Eigen::Matrix3d R = T_camera_model.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_camera_model.topRightCorner<3, 1>();
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    const Eigen::Vector3d p = R * model.points[i].cast<double>() + t;
    if (!(p.z() > 0.05) || (R * model.normals[i].cast<double>()).dot(p) >= 0.0) continue;  // behind the camera, or a back face
    int u = 0, v = 0;
    if (!k.nearest_pixel(p, u, v)) continue;
    auto& best = nearest[static_cast<std::size_t>(v) * k.width_px + u];
    if (p.z() < best.first) best = {static_cast<float>(p.z()), i};
  }
  return nearest;
}

// The predicted depth image: nearest front-facing model sample per pixel, +inf where none lands; `box`
// gets the pixel bounds of what landed (x0, y0, x1, y1, inclusive).
std::vector<float> predicted_depth(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k,
                                   std::array<int, 4>& box) {
  box = {k.width_px, k.height_px, -1, -1};
  const auto nearest = nearest_samples(model, T_camera_model, k);
  std::vector<float> z_buffer(nearest.size());
  for (std::size_t i = 0; i < nearest.size(); ++i) {
    z_buffer[i] = nearest[i].first;
    if (!std::isfinite(z_buffer[i])) continue;
    const int u = static_cast<int>(i % k.width_px), v = static_cast<int>(i / k.width_px);
    box = {std::min(box[0], u), std::min(box[1], v), std::max(box[2], u), std::max(box[3], v)};
  }
  return z_buffer;
}

}  // namespace

DepthImage crop_to_silhouette(const DepthImage& depth, const CameraIntrinsics& k, const ModelCloud& model,
                              const Eigen::Matrix4d& T_camera_model, double grow_m) {
  DepthImage out = depth;
  if (depth.width != k.width_px || depth.height != k.height_px || !T_camera_model.allFinite()) return out;
  std::array<int, 4> box{};
  const std::vector<float> predicted = predicted_depth(model, T_camera_model, k, box);
  if (box[2] < 0) {  // nothing of the model in view: nothing to keep
    std::fill(out.depth_m.begin(), out.depth_m.end(), 0.0F);
    return out;
  }
  float z_near = std::numeric_limits<float>::infinity(), z_far = 0.0F;
  for (const float z : predicted)
    if (std::isfinite(z)) z_near = std::min(z_near, z), z_far = std::max(z_far, z);
  // Grown by grow_m at the model's nearest depth, in pixels; then a box dilation, rows then columns.
  const int r = static_cast<int>(std::ceil(grow_m * std::max(k.fx_px, k.fy_px) / std::max(z_near, 0.1F))) + 1;
  const int w = k.width_px, h = k.height_px;
  std::vector<unsigned char> rows(predicted.size(), 0), mask(predicted.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::isfinite(predicted[static_cast<std::size_t>(y) * w + x]))
        for (int dx = std::max(0, x - r); dx <= std::min(w - 1, x + r); ++dx) rows[static_cast<std::size_t>(y) * w + dx] = 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (rows[static_cast<std::size_t>(y) * w + x])
        for (int dy = std::max(0, y - r); dy <= std::min(h - 1, y + r); ++dy) mask[static_cast<std::size_t>(dy) * w + x] = 1;
  const auto lo = static_cast<float>(z_near - grow_m), hi = static_cast<float>(z_far + grow_m);
  for (std::size_t i = 0; i < out.depth_m.size(); ++i)
    if (!mask[i] || !(out.depth_m[i] >= lo && out.depth_m[i] <= hi)) out.depth_m[i] = 0.0F;
  return out;
}

double guess_reach_m(const ModelCloud& model, double translation_m, double rotation_deg) {
  double radius = 0.0;
  for (const auto& p : model.points) radius = std::max(radius, static_cast<double>(p.norm()));
  return translation_m + 2.0 * std::sin(std::min(rotation_deg, 180.0) * M_PI / 360.0) * radius;
}

FreeSpaceCheck check_free_space(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const CameraIntrinsics& k) {
  FreeSpaceCheck c;
  if (depth.width != k.width_px || depth.height != k.height_px || !T_camera_model.allFinite()) return c;
  std::array<int, 4> box{};
  const std::vector<float> predicted = predicted_depth(model, T_camera_model, k, box);
  const auto at = [&](int x, int y) { return predicted[static_cast<std::size_t>(y) * k.width_px + x]; };
  constexpr int kRim = 2;  // pixels of the silhouette's rim left out
  const int x0 = std::max(box[0], kRim), x1 = std::min(box[2], k.width_px - 1 - kRim);
  const int y0 = std::max(box[1], kRim), y1 = std::min(box[3], k.height_px - 1 - kRim);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const float z = at(x, y);
      if (!std::isfinite(z)) continue;
      // Interior only: the model covers the pixels kRim away on each side (sparse samples leave holes,
      // so a neighbour counts when any pixel near it is covered).
      bool interior = true;
      for (const auto& [dx, dy] : {std::pair{-kRim, 0}, {kRim, 0}, {0, -kRim}, {0, kRim}})
        interior = interior && (std::isfinite(at(x + dx, y + dy)) || std::isfinite(at(x + dx / 2, y + dy / 2)));
      if (!interior) continue;
      const float measured = depth.at(x, y);
      if (!(measured > 0.0F) || !std::isfinite(measured)) continue;
      ++c.predicted;
      const float tolerance = 0.015F + 0.005F * z * z;
      if (measured > z + tolerance)
        ++c.behind;
      else if (measured < z - tolerance)
        ++c.in_front;
    }
  return c;
}

ViewConstraints view_constraints(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k) {
  ViewConstraints c;
  if (!T_camera_model.allFinite() || model.normals.size() != model.points.size()) return c;
  // The nearest front-facing sample per pixel: what one scan can measure, one point per pixel (a face
  // seen at a grazing angle has many samples but few pixels).
  const Eigen::Matrix3d R = T_camera_model.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_camera_model.topRightCorner<3, 1>();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> seen;  // point, normal (camera frame)
  for (const auto& [z, i] : nearest_samples(model, T_camera_model, k))
    if (std::isfinite(z))
      seen.emplace_back(R * model.points[i].cast<double>() + t, (R * model.normals[i].cast<double>()).normalized());
  c.points = seen.size();
  if (seen.size() < 6) return c;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& [p, n] : seen) centre += p;
  centre /= static_cast<double>(seen.size());
  double r2 = 0.0;
  for (const auto& [p, n] : seen) r2 += (p - centre).squaredNorm();
  const double radius = std::max(std::sqrt(r2 / static_cast<double>(seen.size())), 1e-3);
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& [p, n] : seen) {
    Eigen::Matrix<double, 6, 1> J;
    J << n, (p - centre).cross(n) / radius;
    H += J * J.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H);
  const double largest = std::max(eig.eigenvalues()(5), 1e-12);
  for (int i = 0; i < 6; ++i) {
    c.strength[static_cast<std::size_t>(i)] = eig.eigenvalues()(i) / largest;
    if (c.strength[static_cast<std::size_t>(i)] >= ViewConstraints::kWeak) continue;
    const Eigen::Matrix<double, 6, 1> d = eig.eigenvectors().col(i);
    c.weak.push_back({d.head<3>(), d.tail<3>(), c.strength[static_cast<std::size_t>(i)]});
  }
  return c;
}

}  // namespace projbot::alignment
