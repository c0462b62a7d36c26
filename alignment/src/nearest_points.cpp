#include "projbot/alignment/nearest_points.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

namespace projbot::alignment {

struct NearestPoints::Impl {
  std::size_t size = 0;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
};

NearestPoints::NearestPoints(const std::vector<Eigen::Vector3f>& points) : impl_(std::make_unique<Impl>()) {
  impl_->size = points.size();
  if (points.empty()) return;
  const auto cloud = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const auto& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  impl_->tree.setSortedResults(true);
  impl_->tree.setInputCloud(cloud);
}

NearestPoints::~NearestPoints() = default;
NearestPoints::NearestPoints(NearestPoints&&) noexcept = default;
NearestPoints& NearestPoints::operator=(NearestPoints&&) noexcept = default;

std::size_t NearestPoints::size() const { return impl_->size; }

std::size_t NearestPoints::nearest(const Eigen::Vector3f& q, std::size_t skip) const {
  const std::size_t n = impl_->size;
  if (n == 0 || !q.allFinite()) return n;
  const int k = skip < n ? 2 : 1;
  std::vector<int> index(static_cast<std::size_t>(k));
  std::vector<float> squared(static_cast<std::size_t>(k));
  const int found = impl_->tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), k, index, squared);
  for (int i = 0; i < found; ++i)
    if (static_cast<std::size_t>(index[static_cast<std::size_t>(i)]) != skip)
      return static_cast<std::size_t>(index[static_cast<std::size_t>(i)]);
  return n;
}

}  // namespace projbot::alignment
