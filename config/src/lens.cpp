#include "projbot/config/lens.hpp"

#include <Eigen/LU>
#include <cmath>

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

Eigen::Vector2d ProjectorConfig::project_lit(const Eigen::Vector3d& p) const {
  const Eigen::Vector2d d = distort(distortion, {p.x() / p.z(), p.y() / p.z()});
  return {fx_px * d.x() + cx_px, fy_px * d.y() + cy_px};
}

std::optional<Eigen::Vector3d> ProjectorConfig::panel_ray(double u, double v) const {
  const auto x = undistort(distortion, {(u - cx_px) / fx_px, (v - cy_px) / fy_px});
  if (!x) return std::nullopt;
  return Eigen::Vector3d(x->x(), x->y(), 1.0);
}

}  // namespace projbot::config
