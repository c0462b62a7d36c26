#include "projbot/alignment/verification.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "front_samples.hpp"
#include "projbot/alignment/equations.hpp"

namespace projbot::alignment {

namespace detail {

// The nearest front-facing model sample per pixel under T_camera_model: (depth, sample index), +inf
// where none lands.
std::vector<std::pair<float, std::size_t>> nearest_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model,
                                                           const CameraIntrinsics& k) {
  std::vector<std::pair<float, std::size_t>> nearest(static_cast<std::size_t>(k.width_px) * k.height_px,
                                                     {std::numeric_limits<float>::infinity(), 0});
  for_each_front_sample(model, T_camera_model, k, [&](float z, int u, int v, std::size_t i) {
    auto& best = nearest[static_cast<std::size_t>(v) * k.width_px + u];
    if (z < best.first) best = {z, i};
  });
  return nearest;
}

}  // namespace detail

using detail::for_each_front_sample;
using detail::nearest_samples;

namespace {

// The predicted depth image: nearest front-facing model sample per pixel, +inf where none lands; `box`
// gets the pixel bounds of what landed (x0, y0, x1, y1, inclusive). Depth only: it runs on every
// tracked frame, where the (depth, index) image of nearest_samples cost three times the memory.
std::vector<float> predicted_depth(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k,
                                   std::array<int, 4>& box) {
  box = {k.width_px, k.height_px, -1, -1};
  std::vector<float> z_buffer(static_cast<std::size_t>(k.width_px) * k.height_px, std::numeric_limits<float>::infinity());
  for_each_front_sample(model, T_camera_model, k, [&](float z, int u, int v, std::size_t) {
    float& best = z_buffer[static_cast<std::size_t>(v) * k.width_px + u];
    if (z >= best) return;
    best = z;
    box = {std::min(box[0], u), std::min(box[1], v), std::max(box[2], u), std::max(box[3], v)};
  });
  return z_buffer;
}

// Whether two neighbouring depths lie on one surface: within the Kinect's step and noise at their range
// (4 cm at 2 m), beyond which they are one thing in front of another.
bool continuous(float a, float b) {
  const float z = std::max(a, b);
  return std::abs(a - b) <= 0.02F + 0.005F * z * z;
}

// Clustering where neighbours touch the crop: the crop holds the whole target wherever the guess's
// uncertainty allows, so a surface that runs on past its edge and lies mostly outside the model's
// silhouette at the guess is something else (a vase beside the duck, a shelf beside the figure's hand).
// Its pixels are cleared from `out`; `in` is the depth before cropping, `mask` the grown silhouette
// and `core` the silhouette itself (dilated over the samples' gaps).
void drop_cut_neighbours(DepthImage& out, const DepthImage& in, const std::vector<unsigned char>& mask,
                         const std::vector<unsigned char>& core) {
  const int w = out.width, h = out.height;
  std::vector<unsigned char> seen(out.depth_m.size(), 0);
  std::vector<std::size_t> stack, members;
  for (std::size_t seed = 0; seed < out.depth_m.size(); ++seed) {
    if (!(out.depth_m[seed] > 0.0F) || seen[seed]) continue;
    seen[seed] = 1;
    stack.assign(1, seed);
    members.clear();
    bool cut = false;
    std::size_t in_core = 0;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      members.push_back(i);
      in_core += core[i];
      const int x = static_cast<int>(i % static_cast<std::size_t>(w)), y = static_cast<int>(i / static_cast<std::size_t>(w));
      const float z = out.depth_m[i];
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const std::size_t j = static_cast<std::size_t>(ny) * w + nx;
          if (!mask[j]) {  // past the crop's edge: does the surface go on there?
            cut = cut || (in.depth_m[j] > 0.0F && continuous(z, in.depth_m[j]));
            continue;
          }
          if (seen[j] || !(out.depth_m[j] > 0.0F) || !continuous(z, out.depth_m[j])) continue;
          seen[j] = 1;
          stack.push_back(j);
        }
    }
    if (cut && in_core * 4 < members.size())
      for (const std::size_t i : members) out.depth_m[i] = 0.0F;
  }
}

// The silhouette: the predicted pixels closed over the gaps between the model's samples (gap_px pixels),
// within `box` grown by gap_px.
std::vector<unsigned char> silhouette_of(const std::vector<float>& predicted, const std::array<int, 4>& box, int w, int h,
                                         int gap_px) {
  std::vector<unsigned char> grown(predicted.size(), 0), mask(predicted.size(), 0);
  const auto index = [w](int x, int y) { return static_cast<std::size_t>(y) * w + x; };
  for (int y = box[1]; y <= box[3]; ++y)
    for (int x = box[0]; x <= box[2]; ++x)
      if (std::isfinite(predicted[index(x, y)]))
        for (int dy = std::max(0, y - gap_px); dy <= std::min(h - 1, y + gap_px); ++dy)
          for (int dx = std::max(0, x - gap_px); dx <= std::min(w - 1, x + gap_px); ++dx) grown[index(dx, dy)] = 1;
  // Eroded back: a pixel stays where every pixel within gap_px was reached.
  for (int y = std::max(0, box[1] - gap_px); y <= std::min(h - 1, box[3] + gap_px); ++y)
    for (int x = std::max(0, box[0] - gap_px); x <= std::min(w - 1, box[2] + gap_px); ++x) {
      bool all = true;
      for (int dy = -gap_px; dy <= gap_px && all; ++dy)
        for (int dx = -gap_px; dx <= gap_px && all; ++dx) {
          const int xx = x + dx, yy = y + dy;
          all = xx >= 0 && yy >= 0 && xx < w && yy < h && grown[index(xx, yy)];
        }
      mask[index(x, y)] = all ? 1 : 0;
    }
  return mask;
}

// The model's depth at or next to outline pixel (x, y): the nearest predicted within 2 pixels.
float edge_depth(const std::vector<float>& predicted, int x, int y, int w, int h) {
  float z = std::numeric_limits<float>::infinity();
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const int xx = x + dx, yy = y + dy;
      if (xx >= 0 && yy >= 0 && xx < w && yy < h) z = std::min(z, predicted[static_cast<std::size_t>(yy) * w + xx]);
    }
  return z;
}

// check_free_space's outline counts: from each outline pixel outwards (each side the silhouette ends),
// the first measurement 2 to 5 pixels beyond twice the samples' spacing, past the band of mixed pixels at
// depth steps (bench sensor).
void check_outline(const std::vector<float>& predicted, const std::array<int, 4>& box, const DepthImage& depth,
                   const CameraIntrinsics& k, FreeSpaceCheck& c) {
  if (box[2] < 0) return;
  const int w = k.width_px, h = k.height_px;
  // The samples' spacing in pixels (1 / sqrt of the share of the silhouette's pixels they land on): the
  // silhouette is closed over twice that, and its edge may lie that far past the outermost sample, so
  // the probe starts beyond it.
  std::vector<unsigned char> mask = silhouette_of(predicted, box, w, h, 2);
  std::size_t hit = 0, area = 0;
  for (int y = box[1]; y <= box[3]; ++y)
    for (int x = box[0]; x <= box[2]; ++x)
      if (mask[static_cast<std::size_t>(y) * w + x])
        ++area, hit += std::isfinite(predicted[static_cast<std::size_t>(y) * w + x]) ? 1 : 0;
  if (hit == 0) return;
  const int gap = static_cast<int>(std::lround(2.0 * std::sqrt(static_cast<double>(area) / static_cast<double>(hit))));
  if (gap > 2) mask = silhouette_of(predicted, box, w, h, gap);
  const auto inside = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && mask[static_cast<std::size_t>(y) * w + x];
  };
  const int first = 2 + gap, last = first + 3;
  for (int y = box[1]; y <= box[3]; ++y)
    for (int x = box[0]; x <= box[2]; ++x) {
      if (!inside(x, y)) continue;
      for (const auto& [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
        if (inside(x + dx, y + dy)) continue;
        const float z = edge_depth(predicted, x, y, w, h);
        if (!std::isfinite(z)) continue;
        // Only where the ray stays outside all the way: a gap between the model's samples or a narrow
        // gap between its parts (a mug's handle) is no outline. A probe counts only with the silhouette
        // `gap` pixels away across the ray too (a ray along a ragged edge runs beside the model).
        const auto clear = [&](int xx, int yy) {
          for (int s = -gap; s <= gap; ++s)
            if (inside(xx + s * dy, yy + s * dx)) return false;
          return true;
        };
        float measured = 0.0F;
        bool outline = true, probed = false;
        for (int o = 1; o <= last && outline; ++o) {
          const int xx = x + o * dx, yy = y + o * dy;
          outline = xx >= 0 && yy >= 0 && xx < w && yy < h && !inside(xx, yy);
          if (!outline || o < first || has_depth(measured) || !clear(xx, yy)) continue;
          probed = true;
          measured = depth.at(xx, yy);
        }
        if (!outline || !probed) continue;
        const float tolerance = 0.015F + 0.005F * z * z;
        if (!has_depth(measured))
          ++c.outline_missing;
        else if (measured > z + tolerance)
          ++c.outline_step;
        else if (measured < z - tolerance)
          ++c.outline_front;
        else
          ++c.outline_flush;
      }
    }
}

}  // namespace

DepthImage crop_to_silhouette(const DepthImage& depth, const CameraIntrinsics& k, const ModelCloud& model,
                              const Eigen::Matrix4d& T_camera_model, double grow_m, bool cluster) {
  DepthImage out = depth;
  if (depth.width != k.width_px || depth.height != k.height_px || !T_camera_model.allFinite()) return out;
  std::array<int, 4> box{};
  const std::vector<float> predicted = predicted_depth(model, T_camera_model, k, box);
  if (box[2] < 0) {  // nothing of the model in view: nothing to keep
    std::fill(out.depth_m.begin(), out.depth_m.end(), 0.0F);
    return out;
  }
  float z_near = std::numeric_limits<float>::infinity(), z_far = 0.0F;
  for (const float z : predicted)
    if (std::isfinite(z)) z_near = std::min(z_near, z), z_far = std::max(z_far, z);
  // Grown by grow_m at the model's nearest depth, in pixels; then a box dilation, rows then columns.
  const int r = static_cast<int>(std::ceil(grow_m * std::max(k.fx_px, k.fy_px) / std::max(z_near, 0.1F))) + 1;
  const int w = k.width_px, h = k.height_px;
  std::vector<unsigned char> rows(predicted.size(), 0), mask(predicted.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::isfinite(predicted[static_cast<std::size_t>(y) * w + x]))
        for (int dx = std::max(0, x - r); dx <= std::min(w - 1, x + r); ++dx) rows[static_cast<std::size_t>(y) * w + dx] = 1;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (rows[static_cast<std::size_t>(y) * w + x])
        for (int dy = std::max(0, y - r); dy <= std::min(h - 1, y + r); ++dy) mask[static_cast<std::size_t>(dy) * w + x] = 1;
  const auto lo = static_cast<float>(z_near - grow_m), hi = static_cast<float>(z_far + grow_m);
  for (std::size_t i = 0; i < out.depth_m.size(); ++i)
    if (!mask[i] || !(out.depth_m[i] >= lo && out.depth_m[i] <= hi)) out.depth_m[i] = 0.0F;
  if (!cluster) return out;
  // The silhouette itself, over the gaps between the model's samples (2 pixels).
  std::vector<unsigned char> core(predicted.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (std::isfinite(predicted[static_cast<std::size_t>(y) * w + x]))
        for (int dy = std::max(0, y - 2); dy <= std::min(h - 1, y + 2); ++dy)
          for (int dx = std::max(0, x - 2); dx <= std::min(w - 1, x + 2); ++dx) core[static_cast<std::size_t>(dy) * w + dx] = 1;
  drop_cut_neighbours(out, depth, mask, core);
  return out;
}

double guess_reach_m(const ModelCloud& model, double translation_m, double rotation_deg) {
  double radius = 0.0;
  for (const auto& p : model.points) radius = std::max(radius, static_cast<double>(p.norm()));
  return translation_m + 2.0 * std::sin(std::min(rotation_deg, 180.0) * M_PI / 360.0) * radius;
}

FreeSpaceCheck check_free_space(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const CameraIntrinsics& k, bool outline) {
  FreeSpaceCheck c;
  if (depth.width != k.width_px || depth.height != k.height_px || !T_camera_model.allFinite()) return c;
  std::array<int, 4> box{};
  const std::vector<float> predicted = predicted_depth(model, T_camera_model, k, box);
  const auto at = [&](int x, int y) { return predicted[static_cast<std::size_t>(y) * k.width_px + x]; };
  if (outline) check_outline(predicted, box, depth, k, c);
  constexpr int kRim = 2;  // pixels of the silhouette's rim left out
  const int x0 = std::max(box[0], kRim), x1 = std::min(box[2], k.width_px - 1 - kRim);
  const int y0 = std::max(box[1], kRim), y1 = std::min(box[3], k.height_px - 1 - kRim);
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const float z = at(x, y);
      if (!std::isfinite(z)) continue;
      // Interior only: the model covers the pixels kRim away on each side (sparse samples leave holes,
      // so a neighbour counts when any pixel near it is covered).
      bool interior = true;
      for (const auto& [dx, dy] : {std::pair{-kRim, 0}, {kRim, 0}, {0, -kRim}, {0, kRim}})
        interior = interior && (std::isfinite(at(x + dx, y + dy)) || std::isfinite(at(x + dx / 2, y + dy / 2)));
      if (!interior) continue;
      const float measured = depth.at(x, y);
      if (!has_depth(measured)) continue;
      ++c.predicted;
      const float tolerance = 0.015F + 0.005F * z * z;
      if (measured > z + tolerance)
        ++c.behind;
      else if (measured < z - tolerance)
        ++c.in_front;
      else
        ++c.agree;
    }
  return c;
}

namespace {

// Where points lie: their centre and RMS radius about it. The point-to-plane Jacobian of a point with
// normal n, [n, (p - centre) x n / radius] (translation, then rotation about the centre scaled by the
// radius), makes translations and rotations comparable.
struct Spread {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 1e-3;
  Eigen::Matrix<double, 6, 1> jacobian(const Eigen::Vector3d& p, const Eigen::Vector3d& n) const {
    Eigen::Matrix<double, 6, 1> J;
    J << n, (p - centre).cross(n) / radius;
    return J;
  }
};

// The spread of point(e) over `items`.
template <class Items, class Point>
Spread spread(const Items& items, Point point) {
  Spread s;
  for (const auto& e : items) s.centre += point(e);
  const double n = static_cast<double>(std::max<std::size_t>(items.size(), 1));
  s.centre /= n;
  double r2 = 0.0;
  for (const auto& e : items) r2 += (point(e) - s.centre).squaredNorm();
  s.radius = std::max(std::sqrt(r2 / n), 1e-3);
  return s;
}

}  // namespace

StrongStep strong_point_to_plane_step(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                                      const std::vector<double>& distances) {
  StrongStep out;
  if (points.size() < 6 || normals.size() != points.size() || distances.size() != points.size()) return out;
  const Spread s = spread(points, [](const Eigen::Vector3d& p) { return p; });
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Matrix<double, 6, 1> J = s.jacobian(points[i], normals[i]);
    H += J * J.transpose();
    g += J * distances[i];
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H);
  const double largest = eig.eigenvalues()(5);
  Eigen::Matrix<double, 6, 1> y = Eigen::Matrix<double, 6, 1>::Zero();
  for (int i = 0; i < 6; ++i) {
    if (!(largest > 0.0 && eig.eigenvalues()(i) >= kWeakStrength * largest)) {
      ++out.held;
      continue;
    }
    y += eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(g) / eig.eigenvalues()(i));
  }
  if (!y.allFinite()) return out;
  // p -> R (p - centre) + centre + t, R the turn by w (linearised: p + t + w x (p - centre)).
  const Eigen::Vector3d w = y.tail<3>() / s.radius;
  const double angle = w.norm();
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (angle > 0.0) R = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
  out.T.topLeftCorner<3, 3>() = R;
  out.T.topRightCorner<3, 1>() = y.head<3>() + s.centre - R * s.centre;
  return out;
}

ViewConstraints view_constraints(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k) {
  ViewConstraints c;
  if (!T_camera_model.allFinite() || model.normals.size() != model.points.size()) return c;
  // The nearest front-facing sample per pixel: what one scan can measure, one point per pixel (a face
  // seen at a grazing angle has many samples but few pixels).
  const Eigen::Matrix3d R = T_camera_model.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_camera_model.topRightCorner<3, 1>();
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> seen;  // point, normal (camera frame)
  for (const auto& [z, i] : nearest_samples(model, T_camera_model, k))
    if (std::isfinite(z))
      seen.emplace_back(R * model.points[i].cast<double>() + t, (R * model.normals[i].cast<double>()).normalized());
  c.points = seen.size();
  if (seen.size() < 6) return c;
  const Spread s = spread(seen, [](const auto& point_normal) { return point_normal.first; });
  c.centre = s.centre;
  c.radius = s.radius;
  Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();
  for (const auto& [p, n] : seen) {
    const Eigen::Matrix<double, 6, 1> J = s.jacobian(p, n);
    H += J * J.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(H);
  const double largest = std::max(eig.eigenvalues()(5), 1e-12);
  for (int i = 0; i < 6; ++i) {
    c.strength[static_cast<std::size_t>(i)] = eig.eigenvalues()(i) / largest;
    const Eigen::Matrix<double, 6, 1> d = eig.eigenvectors().col(i);
    c.all.push_back({d.head<3>(), d.tail<3>(), c.strength[static_cast<std::size_t>(i)]});
    if (c.strength[static_cast<std::size_t>(i)] < ViewConstraints::kWeak) c.weak.push_back(c.all.back());
  }
  return c;
}

bool looks_alike(const ModelCloud& model, const Eigen::Matrix4d& T_model_model, const std::vector<std::size_t>& probes,
                 const NearestPoints* samples) {
  const std::size_t n = model.points.size();
  // Without colours that vary, every slide along the model's own surface would look alike: the shop's
  // plain figure, slid 10-20 mm by PCL's ICP, would pass. Such a model's content is where its shape is.
  if (n < 2 || !T_model_model.allFinite() || !has_colour_contrast(model)) return false;
  std::optional<NearestPoints> built;
  if (!samples || samples->size() != n) samples = &built.emplace(model.points);
  std::vector<std::size_t> spread;
  if (probes.empty())
    for (std::size_t i = 0; i < n; i += std::max<std::size_t>(1, n / 300)) spread.push_back(i);
  const std::vector<std::size_t>& at = probes.empty() ? spread : probes;
  const Eigen::Matrix3f R = T_model_model.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = T_model_model.topRightCorner<3, 1>().cast<float>();
  double own_d = 0, own_c = 0, moved_d = 0, moved_c = 0;
  for (const std::size_t i : at) {
    if (i >= n) return false;
    const Eigen::Vector3f& p = model.points[i];
    const std::size_t own = samples->nearest(p, i);
    const Eigen::Vector3f q = R * p + t;
    const std::size_t moved = samples->nearest(q, n);
    if (own >= n || moved >= n) return false;
    own_d += (model.points[own] - p).norm();
    moved_d += (model.points[moved] - q).norm();
    own_c += (model.colours[own] - model.colours[i]).norm();
    moved_c += (model.colours[moved] - model.colours[i]).norm();
  }
  // Margins: the moved points are anywhere between samples, the probes' own neighbours are samples.
  return moved_d <= 1.5 * own_d && moved_c <= 1.5 * own_c + 0.02 * static_cast<double>(at.size());
}

std::vector<std::size_t> visible_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                         const CameraIntrinsics& k, std::size_t max) {
  std::vector<std::size_t> seen;
  if (depth.width != k.width_px || depth.height != k.height_px || !T_camera_model.allFinite()) return seen;
  for_each_front_sample(model, T_camera_model, k, [&](float z, int u, int v, std::size_t i) {
    const float measured = depth.at(u, v);
    if (std::isfinite(measured) && std::abs(measured - z) < 0.01F) seen.push_back(i);
  });
  if (seen.size() <= max) return seen;
  std::vector<std::size_t> spread;
  for (std::size_t j = 0; j < max; ++j) spread.push_back(seen[j * seen.size() / max]);
  return spread;
}

std::vector<Eigen::Matrix4d> box_turns(const ModelCloud& model) {
  if (model.points.empty()) return {};
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f& p : model.points) box.extend(p);
  const Eigen::Vector3d centre = box.center().cast<double>();
  // A cube's rotations are the signed permutation matrices with determinant +1.
  std::vector<Eigen::Matrix4d> turns;
  std::array<int, 3> axis{0, 1, 2};
  do {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d R = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) R(r, axis[static_cast<std::size_t>(r)]) = (signs >> r) & 1 ? -1.0 : 1.0;
      if (R.determinant() < 0.0 || R.isIdentity()) continue;
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      T.topLeftCorner<3, 3>() = R;
      T.topRightCorner<3, 1>() = centre - R * centre;
      turns.push_back(T);
    }
  } while (std::next_permutation(axis.begin(), axis.end()));
  return turns;
}

Eigen::Matrix4d nearest_look_alike(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const Eigen::Matrix4d& prior,
                                   const std::vector<Eigen::Matrix4d>& turns, const DepthImage& depth, const CameraIntrinsics& k,
                                   double margin_deg, const NearestPoints* samples) {
  const auto off_deg = [&](const Eigen::Matrix4d& T) { return rotation_angle_deg(rigid_inverse(prior) * T); };
  Eigen::Matrix4d best = T_camera_model;
  double best_deg = off_deg(T_camera_model) - margin_deg;
  std::vector<std::size_t> seen;  // looked for only when a turn would be nearer the prior
  std::optional<NearestPoints> built;
  for (const Eigen::Matrix4d& turn : turns) {
    const Eigen::Matrix4d candidate = T_camera_model * turn;
    const double deg = off_deg(candidate);
    if (!(deg < best_deg)) continue;
    if (seen.empty()) seen = visible_samples(model, T_camera_model, depth, k, 100);
    if (seen.empty()) break;
    if (!samples || samples->size() != model.points.size()) samples = &built.emplace(model.points);
    // The candidate draws model point turn * p where T draws p: the content it puts on the seen surfaces
    // is T's where the model turned back onto itself looks alike there.
    if (!looks_alike(model, rigid_inverse(turn), seen, samples)) continue;
    best = candidate;
    best_deg = deg;
  }
  return best;
}

}  // namespace projbot::alignment
