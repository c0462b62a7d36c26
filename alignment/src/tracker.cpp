#include "projbot/alignment/tracker.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"

namespace projbot::alignment {
namespace {

// exp of a twist (v, w) as a rigid transform (first order in the rotation's axis-angle, exact rotation).
Eigen::Matrix4d twist_to_transform(const Eigen::Matrix<double, 6, 1>& xi) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = exp_so3(xi.tail<3>());
  T.topRightCorner<3, 1>() = xi.head<3>();
  return T;
}

double sensor_sigma(double z) { return std::max(kKinectV1SigmaZCoeff * z * z, 0.001); }

}  // namespace

ProjectiveTracker::ProjectiveTracker(ModelCloud model, CameraIntrinsics intrinsics, TrackerConfig config)
    : model_(std::move(model)), k_(intrinsics), cfg_(std::move(config)) {
  if (model_.points.size() < 10 || model_.normals.size() != model_.points.size())
    throw AlignmentError("tracker: the model needs at least 10 points with normals");
  if (!(k_.fx_px > 0) || !(k_.fy_px > 0) || k_.width_px <= 0 || k_.height_px <= 0)
    throw AlignmentError("tracker: bad intrinsics");
  if (cfg_.pyramid_levels < 1 || cfg_.iterations.size() != static_cast<std::size_t>(cfg_.pyramid_levels) ||
      cfg_.model_points.size() != static_cast<std::size_t>(cfg_.pyramid_levels))
    throw AlignmentError("tracker: iterations and model_points need one entry per pyramid level");
  // A fixed shuffle: the first n points are a uniform subsample for every n.
  std::vector<std::size_t> order(model_.points.size());
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  double sq = 0.0;
  for (const auto& p : model_.points) sq += p.cast<double>().squaredNorm();
  model_radius_m_ = std::sqrt(sq / static_cast<double>(model_.points.size()));
  ModelCloud shuffled;
  for (auto i : order) {
    shuffled.points.push_back(model_.points[i]);
    shuffled.normals.push_back(model_.normals[i]);
  }
  model_ = std::move(shuffled);
}

std::vector<ProjectiveTracker::Level> ProjectiveTracker::pyramid(const DepthImage& depth) const {
  if (depth.width != k_.width_px || depth.height != k_.height_px)
    throw AlignmentError("tracker: depth frame is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                         ", the camera " + std::to_string(k_.width_px) + "x" + std::to_string(k_.height_px));
  std::vector<Level> levels(static_cast<std::size_t>(cfg_.pyramid_levels));
  levels[0].k = k_;
  levels[0].z = depth.depth_m.data();  // read in place: the pyramid, with a copy of this level, was a fifth of the tracking
  for (std::size_t l = 1; l < levels.size(); ++l) {
    const Level& fine = levels[l - 1];
    Level& coarse = levels[l];
    coarse.k = fine.k;
    coarse.k.width_px = fine.k.width_px / 2;
    coarse.k.height_px = fine.k.height_px / 2;
    coarse.k.fx_px = fine.k.fx_px / 2, coarse.k.fy_px = fine.k.fy_px / 2;
    coarse.k.cx_px = (fine.k.cx_px + 0.5) / 2 - 0.5, coarse.k.cy_px = (fine.k.cy_px + 0.5) / 2 - 0.5;
    coarse.own.assign(static_cast<std::size_t>(coarse.k.width_px) * coarse.k.height_px, 0.0F);
    for (int y = 0; y < coarse.k.height_px; ++y)
      for (int x = 0; x < coarse.k.width_px; ++x) {
        // Mean of the valid 2x2 block, unless it straddles a depth edge (then no depth, not a blend).
        float sum = 0, lo = 1e9F, hi = 0;
        int n = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const float z = fine.z[static_cast<std::size_t>(2 * y + dy) * fine.k.width_px + 2 * x + dx];
            if (!has_depth(z)) continue;
            sum += z, lo = std::min(lo, z), hi = std::max(hi, z), ++n;
          }
        if (n >= 2 && hi - lo < 3.0F * static_cast<float>(sensor_sigma(lo)) + 0.01F)
          coarse.own[static_cast<std::size_t>(y) * coarse.k.width_px + x] = sum / static_cast<float>(n);
      }
    coarse.z = coarse.own.data();
  }
  return levels;
}

// A weak pull towards the start pose (the motion model's prediction, or the last pose): in the
// directions the depth constrains, negligible beside the data; in those it does not (a box seen
// face-on slides freely along its face), it keeps the start instead of whatever the solver's null
// space gives. It weighs how far the model's points move from the start (at its origin c, and over
// its radius for turns), times `weight` times the data's mean information per axis.
void add_start_prior(Eigen::Matrix<double, 6, 6>& H, Eigen::Matrix<double, 6, 1>& g, const Eigen::Matrix4d& T,
                     const Eigen::Matrix4d& T_start, double weight, double radius_m) {
  if (!(weight > 0.0)) return;
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>() * T_start.topLeftCorner<3, 3>().transpose();
  Eigen::Matrix<double, 6, 1> xi;  // T = exp(xi) T_start to first order (turns about the camera's origin)
  xi.head<3>() = T.topRightCorner<3, 1>() - R * T_start.topRightCorner<3, 1>();
  xi.tail<3>() = log_so3(R);
  // The displacement of the model's origin c is v + w x c = M xi; of its points, also rho w.
  const Eigen::Vector3d c = T.topRightCorner<3, 1>();
  Eigen::Matrix3d cx;
  cx << 0.0, -c.z(), c.y(), c.z(), 0.0, -c.x(), -c.y(), c.x(), 0.0;
  Eigen::Matrix<double, 3, 6> M;
  M << Eigen::Matrix3d::Identity(), -cx;
  Eigen::Matrix<double, 6, 6> Hp = M.transpose() * M;
  Hp.bottomRightCorner<3, 3>() += radius_m * radius_m * Eigen::Matrix3d::Identity();
  Hp *= weight * H.trace() / 6.0;
  H += Hp;
  g += Hp * xi;
}

TrackResult ProjectiveTracker::track(const DepthImage& depth, const Eigen::Matrix4d& T_prev,
                                     const Eigen::Matrix4d* T_hold) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (!T_prev.allFinite()) throw AlignmentError("tracker: previous pose is not finite");
  if (T_hold && !T_hold->allFinite()) throw AlignmentError("tracker: held pose is not finite");
  const std::vector<Level> levels = pyramid(depth);
  TrackResult out;
  Eigen::Matrix4d T = T_prev;

  // One pass over the model points of a level: the normal equations, or the quality numbers.
  struct Pass {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    std::size_t used = 0, candidates = 0, inliers = 0;
    double inlier_sq = 0.0;
  };
  const auto run = [&](const Level& lv, std::size_t count, const Eigen::Matrix4d& T_cur, double reach) {
    Pass p;
    const Eigen::Matrix3d R = T_cur.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = T_cur.topRightCorner<3, 1>();
    const std::size_t n = std::min(count, model_.points.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d x = R * model_.points[i].cast<double>() + t;
      const Eigen::Vector3d nrm = R * model_.normals[i].cast<double>();
      if (x.z() <= 0.05 || nrm.dot(x) >= 0.0) continue;  // behind the camera, or facing away
      int u = 0, v = 0;
      if (!lv.k.nearest_pixel(x, u, v)) continue;
      const float zs = lv.z[static_cast<std::size_t>(v) * lv.k.width_px + u];
      if (!has_depth(zs)) continue;
      if (zs < x.z() - cfg_.occlusion_margin_m) continue;  // something in front of the model: occluded
      ++p.candidates;
      const Eigen::Vector3d q((u - lv.k.cx_px) * zs / lv.k.fx_px, (v - lv.k.cy_px) * zs / lv.k.fy_px, zs);
      const Eigen::Vector3d d = x - q;
      if (d.squaredNorm() > reach * reach) continue;
      const double r = nrm.dot(d);  // point-to-plane, the plane of the model's exact normal
      if (std::abs(r) <= cfg_.inlier_distance_m) {
        ++p.inliers;
        p.inlier_sq += r * r;
      }
      // Huber weight with a threshold that grows with the sensor's noise at this depth.
      const double delta = cfg_.huber_sigmas * sensor_sigma(zs);
      const double w = std::abs(r) <= delta ? 1.0 : delta / std::abs(r);
      Eigen::Matrix<double, 6, 1> J;
      J.head<3>() = nrm;           // d r / d v
      J.tail<3>() = x.cross(nrm);  // d r / d w, for x -> x + w x x + v
      p.H.selfadjointView<Eigen::Upper>().rankUpdate(J, w);
      p.g += w * r * J;
      ++p.used;
    }
    return p;
  };

  for (int l = cfg_.pyramid_levels - 1; l >= 0; --l) {
    const auto li = static_cast<std::size_t>(cfg_.pyramid_levels - 1 - l);  // coarsest first in the config
    const Level& lv = levels[static_cast<std::size_t>(l)];
    const double reach = li == 0 ? std::max(cfg_.max_distance_m, cfg_.coarse_max_distance_m) : cfg_.max_distance_m;
    for (int it = 0; it < cfg_.iterations[li]; ++it) {
      Pass p = run(lv, cfg_.model_points[li], T, reach);
      ++out.iterations;
      if (p.used < 6 * 3) break;
      p.H.triangularView<Eigen::Lower>() = p.H.transpose();
      if (T_hold)
        add_start_prior(p.H, p.g, T, *T_hold, cfg_.hold_prior, model_radius_m_);
      else
        add_start_prior(p.H, p.g, T, T_prev, cfg_.start_prior, model_radius_m_);
      const Eigen::Matrix<double, 6, 1> xi = p.H.ldlt().solve(-p.g);
      if (!xi.allFinite()) break;
      T = twist_to_transform(xi) * T;
      if (xi.head<3>().norm() + xi.tail<3>().norm() * model_radius_m_ < cfg_.converged_step_m) break;
    }
  }
  const Pass q = run(levels[0], cfg_.model_points.back(), T, cfg_.max_distance_m);
  out.T_camera_target = T;
  out.correspondences = q.used;
  out.inlier_ratio = q.candidates > 0 ? static_cast<double>(q.inliers) / static_cast<double>(q.candidates) : 0.0;
  out.rmse_mm =
      q.inliers > 0 ? 1000.0 * std::sqrt(q.inlier_sq / static_cast<double>(q.inliers)) : std::numeric_limits<double>::infinity();
  out.accepted =
      q.used >= cfg_.min_correspondences && out.inlier_ratio >= cfg_.min_inlier_ratio && out.rmse_mm <= cfg_.max_rmse_mm;
  out.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace projbot::alignment
