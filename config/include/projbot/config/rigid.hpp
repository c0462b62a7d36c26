#pragma once
// Rigid transforms read from outside the project's own files.

#include <Eigen/Core>
#include <string_view>

namespace projbot::config {

/// A rigid transform read from outside (a dataset's float32 rotations, a matrix typed on the command line):
/// checked as validate_rigid but with its rotation orthonormal to `tolerance`, then returned with the
/// rotation re-orthonormalised (the nearest rotation, by SVD). Throws ConfigError with `where`.
Eigen::Matrix4d orthonormalised_rigid(const Eigen::Matrix4d& T, std::string_view where, double tolerance = 1e-4);

}  // namespace projbot::config
