// Turns the depth cannot see: a pose turned about an axis its view leaves free, back towards a prior.

#include <Eigen/Geometry>
#include <cmath>
#include <optional>
#include <vector>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/verification.hpp"

namespace projbot::alignment {

TurnAxis turn_axis(const ViewConstraints& view, const WeakDirection& weak) {
  // The weak motion moves a point p by t + w x (p - centre), w the rotation over the radius: a pure turn
  // about the axis through q = centre + (w x t) / |w|^2 (t's part along w is a slide along the axis).
  const Eigen::Vector3d w = weak.rotation / view.radius;
  return {view.centre + w.cross(weak.translation) / w.squaredNorm(), w.normalized()};
}

Eigen::Matrix4d TurnAxis::turn(double angle_rad) const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle_rad, direction).toRotationMatrix();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = point - R * point;
  return T;
}

Eigen::Matrix4d turn_towards(const ViewConstraints& view, const WeakDirection& weak, const Eigen::Matrix4d& T_camera_model,
                             const Eigen::Matrix4d& prior) {
  if (weak.is_slide() || !T_camera_model.allFinite() || !prior.allFinite()) return Eigen::Matrix4d::Identity();
  const TurnAxis axis = turn_axis(view, weak);
  // The prior's orientation relative to T's, split into a twist about the axis and the rest (swing).
  Eigen::Quaterniond relative(Eigen::Matrix3d(prior.topLeftCorner<3, 3>() * T_camera_model.topLeftCorner<3, 3>().transpose()));
  if (relative.w() < 0.0) relative.coeffs() = -relative.coeffs();
  return axis.turn(2.0 * std::atan2(relative.vec().dot(axis.direction), relative.w()));
}

namespace {

// Whether the samples `probes` seen at T, moved to where T_model_model takes them, still lie on the
// model's surface: all but 2 % within twice their own spacing to a sample plus 2 mm (the
// depth's noise at a metre; the real mug's scanned model is round to about 1.5 mm).
bool stays_on_surface(const ModelCloud& model, const NearestPoints& samples, const Eigen::Matrix4d& T_model_model,
                      const std::vector<std::size_t>& probes) {
  const Eigen::Matrix3f R = T_model_model.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = T_model_model.topRightCorner<3, 1>().cast<float>();
  const std::size_t n = model.points.size();
  std::size_t off = 0;
  for (const std::size_t i : probes) {
    const Eigen::Vector3f& p = model.points[i];
    const std::size_t own = samples.nearest(p, i);
    const Eigen::Vector3f q = R * p + t;
    const std::size_t moved = samples.nearest(q, n);
    if (own >= n || moved >= n || (model.points[moved] - q).norm() > 2.0F * (model.points[own] - p).norm() + 0.002F) ++off;
  }
  return static_cast<double>(off) <= 0.02 * static_cast<double>(probes.size());
}

}  // namespace

Eigen::Matrix4d nearest_unseen_turn(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const Eigen::Matrix4d& prior,
                                    const DepthImage& depth, const CameraIntrinsics& k, const NearestPoints* samples) {
  constexpr double kMinTurnDeg = 1.0;  // nearer than that: not worth a check
  constexpr std::size_t kProbes = 200;
  // The turn a body of revolution's seen surface leaves free is its weakest direction, but not below
  // kWeakStrength: the real mug's was 0.04 (the next 0.30), the pixel grid's samples not quite round.
  // The checks below decide; this only spares them where every direction is firm.
  constexpr double kMaxStrength = 0.1;
  if (model.points.size() < 2) return T_camera_model;
  const ViewConstraints view = view_constraints(model, T_camera_model, k);
  std::vector<std::size_t> probes;         // the samples seen at T: found once a turn is worth checking
  std::optional<FreeSpaceCheck> unturned;  // T's own free-space check: once, when a turn stays on the surface
  std::optional<NearestPoints> built;      // the samples' index, when none is given: once a turn is worth checking
  for (const WeakDirection& weak : view.all) {
    if (weak.strength > kMaxStrength) break;
    const Eigen::Matrix4d turn = turn_towards(view, weak, T_camera_model, prior);
    if (rotation_angle_deg(turn) < kMinTurnDeg) continue;
    if (probes.empty()) probes = visible_samples(model, T_camera_model, depth, k, kProbes);
    if (probes.size() < kProbes / 4) return T_camera_model;
    if (!samples || samples->size() != model.points.size()) samples = &built.emplace(model.points);
    const Eigen::Matrix4d turned = turn * T_camera_model;
    // A point seen at T (T p) lies on the turned model where it draws turned^-1 T p.
    if (!stays_on_surface(model, *samples, rigid_inverse(turned) * T_camera_model, probes)) continue;
    if (!unturned) unturned = check_free_space(model, T_camera_model, depth, k);
    const FreeSpaceCheck after = check_free_space(model, turned, depth, k);
    if (after.predicted == 0 ||
        static_cast<double>(after.behind) > static_cast<double>(unturned->behind) + 0.01 * static_cast<double>(after.predicted))
      continue;
    return turned;
  }
  return T_camera_model;
}

}  // namespace projbot::alignment
