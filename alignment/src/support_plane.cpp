// The support a target rests on, found in the frame (no map): PCL's RANSAC plane segmentation. Its own
// translation unit, the only one with pcl/segmentation.

#include <pcl/ModelCoefficients.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/sac_model_plane.h>
#include <pcl/segmentation/sac_segmentation.h>

#include <cmath>
#include <limits>
#include <optional>

#include "projbot/alignment/registration.hpp"

namespace projbot::alignment {
namespace {

constexpr double kPlaneDistanceM = 0.008;     // RANSAC inlier band: a Kinect's table at 1 m is +-3 mm (2 sigma)
constexpr int kStride = 3;                    // the search's pixels: every third of every third row
constexpr std::size_t kMinPlanePoints = 133;  // 1200 pixels' worth
constexpr int kMaxPlanes = 6;  // rejected planes (the target's own faces, a wall) are removed and the search goes on
constexpr double kMinCentreAboveM = 0.005;
// The search reaches this far past the model's sphere at the guess: within the sphere alone the mug's
// table was hidden behind the mug and its neighbours (the planes found were their faces). (Searching
// the sphere first and wider only where nothing qualified found planes that were not the mug's table:
// 75 % instead of 82 % within 10 mm on the two cluttered scenes; the pudding box leaning on the wood
// block, found in the sphere, is lost with the wider search in the first frame of --track.)
constexpr double kBeyondSphereM = 0.10;

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// The frame's points within `radius` of `centre`: on every kStride-th pixel for the search (RANSAC's
// cost follows the points), and on every other pixel to fit the plane found (as precise as before the
// search thinned: on every other pixel both, the marker tracked through the 20-image scene stayed lit;
// with the plane fitted on every third, lost its last 4 images).
struct Near {
  Cloud::Ptr sparse = pcl::make_shared<Cloud>();
  Cloud::Ptr dense = pcl::make_shared<Cloud>();
};

Near points_near(const DepthImage& depth, const CameraIntrinsics& k, const Eigen::Vector3d& centre, double radius) {
  Near near;
  const PointCloud all = depth_to_cloud(depth, k);
  const Eigen::Vector3f c = centre.cast<float>();
  const auto r2 = static_cast<float>(radius * radius);
  for (int y = 0; y < all.height; ++y) {
    if (y % kStride != 0 && y % 2 != 0) continue;
    for (int x = 0; x < all.width; ++x) {
      const bool sparse = x % kStride == 0 && y % kStride == 0, dense = x % 2 == 0 && y % 2 == 0;
      if (!sparse && !dense) continue;
      const Eigen::Vector3f& p = all.points[static_cast<std::size_t>(y) * all.width + x];
      if (!p.allFinite() || (p - c).squaredNorm() > r2) continue;
      if (sparse) near.sparse->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      if (dense) near.dense->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
    }
  }
  return near;
}

// Coefficients (a, b, c, d) as a Plane with a unit normal and the camera (origin) on its upper side.
std::optional<Plane> plane_of(const Eigen::VectorXf& coefficients) {
  if (coefficients.size() != 4) return std::nullopt;
  Plane plane;
  plane.normal = coefficients.head<3>().cast<double>();
  plane.d = coefficients[3];
  const double norm = plane.normal.norm();
  if (!(norm > 0.0) || !std::isfinite(plane.d)) return std::nullopt;
  plane.normal /= norm, plane.d /= norm;
  if (plane.d < 0.0) plane.normal = -plane.normal, plane.d = -plane.d;
  return plane;
}

// The plane refitted (least squares) to the points of `dense` within the inlier band of `coarse`.
Plane refitted(const Cloud::Ptr& dense, const Plane& coarse) {
  pcl::SampleConsensusModelPlane<pcl::PointXYZ> model(dense);
  const Eigen::Vector4f given(static_cast<float>(coarse.normal.x()), static_cast<float>(coarse.normal.y()),
                              static_cast<float>(coarse.normal.z()), static_cast<float>(coarse.d));
  pcl::Indices inliers;
  model.selectWithinDistance(given, kPlaneDistanceM, inliers);
  if (inliers.size() < 3) return coarse;
  Eigen::VectorXf refined;
  model.optimizeModelCoefficients(inliers, given, refined);
  return plane_of(refined).value_or(coarse);
}

// Whether `plane` is the target's support at the guess: its centre on the plane's camera side and its
// lowest point within reach_m (and the inlier band) of it.
bool supports(const Plane& plane, const ModelCloud& model, const Eigen::Matrix4d& T_camera_guess, const Eigen::Vector3d& centre,
              double reach_m) {
  double lowest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < model.points.size(); i += 7)
    lowest = std::min(lowest, plane.height_of((T_camera_guess * model.points[i].cast<double>().homogeneous()).head<3>()));
  return plane.height_of(centre) >= kMinCentreAboveM && std::abs(lowest) <= reach_m + kPlaneDistanceM;
}

// The support among the planes of `near`: under the target at the guess and touching it (supports), the
// largest such of up to kMaxPlanes.
std::optional<Footing> support_among(const Near& near, const ModelCloud& model, const Eigen::Matrix4d& T_camera_guess,
                                     const Eigen::Vector3d& centre, double reach_m) {
  pcl::SACSegmentation<pcl::PointXYZ> seg;
  seg.setOptimizeCoefficients(true);
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setDistanceThreshold(kPlaneDistanceM);
  seg.setMaxIterations(300);
  Cloud::Ptr cloud = near.sparse;
  for (int attempt = 0; attempt < kMaxPlanes && cloud->size() >= kMinPlanePoints; ++attempt) {
    pcl::ModelCoefficients coefficients;
    pcl::PointIndices::Ptr inliers = pcl::make_shared<pcl::PointIndices>();
    seg.setInputCloud(cloud);
    seg.segment(*inliers, coefficients);
    if (inliers->indices.size() < kMinPlanePoints) break;
    const std::optional<Plane> plane = plane_of(
        Eigen::Map<const Eigen::VectorXf>(coefficients.values.data(), static_cast<Eigen::Index>(coefficients.values.size())));
    if (!plane) break;
    if (supports(*plane, model, T_camera_guess, centre, reach_m)) {
      Footing f;
      f.floor = refitted(near.dense, *plane);
      f.height_m = 0.0;
      f.upright_known = false;
      return f;
    }
    pcl::ExtractIndices<pcl::PointXYZ> extract;  // not under the target: take it away and look again
    extract.setInputCloud(cloud);
    extract.setIndices(inliers);
    extract.setNegative(true);
    auto rest = pcl::make_shared<Cloud>();
    extract.filter(*rest);
    cloud = rest;
  }
  return std::nullopt;
}

}  // namespace

std::optional<Footing> support_in_frame(const ModelCloud& model, const DepthImage& depth, const CameraIntrinsics& k,
                                        const Eigen::Matrix4d& T_camera_guess, double reach_m) {
  if (model.points.empty()) throw AlignmentError("support_in_frame: empty model");
  const Eigen::Vector3d centroid = centroid_of(model);
  double radius = 0.0;
  for (const auto& p : model.points) radius = std::max(radius, (p.cast<double>() - centroid).norm());
  const Eigen::Vector3d centre = (T_camera_guess * centroid.homogeneous()).head<3>();
  return support_among(points_near(depth, k, centre, radius + reach_m + kBeyondSphereM), model, T_camera_guess, centre, reach_m);
}

}  // namespace projbot::alignment
