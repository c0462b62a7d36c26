#pragma once
// Depth input: images from files, point clouds from PCD / PLY, and depth -> organised cloud through the
// camera intrinsics. Plain types only; PCL stays inside src/.

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "projbot/config/pinhole.hpp"

namespace projbot::alignment {

/// A bad depth file, cloud or request: the message names the file and what is wrong.
class AlignmentError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A depth camera's intrinsics: the one pinhole type (config::Pinhole), Kinect v1 by default.
using CameraIntrinsics = config::Pinhole;

/// A depth image in metres, row-major, top row first; 0 or NaN marks a missing measurement.
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<float> depth_m;
  double capture_time_s = 0.0;  ///< when the frame was taken (steady clock or recording time)

  float at(int x, int y) const { return depth_m[static_cast<std::size_t>(y) * width + x]; }
};

/// Whether a depth image's pixel holds a measurement: positive and finite (0, NaN, negative or
/// infinite: missing).
inline bool has_depth(float z) { return z > 0.0F && std::isfinite(z); }

/// Points in the camera frame, metres. Organised when height > 1: one point per pixel, NaN where the
/// pixel had no valid depth (like PCL's organised clouds). Unorganised: height 1, all finite.
struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  int width = 0;
  int height = 0;

  bool organised() const { return height > 1; }
  std::size_t finite_count() const;
};

/// Reads a 16-bit PNG depth image; `units_per_metre` converts its values (1000 for mm, 5000 for TUM).
DepthImage read_depth_png(const std::filesystem::path& path, double units_per_metre);

/// Reads a 16-bit TIFF depth image (PCL's image grabber format); `metres_per_unit` converts its values
/// (PCL's `z_multiplication_factor`, 0.001 for mm).
DepthImage read_depth_tiff(const std::filesystem::path& path, double metres_per_unit);

/// Reads the depth intrinsics and z factor from a PCL grabber XML file (<depth><focal_length_x>...).
struct GrabberCalibration {
  CameraIntrinsics intrinsics;
  double metres_per_unit = 0.001;
};
GrabberCalibration read_pcl_grabber_xml(const std::filesystem::path& path, int width_px, int height_px);

/// Back-projects a depth image: pixel (i, j) with depth z becomes ((i - cx) z / fx, (j - cy) z / fy, z).
/// Zero, NaN and out-of-range (< min_m or > max_m) pixels become NaN points; zero is never valid. The
/// result is organised.
PointCloud depth_to_cloud(const DepthImage& depth, const CameraIntrinsics& k, double min_m = 0.3, double max_m = 8.0);

/// A known plane in the camera frame, n . p + d = 0 with |n| = 1 and n pointing up (away from what lies
/// under it): the floor, from the map and the camera's pose.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double d = 0.0;
  double height_of(const Eigen::Vector3d& p) const { return normal.dot(p) + d; }
};

/// The floor (z = 0 in the map) in the frame of a camera at T_world_camera.
Plane floor_in_camera(const Eigen::Matrix4d& T_world_camera);

/// The depth image without the pixels whose points lie within margin_m above `plane`, or below it
/// (set to 0, missing): the floor a figure stands on, which would otherwise count against its gate.
DepthImage without_plane(const DepthImage& depth, const CameraIntrinsics& k, const Plane& plane, double margin_m);

/// Reads a PCD or PLY file (by extension) as x, y, z; keeps the organisation of organised PCDs.
PointCloud read_cloud(const std::filesystem::path& path);

/// Drops non-finite points: the result is unorganised.
PointCloud finite_points(const PointCloud& cloud);

}  // namespace projbot::alignment
