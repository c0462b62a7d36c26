// A k-d tree for PCL's point searches that answers one query at a time without OpenMP. Private to
// registration.cpp, the one translation unit with PCL's filters, features and registration.
//
// Why: pcl::search::KdTree asks pcl::KdTreeFLANN, which asks FLANN's batch knnSearch for every single
// query, and that opens an OpenMP parallel region (of one thread) each time; libgomp ends every region
// at a team barrier that wakes waiters with a futex system call whether there are any or not. On this
// project's 2-core machine a nearest-neighbour query into a 60 000-point tree took 3.3 us that way and
// 0.5 us through FLANN's own findNeighbors on the same kind of tree (same leaf size, exact search, the
// same answers). ICP's correspondences, the scan normals, the outlier filter and the quality gate make
// one query per point, tens of thousands per acquisition.
//
// The tree is FLANN's KDTreeSingleIndex with PCL's parameters (15 points a leaf, exact search), built on
// the points' x, y, z (PCL's point representation for PointXYZ and PointNormal); points that are not
// finite are left out, and answers give indices into the input cloud, as PCL's do.

#pragma once

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace projbot::alignment {

template <typename PointT>
class SerialKdTree : public pcl::search::KdTree<PointT> {
 public:
  using Cloud = pcl::PointCloud<PointT>;
  using pcl::search::Search<PointT>::nearestKSearch;
  using pcl::search::Search<PointT>::radiusSearch;
  using Ptr = std::shared_ptr<SerialKdTree<PointT>>;

  void setInputCloud(const typename Cloud::ConstPtr& cloud, const pcl::IndicesConstPtr& indices = {}) override {
    this->input_ = cloud;
    this->indices_ = indices;
    index_.reset();
    ids_.clear();
    xyz_.clear();
    if (!cloud) return;
    const auto add = [&](pcl::index_t i) {
      const PointT& p = (*cloud)[static_cast<std::size_t>(i)];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return;
      xyz_.insert(xyz_.end(), {p.x, p.y, p.z});
      ids_.push_back(i);
    };
    if (indices)
      for (const pcl::index_t i : *indices) add(i);
    else
      for (std::size_t i = 0; i < cloud->size(); ++i) add(static_cast<pcl::index_t>(i));
    if (ids_.empty()) return;
    index_ = std::make_unique<Index>(flann::Matrix<float>(xyz_.data(), ids_.size(), 3), flann::KDTreeSingleIndexParams(15));
    index_->buildIndex();
  }

  int nearestKSearch(const PointT& point, int k, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances) const override {
    k = std::min(k, static_cast<int>(ids_.size()));
    if (k <= 0 || !finite(point)) {
      k_indices.clear();
      k_sqr_distances.clear();
      return 0;
    }
    flann::KNNSimpleResultSet<float> result(static_cast<std::size_t>(k));
    const float q[3] = {point.x, point.y, point.z};
    index_->findNeighbors(result, q, params_);
    return copied(result, static_cast<std::size_t>(k), true, k_indices, k_sqr_distances);
  }

  int radiusSearch(const PointT& point, double radius, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                   unsigned int max_nn = 0) const override {
    if (!index_ || !finite(point) || !(radius > 0.0)) {
      k_indices.clear();
      k_sqr_distances.clear();
      return 0;
    }
    flann::RadiusResultSet<float> result(static_cast<float>(radius * radius));
    const float q[3] = {point.x, point.y, point.z};
    index_->findNeighbors(result, q, params_);
    std::size_t n = result.size();
    const bool capped = max_nn > 0 && n > max_nn;  // the nearest max_nn, as PCL gives them
    n = capped ? max_nn : n;
    return copied(result, n, this->sorted_results_ || capped, k_indices, k_sqr_distances);
  }

 private:
  using Index = flann::KDTreeSingleIndex<flann::L2_Simple<float>>;

  static bool finite(const PointT& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); }

  template <typename ResultSet>
  int copied(ResultSet& result, std::size_t n, bool sorted, pcl::Indices& k_indices, std::vector<float>& k_sqr_distances) const {
    n = std::min(n, result.size());
    thread_local std::vector<std::size_t> at;
    at.resize(n);
    k_sqr_distances.resize(n);
    if (n > 0) result.copy(at.data(), k_sqr_distances.data(), n, sorted);
    k_indices.resize(n);
    for (std::size_t i = 0; i < n; ++i) k_indices[i] = ids_[at[i]];
    return static_cast<int>(n);
  }

  std::vector<float> xyz_;                      // the finite points, x y z each; the index points into it
  std::vector<pcl::index_t> ids_;               // their indices in the input cloud
  std::unique_ptr<Index> index_;                // none without finite points
  flann::SearchParams params_{-1, 0.0F, true};  // unlimited checks, exact
};

}  // namespace projbot::alignment
