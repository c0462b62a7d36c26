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

/// Whether any coefficient is non-zero.
bool has_distortion(const Distortion& k);

/// Where the lens takes normalised coordinate x (OpenCV's forward model).
Eigen::Vector2d distort(const Distortion& k, const Eigen::Vector2d& x);

/// The normalised coordinate the lens takes to `d` (Newton's method from d); empty when it does not
/// converge to within 1e-10 (a distortion too strong to invert there).
std::optional<Eigen::Vector2d> undistort(const Distortion& k, const Eigen::Vector2d& d);

/// The Jacobian of distort() at x (its determinant <= 0 where the lens folds the image over).
Eigen::Matrix2d distort_jacobian(const Distortion& k, const Eigen::Vector2d& x);

/// The one camera type: a pinhole (A_p, Eq. 3), its lens's distortion and the depth range it draws. The
/// projector's (ProjectorConfig adds its refresh, lag and photometry), the depth camera's (`camera:`, a
/// pinhole: no distortion), the colour camera's and a calibration's two lenses (whose clip range is unused).
struct Camera : Pinhole {
  Camera() = default;
  Camera(const Pinhole& pinhole, double near, double far, const Distortion& lens = {})
      : Pinhole(pinhole), near_m(near), far_m(far), distortion(lens) {}
  double near_m = 0.1;  ///< near clipping distance along z, metres (> 0)
  double far_m = 20.0;  ///< far clipping distance along z, metres (> near_m)
  /// k1, k2, p1, p2, k3 (`projector.distortion`, or a calibration's); zero for a pinhole. The renderer
  /// pre-distorts the projector's image by it.
  Distortion distortion{};

  /// The image position where point p (z > 0) lands through the lens: A after the distortion. Equals
  /// project(p) without distortion. (For a projector: the panel pixel whose light reaches p.)
  Eigen::Vector2d project_lit(const Eigen::Vector3d& p) const;
  /// The direction (x, y, 1) that image position (u, v) sees (a projector: sends its light out along): the
  /// lens undone. Empty where the distortion cannot be inverted (validate_projector refuses such lenses).
  std::optional<Eigen::Vector3d> panel_ray(double u, double v) const;
};

}  // namespace projbot::config
