#pragma once
// Pose error as the BOP benchmark scores it: ADD (Hinterstoisser et al., ACCV 2012), the mean distance
// between the model's vertices under the estimate and under the truth; ADD-S for symmetric shapes, the
// mean distance from each vertex under the estimate to the nearest vertex under the truth.

#include <Eigen/Core>
#include <vector>

namespace projbot::alignment {

/// ADD in metres over `vertices` (model frame, metres).
double add_error_m(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Matrix4d& T_est, const Eigen::Matrix4d& T_true);

/// ADD-S in metres: each vertex under T_est to its nearest vertex under T_true (exact: NearestPoints, the distance in double).
double adds_error_m(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Matrix4d& T_est, const Eigen::Matrix4d& T_true);

}  // namespace projbot::alignment
