#pragma once
// Degrees and radians, converted in one place. Configuration and people speak degrees; Eigen and the
// maths speak radians.

#include <numbers>

namespace projbot::config {

/// `rad` radians in degrees.
constexpr double degrees(double rad) { return rad * 180.0 / std::numbers::pi; }

/// `deg` degrees in radians.
constexpr double radians(double deg) { return deg * std::numbers::pi / 180.0; }

}  // namespace projbot::config
