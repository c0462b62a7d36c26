#pragma once
// Internal to alignment: a model's front-facing samples as a camera sees them at a pose (the free-space
// check and colour's placing both start from them).

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace projbot::alignment::detail {

// Calls f(z, u, v, sample index) for each front-facing model sample under T_camera_model that
// lands in the image.
template <class F>
void for_each_front_sample(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k, F&& f) {
  const Eigen::Matrix3d R = T_camera_model.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_camera_model.topRightCorner<3, 1>();
  // A back face is told in the model's frame, from the camera's centre there: half the samples are
  // dropped before they are moved (the free-space check runs this on every tracked frame).
  const Eigen::Vector3d eye = -R.transpose() * t;
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    const Eigen::Vector3d m = model.points[i].cast<double>();
    if (model.normals[i].cast<double>().dot(m - eye) >= 0.0) continue;  // a back face
    const Eigen::Vector3d p = R * m + t;
    if (!(p.z() > 0.05)) continue;  // behind the camera
    int u = 0, v = 0;
    if (!k.nearest_pixel(p, u, v)) continue;
    f(static_cast<float>(p.z()), u, v, i);
  }
}

// The nearest front-facing model sample per pixel under T_camera_model: (depth, sample index), +inf
// where none lands.
std::vector<std::pair<float, std::size_t>> nearest_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model,
                                                           const CameraIntrinsics& k);

}  // namespace projbot::alignment::detail
