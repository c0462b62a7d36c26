#pragma once
// Nearest-point queries over a fixed set of points: PCL's k-d tree (FLANN's exact single-tree search)
// behind a header free of PCL, for the checks that compare a model with itself moved (looks_alike, the
// unseen turn's surface test) and for ADD-S.

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <vector>

namespace projbot::alignment {

class NearestPoints {
 public:
  explicit NearestPoints(const std::vector<Eigen::Vector3f>& points);
  ~NearestPoints();
  NearestPoints(NearestPoints&&) noexcept;
  NearestPoints& operator=(NearestPoints&&) noexcept;
  NearestPoints(const NearestPoints&) = delete;
  NearestPoints& operator=(const NearestPoints&) = delete;

  /// The index of the point nearest `q` other than the one at `skip` (size(): none skipped); size()
  /// when there is none (no points, or only the skipped one).
  std::size_t nearest(const Eigen::Vector3f& q, std::size_t skip) const;
  std::size_t size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::alignment
