#include "projbot/alignment/coarse_search.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "projbot/config/angles.hpp"

namespace projbot::alignment {

namespace {

// Up to `count` of the model's points, spread evenly over its sample order, with their normals.
struct Samples {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> normals;
};

Samples spread_samples(const ModelCloud& model, std::size_t count) {
  Samples s;
  const std::size_t n = model.points.size();
  const std::size_t stride = std::max<std::size_t>(1, n / std::max<std::size_t>(count, 1));
  for (std::size_t i = 0; i < n && model.normals.size() == n; i += stride) {
    s.points.push_back(model.points[i].cast<double>());
    s.normals.push_back(model.normals[i].cast<double>());
  }
  return s;
}

// The samples that face the camera with the model at T, in the camera frame.
std::vector<Eigen::Vector3d> facing(const Samples& s, const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Eigen::Vector3d p = R * s.points[i] + t;
    if ((R * s.normals[i]).dot(p) < 0.0) out.push_back(p);
  }
  return out;
}

// The score of `seen` (camera-facing samples, camera frame) moved by `move` (see CoarseCandidate).
double score(const std::vector<Eigen::Vector3d>& seen, const Eigen::Vector3d& move, const DepthImage& depth,
             const CameraIntrinsics& k, double step_m) {
  if (seen.empty()) return -2.0;
  int agree = 0, behind = 0, u = 0, v = 0;
  for (const auto& s : seen) {
    const Eigen::Vector3d p = s + move;
    if (!(p.z() > 0.0) || !k.nearest_pixel(p, u, v)) continue;
    const float measured = depth.at(u, v);
    if (!has_depth(measured)) continue;
    const double tolerance = step_m + 0.0025 * p.z() * p.z();
    if (measured > p.z() + tolerance)
      ++behind;
    else if (measured >= p.z() - tolerance)
      ++agree;
  }
  return (agree - 2.0 * behind) / static_cast<double>(seen.size());
}

// The turns about the camera axes through `centre` that the search tries (the identity first).
std::vector<Eigen::Matrix4d> turns_about(const Eigen::Vector3d& centre, double turn_deg) {
  std::vector<Eigen::Matrix4d> turns{Eigen::Matrix4d::Identity()};
  if (turn_deg <= 0.0) return turns;
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) {
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      T.topLeftCorner<3, 3>() =
          Eigen::AngleAxisd(sign * config::radians(turn_deg), Eigen::Vector3d::Unit(axis)).toRotationMatrix();
      T.topRightCorner<3, 1>() = centre - T.topLeftCorner<3, 3>() * centre;
      turns.push_back(T);
    }
  return turns;
}

// The moves within reach on the grid (the zero move included).
std::vector<Eigen::Vector3d> grid_moves(double reach_m, double step_m) {
  std::vector<Eigen::Vector3d> moves;
  const int n = static_cast<int>(std::floor(reach_m / step_m));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int l = -n; l <= n; ++l) {
        const Eigen::Vector3d m = step_m * Eigen::Vector3d(i, j, l);
        if (m.norm() <= reach_m + 1e-9) moves.push_back(m);
      }
  return moves;
}

// The best `count` of `all` (best first) whose centres lie `separation` apart.
std::vector<CoarseCandidate> separated(std::vector<std::pair<CoarseCandidate, Eigen::Vector3d>> all, std::size_t count,
                                       double separation) {
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first.score > b.first.score; });
  std::vector<CoarseCandidate> out;
  std::vector<Eigen::Vector3d> centres;
  for (const auto& [c, centre] : all) {
    if (out.size() >= count || c.score <= 0.0) break;
    const bool apart =
        std::all_of(centres.begin(), centres.end(), [&](const auto& o) { return (o - centre).norm() >= separation; });
    if (!apart) continue;
    out.push_back(c);
    centres.push_back(centre);
  }
  return out;
}

}  // namespace

std::vector<CoarseCandidate> coarse_candidates(const ModelCloud& model, const Eigen::Matrix4d& T_guess, const DepthImage& depth,
                                               const CameraIntrinsics& k, const CoarseSearch& search) {
  if (depth.width != k.width_px || depth.height != k.height_px || !T_guess.allFinite() || !(search.step_m > 0.0)) return {};
  const double step = search.grid_step_m();
  const Samples samples = spread_samples(model, search.samples);
  const Eigen::Vector3d centre = (T_guess * centroid_of(model).homogeneous()).head<3>();
  const std::vector<Eigen::Vector3d> moves = grid_moves(search.reach_m, step);
  std::vector<std::pair<CoarseCandidate, Eigen::Vector3d>> best;  // per move, the best turn
  best.reserve(moves.size());
  for (const auto& m : moves) best.push_back({CoarseCandidate{T_guess, -3.0}, centre + m});
  for (const auto& turn : turns_about(centre, search.turn_deg)) {
    const Eigen::Matrix4d T = turn * T_guess;
    const std::vector<Eigen::Vector3d> seen = facing(samples, T);
    for (std::size_t i = 0; i < moves.size(); ++i) {
      const double s = score(seen, moves[i], depth, k, step);
      if (s <= best[i].first.score) continue;
      best[i].first.score = s;
      best[i].first.T_camera_model = T;
      best[i].first.T_camera_model.topRightCorner<3, 1>() += moves[i];
    }
  }
  return separated(std::move(best), search.count, search.separation_m);
}

}  // namespace projbot::alignment
