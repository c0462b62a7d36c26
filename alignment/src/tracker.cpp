#include "projbot/alignment/tracker.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <string>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/config/clock.hpp"

namespace projbot::alignment {
namespace {

// exp of a twist (v, w) as a rigid transform (first order in the rotation's axis-angle, exact rotation).
Eigen::Matrix4d twist_to_transform(const Eigen::Matrix<double, 6, 1>& xi) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = exp_so3(xi.tail<3>());
  T.topRightCorner<3, 1>() = xi.head<3>();
  return T;
}

// H's upper triangle += w J J^T, written out: Eigen's rankUpdate (and a product assignment) were a
// library call per correspondence, a sixth of the tracker's time.
inline void add_weighted_outer(Eigen::Matrix<double, 6, 6>& H, const Eigen::Matrix<double, 6, 1>& J, double w) {
  for (int c = 0; c < 6; ++c) {
    const double wj = w * J[c];
    for (int r = 0; r <= c; ++r) H(r, c) += wj * J[r];
  }
}

double sensor_sigma(double z) { return std::max(kKinectV1SigmaZCoeff * z * z, 0.001); }

constexpr int kSplat = 1;           // outline_grid: each model point covers the pixels this far around its own
constexpr int kMaxEdgeSearch = 32;  // TrackerConfig::edge_search_px at most

// Where, along p + s d (s in pixels, -reach..reach, d outward), the depth image steps from the
// target's surface (at most `band` behind z_ref, the outline's depth, and not far in front of it) to
// what lies behind, nearest s = anchor: NaN when there is no such step, or something in front of the
// target lies between. The Kinect loses the pixel on each side of a step (and more at grazing angles
// on the target's side), so the step is put 1.5 pixels before the first pixel behind it.
double silhouette_step(const float* z, const CameraIntrinsics& k, const Eigen::Vector2d& p, const Eigen::Vector2d& d,
                       double z_ref, double band, int reach, double anchor) {
  enum Kind : signed char { none, surface, behind, in_front };
  std::array<Kind, 2 * kMaxEdgeSearch + 1> kind{};
  const double front = std::max(band, 0.08);  // a limb's own curve comes nearer than band, an occluder more
  for (int s = -reach; s <= reach; ++s) {
    const Eigen::Vector2d x = p + s * d;
    Kind& c = kind[static_cast<std::size_t>(s + reach)];
    if (!(x.x() > -0.5 && x.y() > -0.5 && x.x() < k.width_px - 0.5 && x.y() < k.height_px - 0.5)) continue;
    const float zs = z[static_cast<std::size_t>(x.y() + 0.5) * k.width_px + static_cast<std::size_t>(x.x() + 0.5)];
    if (!has_depth(zs)) continue;
    c = zs > z_ref + band ? behind : zs < z_ref - front ? in_front : surface;
  }
  double best = std::numeric_limits<double>::quiet_NaN();
  for (int a = -reach; a < reach; ++a) {
    if (kind[static_cast<std::size_t>(a + reach)] != surface) continue;
    int b = a + 1;
    while (b <= reach && b - a <= 5 && kind[static_cast<std::size_t>(b + reach)] == none) ++b;
    if (b > reach || kind[static_cast<std::size_t>(b + reach)] != behind) continue;
    const double step = std::max(0.5 * (a + b), b - 1.5);
    bool hidden = false;
    for (int s = std::min(0, a); s <= std::max(0, a); ++s)
      hidden = hidden || kind[static_cast<std::size_t>(s + reach)] == in_front;
    if (!hidden && !(std::abs(step - anchor) >= std::abs(best - anchor))) best = step;
  }
  return best;
}

}  // namespace

ProjectiveTracker::ProjectiveTracker(ModelCloud model, CameraIntrinsics intrinsics, TrackerConfig config)
    : model_(std::move(model)), k_(intrinsics), cfg_(std::move(config)) {
  if (model_.points.size() < 10 || model_.normals.size() != model_.points.size())
    throw AlignmentError((model_.source.empty() ? std::string("tracker: the model") : model_.source + ": the model") +
                         " needs at least 10 points with normals (its surface has no area to sample?)");
  if (!(k_.fx_px > 0) || !(k_.fy_px > 0) || k_.width_px <= 0 || k_.height_px <= 0)
    throw AlignmentError("tracker: bad intrinsics");
  if (cfg_.pyramid_levels < 1 || cfg_.iterations.size() != static_cast<std::size_t>(cfg_.pyramid_levels) ||
      cfg_.model_points.size() != static_cast<std::size_t>(cfg_.pyramid_levels))
    throw AlignmentError("tracker: iterations and model_points need one entry per pyramid level");
  if (cfg_.edge_weight > 0.0 && !(cfg_.edge_search_px >= 1 && cfg_.edge_search_px <= kMaxEdgeSearch))
    throw AlignmentError("tracker: edge_search_px must be 1.." + std::to_string(kMaxEdgeSearch) + ", not " +
                         std::to_string(cfg_.edge_search_px));
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

std::vector<float> ProjectiveTracker::outline_grid(const Eigen::Matrix4d& T, std::size_t n) const {
  const int w = k_.width_px, h = k_.height_px;
  std::vector<float> grid(static_cast<std::size_t>(w) * h, std::numeric_limits<float>::infinity());
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  for (std::size_t i = 0; i < std::min(n, model_.points.size()); ++i) {
    const Eigen::Vector3d x = R * model_.points[i].cast<double>() + t;
    int u = 0, v = 0;
    if (x.z() <= 0.05 || (R * model_.normals[i].cast<double>()).dot(x) >= 0.0 || !k_.nearest_pixel(x, u, v)) continue;
    for (int y = std::max(v - kSplat, 0); y <= std::min(v + kSplat, h - 1); ++y)
      for (int c = std::max(u - kSplat, 0); c <= std::min(u + kSplat, w - 1); ++c) {
        float& near = grid[static_cast<std::size_t>(y) * w + c];
        near = std::min(near, static_cast<float>(x.z()));
      }
  }
  return grid;
}

bool ProjectiveTracker::add_edge(const Level& lv, const std::vector<float>& outline, const Eigen::Vector3d& x,
                                 const Eigen::Vector3d& x0, const Eigen::Vector3d& nrm, Eigen::Matrix<double, 6, 6>& H,
                                 Eigen::Matrix<double, 6, 1>& g) const {
  const CameraIntrinsics& k = lv.k;
  const double iz = 1.0 / x.z();
  Eigen::Matrix<double, 2, 3> P;  // pixels per metre of the point's motion
  P << k.fx_px * iz, 0.0, -k.fx_px * x.x() * iz * iz, 0.0, k.fy_px * iz, -k.fy_px * x.y() * iz * iz;
  const Eigen::Vector2d dn = P * nrm;
  if (!(dn.norm() > 1e-9)) return false;
  const Eigen::Vector2d d = dn.normalized();  // the outline's outward normal in the image
  if (std::abs(d.x()) < cfg_.edge_min_across) return false;
  const Eigen::Vector2d p = k.project(x);
  // Where the model's own outline lies along d from x (x may lie inside it: a box's side seen at a
  // grazing angle), and where the image's silhouette does.
  const double band = 3.0 * sensor_sigma(x.z()) + 0.01;
  double predicted = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d p0 = k.project(x0);  // the outline was drawn at the start pose: it moves with the model
  for (int s = 1; s <= cfg_.edge_search_px; ++s) {
    const Eigen::Vector2d b = p0 + s * d;  // rounded to its pixel as silhouette_step rounds
    if (!(b.x() > -0.5 && b.y() > -0.5 && b.x() < k.width_px - 0.5 && b.y() < k.height_px - 0.5)) break;
    if (outline[static_cast<std::size_t>(b.y() + 0.5) * k.width_px + static_cast<std::size_t>(b.x() + 0.5)] > x.z() + band) {
      predicted = s - 1.0 - kSplat;
      break;
    }
  }
  if (!std::isfinite(predicted) || predicted > 0.5 * cfg_.edge_search_px) return false;
  const double step = silhouette_step(lv.z, k, p, d, x.z(), band, cfg_.edge_search_px, predicted) - predicted;
  if (!std::isfinite(step)) return false;
  const double scale = x.z() / (0.5 * (k.fx_px + k.fy_px));  // metres per pixel at this depth
  const double r = -step * scale;                            // the outline is to move `step` pixels along d
  const Eigen::Vector3d j = scale * (P.transpose() * d);
  Eigen::Matrix<double, 6, 1> J;
  J.head<3>() = j;
  J.tail<3>() = x.cross(j);
  const double delta = 1.5 * scale;  // Huber at 1.5 pixels
  const double w = cfg_.edge_weight * (std::abs(r) <= delta ? 1.0 : delta / std::abs(r));
  add_weighted_outer(H, J, w);
  g += w * r * J;
  return true;
}

ProjectiveTracker::Pass ProjectiveTracker::pass(const Level& lv, std::size_t count, const Eigen::Matrix4d& T, double reach,
                                                const Outline* outline) const {
  Pass p;
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  const std::size_t n = std::min(count, model_.points.size());
  // A back face is told in the model's frame, from the camera's centre there, before anything is moved.
  const Eigen::Vector3d eye = -R.transpose() * t;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d m = model_.points[i].cast<double>();
    const Eigen::Vector3d normal = model_.normals[i].cast<double>();
    if (normal.dot(m - eye) >= 0.0) continue;  // facing away
    const Eigen::Vector3d x = R * m + t;
    if (x.z() <= 0.05) continue;  // behind the camera
    const Eigen::Vector3d nrm = R * normal;
    if (outline && -nrm.dot(x) < cfg_.edge_max_cos * x.norm() &&
        add_edge(lv, outline->grid, x, outline->T.topLeftCorner<3, 3>() * m + outline->T.topRightCorner<3, 1>(), nrm, p.H, p.g))
      ++p.edges;
    int u = 0, v = 0;
    if (!lv.k.nearest_pixel(x, u, v)) continue;
    const float zs = lv.z[static_cast<std::size_t>(v) * lv.k.width_px + u];
    if (!has_depth(zs)) continue;
    if (zs < x.z() - cfg_.occlusion_margin_m) continue;  // something in front of the model: occluded
    ++p.candidates;
    const Eigen::Vector3d q = lv.k.back_project(u, v, zs);
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
    add_weighted_outer(p.H, J, w);
    p.g += w * r * J;
    ++p.used;
  }
  return p;
}

double ProjectiveTracker::descend(const std::vector<Level>& levels, const Outline* outline, const Eigen::Matrix4d& anchor,
                                  double prior, Eigen::Matrix4d& T, int& iterations) const {
  double shift = 0.0;
  for (int l = cfg_.pyramid_levels - 1; l >= 0; --l) {
    const auto li = static_cast<std::size_t>(cfg_.pyramid_levels - 1 - l);  // coarsest first in the config
    const Level& lv = levels[static_cast<std::size_t>(l)];
    const double reach = li == 0 ? std::max(cfg_.max_distance_m, cfg_.coarse_max_distance_m) : cfg_.max_distance_m;
    for (int it = 0; it < cfg_.iterations[li]; ++it) {
      Pass p = pass(lv, cfg_.model_points[li], T, reach, l == 0 ? outline : nullptr);
      ++iterations;
      if (p.used < 6 * 3) break;
      p.H.triangularView<Eigen::Lower>() = p.H.transpose();
      const Eigen::Matrix<double, 6, 6> H_data = p.H;
      add_start_prior(p.H, p.g, T, anchor, prior, model_radius_m_);
      const Eigen::Matrix<double, 6, 1> xi = p.H.ldlt().solve(-p.g);
      if (!xi.allFinite()) break;
      T = twist_to_transform(xi) * T;
      // How far the step moved the surface along its normals (RMS over the correspondences): the data's
      // own measure of still being on the way (a move along a direction it leaves free counts nothing).
      shift = std::sqrt(std::max(0.0, xi.dot(H_data * xi)) / static_cast<double>(p.used));
      if (xi.head<3>().norm() + xi.tail<3>().norm() * model_radius_m_ < cfg_.converged_step_m) break;
    }
  }
  return shift;
}

TrackResult ProjectiveTracker::track(const DepthImage& depth, const Eigen::Matrix4d& T_prev,
                                     const Eigen::Matrix4d* T_hold) const {
  const auto t0 = std::chrono::steady_clock::now();
  if (!T_prev.allFinite()) throw AlignmentError("tracker: previous pose is not finite");
  if (T_hold && !T_hold->allFinite()) throw AlignmentError("tracker: held pose is not finite");
  const std::vector<Level> levels = pyramid(depth);
  // The outline under the start pose (a frame's steps are millimetres), for the finest level's edges.
  std::optional<Outline> outline;
  if (cfg_.edge_weight > 0.0) outline = Outline{outline_grid(T_prev, cfg_.model_points.back()), T_prev};
  const Outline* edges = outline ? &*outline : nullptr;
  TrackResult out;
  Eigen::Matrix4d T = T_prev;
  const double prior = T_hold ? cfg_.hold_prior : cfg_.start_prior;
  double shift = descend(levels, edges, T_hold ? *T_hold : T_prev, prior, T, out.iterations);
  // A descent that ends still moving (a start far along a direction the depth constrains weakly, or the
  // prior holding it back there) goes on from where it got to, the start prior moved there with it.
  for (int round = 0; round < cfg_.extra_descents && shift > cfg_.settled_shift_m; ++round) {
    const Eigen::Matrix4d from = T;
    shift = descend(levels, edges, T_hold ? *T_hold : from, prior, T, out.iterations);
  }
  out.last_shift_m = shift;
  const Pass q = pass(levels[0], cfg_.model_points.back(), T, cfg_.max_distance_m, edges);  // edges: counted
  out.T_camera_target = T;
  out.correspondences = q.used;
  out.edge_points = q.edges;
  out.inlier_ratio = q.candidates > 0 ? static_cast<double>(q.inliers) / static_cast<double>(q.candidates) : 0.0;
  out.rmse_mm =
      q.inliers > 0 ? 1000.0 * std::sqrt(q.inlier_sq / static_cast<double>(q.inliers)) : std::numeric_limits<double>::infinity();
  out.accepted =
      q.used >= cfg_.min_correspondences && out.inlier_ratio >= cfg_.min_inlier_ratio && out.rmse_mm <= cfg_.max_rmse_mm;
  out.time_ms = config::ms_since(t0);
  return out;
}

}  // namespace projbot::alignment
