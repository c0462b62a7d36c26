#pragma once
// A lens's distortion in OpenCV's model (k1, k2, p1, p2, k3), on normalised image coordinates
// (x, y) = (X/Z, Y/Z): what a calibration measures of the projector (issue 13). The renderer pre-distorts
// its image by it, and the twin's projector light follows it.

#include <Eigen/Core>
#include <array>
#include <optional>

#include "projbot/config/pinhole.hpp"

namespace projbot::config {

/// k1, k2, p1, p2, k3; all zero is a pinhole.
using Distortion = std::array<double, 5>;

/// A camera's or projector's lens as a calibration gives it: its pinhole and its distortion. The
/// calibration's two lenses (camera and projector) and a calibration file's projector.
struct Lens {
  Pinhole pinhole;
  Distortion distortion{};
};

/// Whether any coefficient is non-zero.
bool has_distortion(const Distortion& k);

/// Where the lens takes normalised coordinate x (OpenCV's forward model).
Eigen::Vector2d distort(const Distortion& k, const Eigen::Vector2d& x);

/// The normalised coordinate the lens takes to `d` (Newton's method from d); empty when it does not
/// converge to within 1e-10 (a distortion too strong to invert there).
std::optional<Eigen::Vector2d> undistort(const Distortion& k, const Eigen::Vector2d& d);

/// The Jacobian of distort() at x (its determinant <= 0 where the lens folds the image over).
Eigen::Matrix2d distort_jacobian(const Distortion& k, const Eigen::Vector2d& x);

}  // namespace projbot::config
