// The twin's tour: how its projector frames are measured (tour_frames.hpp).

#include "tour_frames.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/motion_model.hpp"
#include "projbot/engine/frame_profiler.hpp"

namespace projbot::twin::detail {

namespace {

// One projector frame of a neighbour: counted, and its error added when it was lit and measured.
void count_frame(NeighbourLight& n, double mean_mm) {
  ++n.report.frames;
  if (!n.shown) return;
  ++n.report.lit_frames;
  if (std::isnan(mean_mm)) return;
  n.report.far_off.count(mean_mm);
  n.sum_mm += mean_mm;
  n.report.worst_mm = n.measured == 0 ? mean_mm : std::max(n.report.worst_mm, mean_mm);
  ++n.measured;
}

}  // namespace

std::pair<double, double> guess_error(const robot::HeadPoses& truth, const TwinTarget& t, const Eigen::Matrix4d& guess) {
  const Eigen::Matrix4d T_camera_true = alignment::rigid_inverse(truth.T_world_camera.matrix()) * t.T_world_target_true;
  const Eigen::Matrix4d error = alignment::rigid_inverse(T_camera_true) * guess;
  return {100.0 * alignment::translation_norm_m(error), alignment::rotation_angle_deg(error)};
}

NeighbourReport finished(const NeighbourLight& l) {
  NeighbourReport r = l.report;
  r.lit_mean_mm = l.measured > 0 ? l.sum_mm / l.measured : std::nan("");
  return r;
}

Eigen::Matrix4d light_pose(const live::DrawnPose* drawn, const alignment::PoseSample& last_lit, double display_s, bool predict) {
  if (drawn) return drawn->T_camera_target;
  return predict ? alignment::predict_pose(last_lit.motion, display_s) : last_lit.T_camera_target;
}

TimelineSample measure_frame(const DwellContext& c, const VisitReport& r, double display_s, const live::DrawnPose* drawn,
                             const alignment::PoseSample& last_lit) {
  TwinTarget& target = c.twin.targets()[c.target];
  target.T_world_target_true = c.twin.scripted_pose(c.target, r.target_visit, display_s);
  target.in_world = c.twin.scripted_presence(c.target, r.target_visit, display_s);
  const config::TargetMotion* motion = target.config.motion_on(r.target_visit);
  TimelineSample s;
  s.t_s = display_s;
  s.shown = drawn != nullptr;
  s.moving = motion && motion->moving_at(display_s);
  s.age_ms = 1000.0 * (display_s - (drawn ? drawn->capture_s : last_lit.capture_time_s));
  s.in_world = target.in_world;
  const double captured_s = display_s - 0.001 * s.age_ms;
  // A capture at the change's instant shows the target where it was: it moves from just after start_s.
  const auto between = [&](double t) { return t >= captured_s - 1e-6 && t <= display_s; };
  s.change_unseen = motion && (between(motion->start_s) || between(motion->end_s()));
  const Eigen::Matrix4d T_camera_target = light_pose(drawn, last_lit, display_s, c.options.predict);
  const MarkerErrors e = marker_errors(c.twin, c.target, c.models, c.truth.T_world_projector.matrix(), T_camera_target);
  s.mean_mm = e.mean_mm;
  s.max_mm = e.max_mm;
  return s;
}

void measure_neighbour(const DwellContext& c, NeighbourLight& n, const live::DrawnPose* drawn) {
  n.shown = drawn != nullptr;
  if (!drawn) return count_frame(n, std::nan(""));
  const MarkerErrors e = marker_errors(c.twin, n.target, c.models, c.truth.T_world_projector.matrix(), drawn->T_camera_target);
  count_frame(n, e.mean_mm);
}

void summarise_timeline(VisitReport& r) {
  std::vector<double> moving, ages;
  double still_sum = 0.0;
  int still_n = 0;
  for (const auto& s : r.timeline) {
    if (s.moving && !s.shown) ++r.moving_blank_frames;
    if (!s.shown || std::isnan(s.mean_mm)) continue;  // blank, or no marker in the projector's light
    ages.push_back(s.age_ms);
    if (s.moving) {
      moving.push_back(s.mean_mm);
    } else {
      still_sum += s.mean_mm;
      ++still_n;
    }
  }
  for (const double m : moving) r.moving_mean_mm += m / static_cast<double>(moving.size());
  r.moving_p95_mm = engine::percentile(moving, 0.95);
  r.still_mean_mm = still_n > 0 ? still_sum / still_n : 0.0;
  double lost_at = -1.0;  // when the current blank episode began, -1 while lit
  bool was_lit = false;
  for (const auto& s : r.timeline) {
    if (s.shown && lost_at >= 0.0) {
      r.recovery_s = std::max(r.recovery_s, s.t_s - lost_at);
      lost_at = -1.0;
    } else if (!s.shown && was_lit && s.in_world && lost_at < 0.0) {
      lost_at = s.t_s;
    }
    was_lit = was_lit || s.shown;
    if (!s.in_world) lost_at = -1.0;  // carried away: blank is right, nothing to recover
  }
  if (lost_at >= 0.0) r.recovery_s = -1.0;
  r.age_p50_ms = engine::percentile(ages, 0.5);
  r.age_p95_ms = engine::percentile(ages, 0.95);
}

NeighbourLight neighbour_light(const Twin& twin, const Acquired& a, std::size_t target, const live::LitTarget& n,
                               const robot::HeadPoses& truth, const ProjectorModels& models) {
  const TwinTarget& t = twin.targets()[target];
  NeighbourLight l;
  l.target = target;
  l.shown = a.projected;
  l.drawn.T_camera_target = l.drawn.motion.T = a.icp.T_scan_model;
  NeighbourReport& r = l.report;
  r.target = t.config.name;
  r.projected = a.projected;
  r.align_ms = a.align_ms;
  std::tie(r.guess_error_cm, r.guess_error_deg) = guess_error(truth, t, n.T_camera_target_guess);
  const MarkerErrors e = marker_errors(twin, target, models, truth.T_world_projector.matrix(), a.icp.T_scan_model);
  r.mean_mm = e.mean_mm;
  r.max_mm = e.max_mm;
  count_frame(l, e.mean_mm);  // the arrival's frame
  return l;
}

// A motion's scored frames as one: the mean of each figure over the frames that saw the target, and how
// many did (none: the first frame's row, which says so).
AppearanceSample mean_appearance(const std::vector<AppearanceSample>& samples) {
  AppearanceSample m = samples.front();
  std::vector<const AppearanceSample*> seen;
  for (const AppearanceSample& a : samples)
    if (a.score.pixels > 0) seen.push_back(&a);
  m.frames = static_cast<int>(seen.size());
  if (seen.empty()) return m;  // pixels 0: "no lit pixel of the target in view"
  const double n = static_cast<double>(seen.size());
  const auto mean = [&](auto field) {
    double sum = 0.0;
    for (const AppearanceSample* a : seen) sum += field(*a);
    return sum / n;
  };
  m.gain = mean([](const AppearanceSample& a) { return a.gain; });
  m.ms_per_frame = mean([](const AppearanceSample& a) { return a.ms_per_frame; });
  m.still_psnr_db = mean([](const AppearanceSample& a) { return a.still_psnr_db; });
  AppearanceScore& s = m.score;
  s.pixels = static_cast<std::size_t>(std::lround(mean([](const AppearanceSample& a) { return double(a.score.pixels); })));
  s.psnr_db = mean([](const AppearanceSample& a) { return a.score.psnr_db; });
  s.ssim = mean([](const AppearanceSample& a) { return a.score.ssim; });
  s.de2000_median = mean([](const AppearanceSample& a) { return a.score.de2000_median; });
  s.de2000_p95 = mean([](const AppearanceSample& a) { return a.score.de2000_p95; });
  s.clipped_share = mean([](const AppearanceSample& a) { return a.score.clipped_share; });
  s.unreachable_share = mean([](const AppearanceSample& a) { return a.score.unreachable_share; });
  m.worst_psnr_db = std::numeric_limits<double>::infinity();
  for (const AppearanceSample* a : seen) m.worst_psnr_db = std::min(m.worst_psnr_db, a->score.psnr_db);
  return m;
}

}  // namespace projbot::twin::detail
