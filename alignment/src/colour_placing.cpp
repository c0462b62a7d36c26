// Colour's placing (issue 41): how well a model's colours agree with the colour image at a pose, and the
// slide along the surface that the depth leaves free and the colours pin.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "front_samples.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/angles.hpp"

namespace projbot::alignment {

using detail::nearest_samples;

namespace {

// The samples colour_agreement compares: camera-frame points and their luminance, seen at a pose.
struct ColourSamples {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> luminance;
};

double luminance(double r, double g, double b) { return 0.299 * r + 0.587 * g + 0.114 * b; }

ColourSamples seen_colours(const ModelCloud& model, const Eigen::Matrix4d& T, const DepthImage& depth,
                           const assets::Image& colour, const CameraIntrinsics& k) {
  ColourSamples s;
  if (model.colours.size() != model.points.size() || !T.allFinite() || depth.width != k.width_px || depth.height != k.height_px ||
      colour.width != k.width_px || colour.height != k.height_px)
    return s;
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  const auto nearest = nearest_samples(model, T, k);
  // Measured within 2 cm of the sample: not hidden, and on the same surface.
  const auto near = [&](int u, int v, float z) {
    if (u < 0 || v < 0 || u >= depth.width || v >= depth.height) return false;
    const float measured = depth.at(u, v);
    return measured > 0.0F && std::abs(measured - z) <= 0.02F;
  };
  constexpr int kRim = 2;  // pixels: the image's colour there mixes the target's with what lies behind
  for (std::size_t pixel = 0; pixel < nearest.size(); ++pixel) {
    const auto& [z, i] = nearest[pixel];
    const int u = static_cast<int>(pixel % depth.width), v = static_cast<int>(pixel / depth.width);
    if (!std::isfinite(z) || !near(u, v, z) || !near(u - kRim, v, z) || !near(u + kRim, v, z) || !near(u, v - kRim, z) ||
        !near(u, v + kRim, z))
      continue;
    const Eigen::Vector3f& c = model.colours[i];
    s.points.push_back(R * model.points[i].cast<double>() + t);
    s.luminance.push_back(luminance(c.x(), c.y(), c.z()));
  }
  return s;
}

// The image's luminance (0..1) at a sub-pixel position, bilinear; NaN outside.
double image_luminance(const assets::Image& im, double x, double y) {
  if (!(x >= 0.0 && y >= 0.0 && x <= im.width - 1.0 && y <= im.height - 1.0)) return std::nan("");
  const int x0 = std::min(static_cast<int>(x), im.width - 2), y0 = std::min(static_cast<int>(y), im.height - 2);
  const double fx = x - x0, fy = y - y0;
  const auto at = [&](int u, int v) {
    const std::uint8_t* p = im.pixel(u, v);
    return luminance(p[0], p[1], p[2]) / 255.0;
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) + fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

// A small rigid move of the samples: turned by `turn` about `centre`, then shifted.
struct SampleMove {
  Eigen::Matrix3d turn = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  Eigen::Vector3d operator()(const Eigen::Vector3d& p) const { return turn * (p - centre) + centre + shift; }
};

// Pearson correlation of the samples' luminance with the image's where they land moved by `move`.
double correlation(const ColourSamples& s, const assets::Image& im, const CameraIntrinsics& k, const SampleMove& move) {
  double n = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Eigen::Vector3d p = move(s.points[i]);
    const Eigen::Vector2d x = k.project(p);
    const double b = image_luminance(im, x.x(), x.y());
    if (!std::isfinite(b)) continue;
    const double a = s.luminance[i];
    n += 1, sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
  }
  if (n < static_cast<double>(kMinColourSamples)) return std::nan("");
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (!(va > 1e-6 * n && vb > 1e-6 * n)) return std::nan("");  // no contrast on one side
  return (sab - sa * sb / n) / std::sqrt(va * vb);
}

}  // namespace

double colour_agreement(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                        const assets::Image& colour, const CameraIntrinsics& k) {
  return correlation(seen_colours(model, T_camera_model, depth, colour, k), colour, k, SampleMove{});
}

ColourRefinement colour_refined(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const assets::Image& colour, const CameraIntrinsics& k, double reach_m, double step_m,
                                double min_gain) {
  ColourRefinement out;
  out.T_camera_model = T_camera_model;
  const ColourSamples seen = seen_colours(model, T_camera_model, depth, colour, k);
  out.agreement_before = out.agreement_after = correlation(seen, colour, k, SampleMove{});
  if (!std::isfinite(out.agreement_before) || !(step_m > 0.0) || !(reach_m >= step_m)) return out;
  // The plane of the two weakest slides (a box face-on: its face's plane), orthonormal, and the weakest
  // turn (the same box turned about its face's normal: only its edges hold it, and the footing's
  // tolerance lets a degree through).
  std::vector<Eigen::Vector3d> axes;
  Eigen::Vector3d turn_axis = Eigen::Vector3d::Zero();
  for (const WeakDirection& d : view_constraints(model, T_camera_model, k).all) {
    if (!d.is_slide()) {
      if (turn_axis.isZero()) turn_axis = d.rotation.normalized();
      continue;
    }
    if (axes.size() == 2) continue;
    Eigen::Vector3d a = d.translation;
    for (const auto& b : axes) a -= a.dot(b) * b;
    if (a.norm() > 0.3) axes.push_back(a.normalized());
  }
  if (axes.size() < 2) return out;
  SampleMove best_move;
  for (const auto& p : seen.points) best_move.centre += p / static_cast<double>(seen.points.size());
  double best = out.agreement_before;
  const auto consider = [&](const SampleMove& m) {
    const double c = correlation(seen, colour, k, m);
    if (std::isfinite(c) && c > best) best = c, best_move = m;
  };
  const auto slide = [&](double reach, double step) {
    const SampleMove from = best_move;
    const int n = static_cast<int>(std::lround(reach / step));
    for (int i = -n; i <= n; ++i)
      for (int j = -n; j <= n; ++j) {
        SampleMove m = from;
        m.shift += i * step * axes[0] + j * step * axes[1];
        consider(m);
      }
  };
  const auto turn = [&](double reach_deg, double step_deg) {
    if (turn_axis.isZero()) return;
    const SampleMove from = best_move;
    const int n = static_cast<int>(std::lround(reach_deg / step_deg));
    for (int i = -n; i <= n; ++i) {
      SampleMove m = from;
      m.turn = Eigen::AngleAxisd(i * config::radians(step_deg), turn_axis).toRotationMatrix() * from.turn;
      consider(m);
    }
  };
  // Coarse to fine: 2 steps, then half a step, then a quarter around the best so far (139 agreements
  // at the defaults instead of the 370 of a full grid of steps and quarter steps: the acquisition's
  // colour took 80-100 ms on the shop's duck and box). Then the weakest turn, and the slide once more.
  // A best on the coarse grid's rim may lie past it (ICP left the face-on box 10 mm along its face and
  // the agreement there was 0.47): the grid moves there, up to twice.
  bool on_rim = true;
  for (int more = 0; more < 3 && on_rim; ++more) {
    const Eigen::Vector3d from = best_move.shift;
    slide(reach_m, 2.0 * step_m);
    const Eigen::Vector3d moved = best_move.shift - from;
    on_rim = std::max(std::abs(moved.dot(axes[0])), std::abs(moved.dot(axes[1]))) >= reach_m - step_m;
  }
  slide(1.5 * step_m, step_m / 2.0);
  slide(step_m / 4.0, step_m / 4.0);
  turn(kColourTurnReachDeg, kColourTurnReachDeg / 8.0);
  turn(kColourTurnReachDeg / 16.0, kColourTurnReachDeg / 32.0);
  slide(step_m / 2.0, step_m / 4.0);
  if (!(best >= out.agreement_before + min_gain)) return out;
  const Eigen::Matrix3d R = T_camera_model.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_camera_model.topRightCorner<3, 1>();
  out.T_camera_model.topLeftCorner<3, 3>() = best_move.turn * R;
  out.T_camera_model.topRightCorner<3, 1>() = best_move(t);
  out.shift_m = best_move.shift;
  out.turn_deg = config::degrees(Eigen::AngleAxisd(best_move.turn).angle());
  out.agreement_after = best;
  out.out_of_reach = on_rim;
  return out;
}

bool has_colour_contrast(const ModelCloud& model) {
  double n = 0, sum = 0, sum2 = 0;
  for (const Eigen::Vector3f& c : model.colours) {
    const double l = luminance(c.x(), c.y(), c.z());
    n += 1, sum += l, sum2 += l * l;
  }
  return n >= static_cast<double>(kMinColourSamples) && sum2 - sum * sum / n > 1e-6 * n;  // as correlation()'s test
}

}  // namespace projbot::alignment
