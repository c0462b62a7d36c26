#pragma once
// The one pinhole camera type (issue 12): the projector's intrinsics A_p, the depth camera's and the
// colour camera's registered to it. OpenCV convention: x right, y down, z forward; a point (X, Y, Z) in
// the camera frame lands at u = fx X/Z + cx, v = fy Y/Z + cy, and pixel (i, j) has its centre at u = i,
// v = j (Eq. 3 of the paper, x = A_p X). A camera with its lens and clip range is config::Camera
// (lens.hpp); the projector's (ProjectorConfig, scene.hpp) is one.

#include <Eigen/Core>
#include <cmath>

namespace projbot::config {

struct Pinhole {
  int width_px = 640;    ///< image width, pixels (> 0)
  int height_px = 480;   ///< image height, pixels (> 0)
  double fx_px = 525.0;  ///< focal length along x, pixels (> 0)
  double fy_px = 525.0;  ///< focal length along y, pixels (> 0)
  double cx_px = 319.5;  ///< principal point x, pixels
  double cy_px = 239.5;  ///< principal point y, pixels

  /// Kinect v1 / PrimeSense depth camera defaults: 640x480, f = 525 px, principal point at the image
  /// centre (the TUM RGB-D and Open3D defaults; PCL's OpenNI grabber reports cx 320, cy 240).
  static Pinhole kinect_v1() { return {}; }

  /// Where camera-frame point p (z > 0) lands in the image, pixels.
  Eigen::Vector2d project(const Eigen::Vector3d& p) const {
    return {fx_px * p.x() / p.z() + cx_px, fy_px * p.y() / p.z() + cy_px};
  }
  /// The camera-frame point at depth z (along the optical axis) seen at pixel position (u, v).
  Eigen::Vector3d back_project(double u, double v, double z) const {
    return {(u - cx_px) * z / fx_px, (v - cy_px) * z / fy_px, z};
  }
  /// Whether pixel position x lies on the image (pixel centres at integers: -0.5 .. width - 0.5 is
  /// covered, this asks for 0 .. width, the convention the callers use).
  bool contains(const Eigen::Vector2d& x) const { return x.x() >= 0.0 && x.y() >= 0.0 && x.x() < width_px && x.y() < height_px; }
  /// The pixel whose centre is nearest to where camera-frame point p (z > 0) projects; false when it
  /// falls outside the image.
  /// (Rounds as std::lround does, half away from zero, without its library call: this runs for every
  /// model point of every tracked frame.)
  bool nearest_pixel(const Eigen::Vector3d& p, int& u, int& v) const {
    const Eigen::Vector2d x = project(p);
    if (!(x.x() > -0.5 && x.y() > -0.5 && x.x() < width_px - 0.5 && x.y() < height_px - 0.5)) return false;  // NaN too
    u = static_cast<int>(x.x() + 0.5);  // non-negative here, so truncation rounds
    v = static_cast<int>(x.y() + 0.5);
    return true;
  }
};

}  // namespace projbot::config
