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
  // dropped before they are moved (the free-space check runs this on every tracked frame). In the
  // samples' own float: its rounding (micrometres) moves a sample only where it lies on a pixel's border
  // (one estimate of the shared frames' 260 moved, through colour's placing).
  const Eigen::Vector3f eye = (-R.transpose() * t).cast<float>();
  const Eigen::Matrix3f Rf = R.cast<float>();
  const Eigen::Vector3f tf = t.cast<float>();
  for (std::size_t i = 0; i < model.points.size(); ++i) {
    const Eigen::Vector3f& m = model.points[i];
    if (model.normals[i].dot(m - eye) >= 0.0F) continue;  // a back face
    const Eigen::Vector3f p = Rf * m + tf;
    if (!(p.z() > 0.05F)) continue;  // behind the camera
    int u = 0, v = 0;
    if (!k.nearest_pixel(p.cast<double>(), u, v)) continue;
    f(p.z(), u, v, i);
  }
}

// The nearest front-facing model sample per pixel under T_camera_model: (depth, sample index), +inf
// where none lands.
std::vector<std::pair<float, std::size_t>> nearest_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model,
                                                           const CameraIntrinsics& k);

}  // namespace projbot::alignment::detail
