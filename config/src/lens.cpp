#include "projbot/config/lens.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "projbot/config/scene.hpp"

namespace projbot::config {

bool has_distortion(const Distortion& k) {
  for (const double c : k)
    if (c != 0.0) return true;
  return false;
}

Eigen::Vector2d distort(const Distortion& k, const Eigen::Vector2d& x) {
  const double r2 = x.squaredNorm();
  const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  const double xy = x.x() * x.y();
  return {x.x() * radial + 2.0 * k[2] * xy + k[3] * (r2 + 2.0 * x.x() * x.x()),
          x.y() * radial + k[2] * (r2 + 2.0 * x.y() * x.y()) + 2.0 * k[3] * xy};
}

Eigen::Matrix2d distort_jacobian(const Distortion& k, const Eigen::Vector2d& x) {
  const double r2 = x.squaredNorm();
  const double radial = 1.0 + r2 * (k[0] + r2 * (k[1] + r2 * k[4]));
  const double g = k[0] + r2 * (2.0 * k[1] + 3.0 * r2 * k[4]);  // d radial / d r2
  const double cross = 2.0 * x.x() * x.y() * g + 2.0 * k[2] * x.x() + 2.0 * k[3] * x.y();
  Eigen::Matrix2d J;
  J << radial + 2.0 * x.x() * x.x() * g + 2.0 * k[2] * x.y() + 6.0 * k[3] * x.x(), cross,  //
      cross, radial + 2.0 * x.y() * x.y() * g + 6.0 * k[2] * x.y() + 2.0 * k[3] * x.x();
  return J;
}

std::optional<Eigen::Vector2d> undistort(const Distortion& k, const Eigen::Vector2d& d) {
  Eigen::Vector2d x = d;
  for (int i = 0; i < 30; ++i) {
    const Eigen::Vector2d r = distort(k, x) - d;
    if (!std::isfinite(r.x()) || !std::isfinite(r.y())) return std::nullopt;
    if (r.norm() < 1e-12) return x;
    const Eigen::Matrix2d J = distort_jacobian(k, x);
    if (!(J.determinant() > 0.0)) return std::nullopt;
    x -= J.inverse() * r;
  }
  if ((distort(k, x) - d).norm() < 1e-10) return x;
  return std::nullopt;
}

Eigen::Vector2d Camera::project_lit(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = distort(distortion, {p.x() / p.z(), p.y() / p.z()});
  return project({d.x(), d.y(), 1.0});
}

std::optional<Eigen::Vector3d> Camera::panel_ray(double u, double v) const {
  const auto x = undistort(distortion, back_project(u, v, 1.0).head<2>());
  if (!x) return std::nullopt;
  return Eigen::Vector3d(x->x(), x->y(), 1.0);
}

namespace {

// A lens the renderer can pre-distort for: over a 33 x 33 grid of the panel (its edges included) every
// position sends its light along one ray, neighbours along neighbouring rays (the lens does not fold the
// image over), and the rays fit in an undistorted image at most twice the panel's size each way.
template <typename Fail>
void validate_lens(const ProjectorConfig& p, const Fail& fail) {
  for (const double c : p.distortion)
    if (!std::isfinite(c)) fail("distortion coefficients must be finite");
  if (!has_distortion(p.distortion)) return;
  constexpr int kSteps = 32;
  for (int j = 0; j <= kSteps; ++j)
    for (int i = 0; i <= kSteps; ++i) {
      const double u = -0.5 + p.width_px * i / double(kSteps), v = -0.5 + p.height_px * j / double(kSteps);
      const auto ray = p.panel_ray(u, v);
      const auto pixel = [](double x, int size) {
        return std::to_string(std::clamp(std::lround(std::floor(x + 0.5)), 0L, size - 1L));
      };
      const auto where = " at panel pixel (" + pixel(u, p.width_px) + ", " + pixel(v, p.height_px) + ")";
      if (!ray || !(distort_jacobian(p.distortion, ray->head<2>()).determinant() > 0.0))
        fail("distortion folds the image over" + where + ": no lens the renderer can pre-distort for (check the calibration)");
      const Eigen::Vector2d image = p.project(*ray);  // where the light goes, as the undistorted pinhole sees it
      if (std::abs(image.x() - p.cx_px) > p.width_px || std::abs(image.y() - p.cy_px) > p.height_px)
        fail("distortion throws the light of the panel" + where +
             " more than an image's width or height from the centre: "
             "too strong to pre-distort for (check the calibration)");
    }
}

}  // namespace

void validate_projector(const ProjectorConfig& p, std::string_view where) {
  const auto fail = [&](const std::string& why) { throw ConfigError(std::string(where) + ": " + why); };
  if (p.width_px <= 0 || p.height_px <= 0 || p.width_px > 16384 || p.height_px > 16384)
    fail("size " + std::to_string(p.width_px) + "x" + std::to_string(p.height_px) + " must be 1..16384 pixels each way");
  if (!(p.fx_px > 0.0) || !(p.fy_px > 0.0) || !std::isfinite(p.fx_px) || !std::isfinite(p.fy_px))
    fail("fx and fy must be finite and > 0");
  if (!std::isfinite(p.cx_px) || !std::isfinite(p.cy_px)) fail("cx and cy must be finite");
  // Bounded below and above, not only positive: near 1e-300 passed "> 0" and tore the depth buffer.
  if (!(p.near_m >= 1e-4) || !(p.far_m <= 1e4) || !(p.near_m < p.far_m) || !(p.far_m <= p.near_m * 1e7)) {
    std::ostringstream v;
    v << "need 0.0001 m <= near < far <= 10000 m with far / near <= 1e7 (near " << p.near_m << ", far " << p.far_m << ")";
    fail(v.str());
  }
  validate_lens(p, fail);
}

}  // namespace projbot::config
