#pragma once
// PCL's filters, normals and features as acquisition uses them, its damped point-to-plane step, (registration.cpp and
// pcl_steps.cpp only: they see PCL), and where a model sits.

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/transformation_estimation_point_to_plane_lls.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <vector>

#include "serial_kdtree.hpp"

namespace projbot::alignment::detail {

using PointN = pcl::PointNormal;
using CloudN = pcl::PointCloud<PointN>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

/// The cloud on a voxel grid of `leaf` metres, its averaged normals made unit again.
CloudN::Ptr voxel_downsample(const CloudN::ConstPtr& in, double leaf);
/// PCL's statistical outlier removal (pcl::StatisticalOutlierRemoval, its arithmetic step for step): a
/// point whose mean distance to its k nearest neighbours is more than `stddev_mul` standard deviations
/// above the mean over all points is left out. Written out because PCL's filter builds its own
/// pcl::search::KdTree, whose per-query OpenMP region made it most of the filter's time (SerialKdTree).
pcl::PointCloud<pcl::PointXYZ>::Ptr outliers_removed(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k,
                                                     double stddev_mul);
/// PCL's own filter (pcl_search: PCL's pipeline as it comes).
pcl::PointCloud<pcl::PointXYZ>::Ptr pcl_outliers_removed(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k,
                                                         double stddev_mul);
/// Normals from k nearest neighbours, oriented towards the sensor at the origin; points without a
/// well-defined normal are dropped.
CloudN::Ptr with_normals(const pcl::PointCloud<pcl::PointXYZ>::ConstPtr& in, int k, bool pcl_search = false);
/// FPFH features of `cloud` (its own normals) within `radius` metres.
Features::Ptr fpfh(const CloudN::ConstPtr& cloud, double radius, bool pcl_search);

/// A k-d tree for PCL's searches: SerialKdTree, or with `pcl_search` PCL's own.
template <typename P>
typename pcl::search::KdTree<P>::Ptr search_tree(bool pcl_search) {
  if (pcl_search) return pcl::make_shared<pcl::search::KdTree<P>>();
  return pcl::make_shared<SerialKdTree<P>>();
}

/// Where a model sits: the centroid of its points, the largest distance of a point from it, and its
/// bounding box in the model frame.
struct Extent {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  double radius = 0.0;
  Eigen::AlignedBox3f box;

  Extent() = default;
  explicit Extent(const std::vector<Eigen::Vector3f>& points) {
    for (const auto& p : points) centroid += p, box.extend(p);
    if (!points.empty()) centroid /= static_cast<float>(points.size());
    for (const auto& p : points) radius = std::max(radius, static_cast<double>((p - centroid).norm()));
  }
  /// The centroid in the scan frame when the model is posed by T_scan_model.
  Eigen::Vector3d centre_in(const Eigen::Matrix4d& T_scan_model) const {
    return (T_scan_model * centroid.cast<double>().homogeneous()).head<3>();
  }
};

/// Point-to-plane least squares as PCL's TransformationEstimationPointToPlaneLLS, but damped: PCL inverts
/// the 6x6 normal matrix outright, and when the correspondences leave a direction unconstrained (one
/// visible plane, a handful of matches) that gives a NaN pose, and the next search asserts inside PCL.
/// Damping leaves such directions where they are instead.
/// Holding weak directions (Aligner::align's hold_weak), the step is solved only in the span of the strong
/// ones: the normal equations about the matched points' centre, rotations scaled by their radius (as
/// view_constraints), each eigen-direction with strength under kWeakStrength left out.
class DampedPointToPlane : public pcl::registration::TransformationEstimationPointToPlaneLLS<PointN, PointN> {
 public:
  explicit DampedPointToPlane(bool hold_weak = false) : hold_weak_(hold_weak) {}
  using pcl::registration::TransformationEstimationPointToPlaneLLS<PointN, PointN>::estimateRigidTransformation;
  void estimateRigidTransformation(const pcl::PointCloud<PointN>& source, const pcl::PointCloud<PointN>& target,
                                   const pcl::Correspondences& correspondences, Eigen::Matrix4f& T) const override;
  /// Weak directions the newest step left where they were.
  int held() const { return held_; }

 private:
  Eigen::Matrix4f strong_step(const pcl::PointCloud<PointN>& source, const pcl::PointCloud<PointN>& target,
                              const pcl::Correspondences& correspondences) const;
  bool hold_weak_;
  mutable int held_ = 0;
};

}  // namespace projbot::alignment::detail
