// The tour's report: the paper's Table 1 beside ours, and the JSON file.

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "projbot/config/output_file.hpp"
#include "projbot/twin/tour.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {
namespace {

// The view's weak directions: what depth alone could not pin down at arrival (camera frame).
nlohmann::json view_json(const alignment::ViewConstraints& c) {
  nlohmann::json weak = nlohmann::json::array();
  for (const auto& w : c.weak)
    weak.push_back({{"kind", w.is_slide() ? "slide" : "turn"},
                    {"translation", {w.translation.x(), w.translation.y(), w.translation.z()}},
                    {"rotation", {w.rotation.x(), w.rotation.y(), w.rotation.z()}},
                    {"strength", w.strength}});
  return {{"points", c.points}, {"strength", c.strength}, {"weak_threshold", alignment::ViewConstraints::kWeak}, {"weak", weak}};
}

// Table 1 of the paper: projection error at markers, mm, per visit of each target (odometry only).
constexpr double kPaperMm[2][3] = {{4.0, 6.0, 12.0}, {6.0, 6.0, 19.0}};

nlohmann::json matrix_json(const Eigen::Matrix4d& T) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < 4; ++r) rows.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  return rows;
}

nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// The other targets lit at a stop (issue 11, item 5).
nlohmann::json neighbours_json(const std::vector<NeighbourReport>& neighbours) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& n : neighbours)
    out.push_back({{"target", n.target},
                   {"projected", n.projected},
                   {"mean_mm", finite_or_null(n.mean_mm)},
                   {"max_mm", finite_or_null(n.max_mm)},
                   {"guess_error_cm", n.guess_error_cm},
                   {"guess_error_deg", n.guess_error_deg},
                   {"align_ms", n.align_ms},
                   {"frames", n.frames},
                   {"lit_frames", n.lit_frames},
                   {"lit_mean_mm", finite_or_null(n.lit_mean_mm)},
                   {"worst_mm", finite_or_null(n.worst_mm)},
                   {"lit_over_10mm_frames", n.far_off.over_10mm},
                   {"lit_over_20mm_frames", n.far_off.over_20mm}});
  return out;
}

// "lit/frames (a / b)": the frames lit, and of them those more than 10 / 20 mm off.
std::string lit_of(int lit, std::size_t frames, const FarOff& off) {
  return std::to_string(lit) + "/" + std::to_string(frames) + " (" + std::to_string(off.over_10mm) + " / " +
         std::to_string(off.over_20mm) + ")";
}

std::string fixed(double v, int decimals) {
  if (std::isnan(v)) return "-";  // nothing measured (no marker in the projector's light, no lit frame)
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

// The other targets in view at each stop, lit with the visited one and each blanked on its own.
void print_neighbours(const TourReport& report, std::ostream& out) {
  bool any = false;
  for (const auto& v : report.visits) any = any || !v.neighbours.empty();
  if (!any) return;
  out << "\nNeighbours in view, lit with the visited target (each blanked on its own):\n\n| # | visited | neighbour | Eq. 1 "
         "guess error cm / deg | at arrival mean / max mm | lit frames (> 10 / > 20 mm off) | mean / worst mm over them | "
         "align ms |\n"
         "|---|---|---|---|---|---|---|---|\n";
  for (const auto& v : report.visits)
    for (const auto& n : v.neighbours)
      out << "| " << v.visit << " | " << v.target << " | " << n.target << " | " << fixed(n.guess_error_cm, 1) << " / "
          << fixed(n.guess_error_deg, 1) << " | "
          << (n.projected ? fixed(n.mean_mm, 2) + " / " + fixed(n.max_mm, 2) : std::string("blanked")) << " | "
          << lit_of(n.lit_frames, static_cast<std::size_t>(n.frames), n.far_off) << " | " << fixed(n.lit_mean_mm, 2) << " / "
          << fixed(n.worst_mm, 2) << " | " << fixed(n.align_ms, 0) << " |\n";
}

}  // namespace

void print_table(const TourReport& report, std::ostream& out) {
  // Targets in order of first visit: the paper's target 1 and target 2.
  std::vector<std::string> names;
  for (const auto& v : report.visits)
    if (std::find(names.begin(), names.end(), v.target) == names.end()) names.push_back(v.target);
  int rows = 0;
  for (const auto& v : report.visits) rows = std::max(rows, v.target_visit);

  out << "Projection error at the markers, mm (mean / max), mode " << to_string(report.mode) << ", seed " << report.seed
      << ", depth model " << report.depth_model << ";\nthe paper's Table 1 (odometry only, one ICP per stop) beside it:\n\n";
  out << "| visit |";
  for (std::size_t c = 0; c < names.size(); ++c)
    out << ' ' << names[c] << " |" << (c < 2 ? " paper target " + std::to_string(c + 1) + " |" : "");
  out << "\n|---|";
  for (std::size_t c = 0; c < names.size(); ++c) out << (c < 2 ? "---|---|" : "---|");
  out << '\n';
  for (int row = 1; row <= rows; ++row) {
    out << "| " << row << " |";
    for (std::size_t c = 0; c < names.size(); ++c) {
      const auto it = std::find_if(report.visits.begin(), report.visits.end(),
                                   [&](const VisitReport& v) { return v.target == names[c] && v.target_visit == row; });
      if (it == report.visits.end())
        out << " - |";
      else if (!it->target_present)
        out << (it->lit_frames == 0 ? " absent, never lit |" : " absent, LIT (wrong) |");
      else if (!it->projected)
        out << " blanked (" << fixed(it->mean_mm, 1) << " / " << fixed(it->max_mm, 1) << " if shown) |";
      else
        out << ' ' << fixed(it->mean_mm, 1) << " / " << fixed(it->max_mm, 1) << " |";
      if (c < 2) out << ' ' << (row <= 3 ? fixed(kPaperMm[c][row - 1], 0) : std::string("-")) << " |";
    }
    out << '\n';
  }

  out << "\n| # | target | base error cm / deg | odometry drift cm | Eq. 1 guess error cm / deg | ICP | inliers | rmse mm | "
         "mean / max mm | align ms |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& v : report.visits) {
    out << "| " << v.visit << " | " << v.target << " (" << v.target_visit << ") | " << fixed(v.base_error_cm, 2) << " / "
        << fixed(v.base_error_deg, 2) << " | " << fixed(v.odometry_error_cm, 1) << " | " << fixed(v.guess_error_cm, 1) << " / "
        << fixed(v.guess_error_deg, 1) << " | " << (v.icp.converged ? "ok" : "failed") << (v.icp.reinitialised ? " (FPFH)" : "")
        << " | " << fixed(v.icp.inlier_ratio, 2) << " | " << fixed(v.icp.rmse_mm, 2) << " | " << fixed(v.mean_mm, 2) << " / "
        << fixed(v.max_mm, 2) << " | " << fixed(v.align_ms, 0) << " |\n";
  }
  bool any_timeline = false;
  for (const auto& v : report.visits) any_timeline = any_timeline || !v.timeline.empty();
  if (any_timeline) {
    out << "\nWhile projecting (" << to_string(report.mode)
        << (report.mode != TourMode::tracking ? ", drawn at the arrival's estimate, not tracked"
            : report.predict                  ? ", drawn at the pose predicted for display time"
                                              : ", drawn at the newest measured pose")
        << "; errors of each projector frame at its display time):\n\n| # | target | moved | while moving mean / p95 / worst mm "
           "| "
           "mean mm still | mean mm at the end | re-converged after the move, s | pose age at display p50 / p95 ms | "
           "track ms/frame | lit frames (> 10 / > 20 mm off) | first light s (wall ms) | "
           "search attempts, ms (longest) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& v : report.visits) {
      if (v.timeline.empty()) continue;
      out << "| " << v.visit << " | " << v.target << " | " << (v.moved ? "yes" : "no") << " | "
          << (v.moved ? fixed(v.moving_mean_mm, 1) + " / " + fixed(v.moving_p95_mm, 1) + " / " + fixed(v.max_mm_moving, 1)
                      : std::string("-"))
          << " | " << fixed(v.still_mean_mm, 2) << " | " << fixed(v.timeline.back().mean_mm, 2) << " | "
          << (v.reconverge_s < 0 ? std::string("never") : fixed(v.reconverge_s, 2)) << " | " << fixed(v.age_p50_ms, 0) << " / "
          << fixed(v.age_p95_ms, 0) << " | " << (v.track_ms_mean > 0 ? fixed(v.track_ms_mean, 1) : std::string("-")) << " | "
          << lit_of(v.lit_frames, v.timeline.size() + 1, v.far_off) << " | "
          << (v.first_light_s < 0 ? std::string("never")
                                  : fixed(v.first_light_s, 2) + " (" + fixed(v.first_light_wall_ms, 0) + ")")
          << " | "
          << (v.search.attempts > 0 ? std::to_string(v.search.attempts) + ", " + fixed(v.search.total_ms, 0) + " (" +
                                          fixed(v.search.max_attempt_ms, 0) + ")"
                                    : std::string("-"))
          << " |\n";
    }
  }
  print_neighbours(report, out);
  double simulated_s = 0.0;
  for (const auto& v : report.visits) simulated_s += v.drive_s + (v.timeline.empty() ? 0.0 : v.timeline.back().t_s);
  out << "\nTour: " << report.visits.size() << " visits in " << fixed(report.wall_s, 1) << " s wall time, "
      << fixed(simulated_s, 1) << " s simulated (driving and projecting)"
      << (report.interrupted ? " (interrupted: the finished visits only)" : "") << ".\n";
  const FarOff off = far_off(report);
  out << "Lit far off (the visited targets and their neighbours, " << report.depth_model << " depth model): " << off.over_20mm
      << " frames more than 20 mm off, " << off.over_10mm << " more than 10 mm"
      << (off.over_10mm > 0 ? " (worst " + fixed(off.worst_mm, 0) + " mm)" : std::string()) << ".\n";
  if (off.over_20mm_change_unseen > 0)
    out << "Of those more than 20 mm off, " << off.over_20mm_change_unseen
        << " drew a pose captured before its target started or stopped moving: no frame had shown it yet.\n";
}

FarOff far_off(const TourReport& report) {
  FarOff all;
  for (const auto& v : report.visits) {
    all.add(v.far_off);
    for (const auto& n : v.neighbours) all.add(n.far_off);
  }
  return all;
}

namespace {

nlohmann::json markers_json(const VisitReport& v) {
  nlohmann::json markers = nlohmann::json::array();
  for (const auto& m : v.markers)
    markers.push_back({{"model_m", {m.marker_m.x(), m.marker_m.y(), m.marker_m.z()}},
                       {"pixel", {m.pixel.x(), m.pixel.y()}},
                       {"in_image", m.in_image},
                       {"landed", m.landed},
                       {"error_mm", m.error_mm}});
  return markers;
}

nlohmann::json timeline_json(const VisitReport& v) {
  nlohmann::json timeline = nlohmann::json::array();
  for (const auto& s : v.timeline)
    timeline.push_back({{"t_s", s.t_s},
                        {"mean_mm", finite_or_null(s.mean_mm)},
                        {"max_mm", finite_or_null(s.max_mm)},
                        {"moving", s.moving},
                        {"shown", s.shown},
                        {"pose_age_ms", s.age_ms}});
  return timeline;
}

// One visit's object: a data table, field by field.
nlohmann::json visit_json(const VisitReport& v) {
  return {
      {"visit", v.visit},
      {"target", v.target},
      {"target_visit", v.target_visit},
      {"projected", v.projected},
      {"T_projector_target_true", matrix_json(v.T_projector_target_true)},
      {"T_projector_target_estimated", matrix_json(v.T_projector_target_estimated)},
      {"markers", markers_json(v)},
      {"mean_mm", finite_or_null(v.mean_mm)},
      {"max_mm", finite_or_null(v.max_mm)},
      {"icp",
       {{"converged", v.icp.converged},
        {"inlier_ratio", v.icp.inlier_ratio},
        {"rmse_mm", finite_or_null(v.icp.rmse_mm)},
        {"iterations", v.icp.iterations},
        {"reinitialised", v.icp.reinitialised},
        {"footing_height_error_mm", v.icp.footing_height_error_mm},
        {"footing_tilt_deg", v.icp.footing_tilt_deg},
        {"colour_shift_mm", v.icp.colour_shift_mm},
        {"colour_agreement", finite_or_null(v.icp.colour_agreement)}}},
      {"free_space",
       {{"predicted_px", v.free_space.predicted},
        {"behind_px", v.free_space.behind},
        {"in_front_px", v.free_space.in_front},
        {"behind_ratio", v.free_space.behind_ratio()}}},
      {"view", view_json(v.view)},
      {"robot",
       {{"base_error_cm", v.base_error_cm},
        {"base_error_deg", v.base_error_deg},
        {"odometry_error_cm", v.odometry_error_cm},
        {"guess_error_cm", v.guess_error_cm},
        {"guess_error_deg", v.guess_error_deg},
        {"drive_s", v.drive_s}}},
      {"timings_ms",
       {{"capture", v.capture_ms}, {"align", v.align_ms}, {"projector_frame", v.frame_ms}, {"track_per_frame", v.track_ms_mean}}},
      {"tracking", {{"frames", v.tracked_frames}, {"dropped_frames", v.dropped_frames}, {"second_passes", v.second_pass_frames}}},
      {"moved", v.moved},
      {"max_mean_mm_while_moving", v.max_mm_moving},
      {"while_moving_mm", {{"mean", finite_or_null(v.moving_mean_mm)}, {"p95", finite_or_null(v.moving_p95_mm)}}},
      {"blank_frames_while_moving", v.moving_blank_frames},
      {"recovery_s", v.recovery_s},
      {"still_mean_mm", v.still_mean_mm},
      {"pose_age_at_display_ms", {{"p50", finite_or_null(v.age_p50_ms)}, {"p95", finite_or_null(v.age_p95_ms)}}},
      {"reconverge_s", v.reconverge_s},
      {"target_present", v.target_present},
      {"lit_frames", v.lit_frames},
      {"lit_over_10mm_frames", v.far_off.over_10mm},
      {"lit_over_20mm_frames", v.far_off.over_20mm},
      {"lit_over_20mm_change_unseen_frames", v.far_off.over_20mm_change_unseen},
      {"lit_worst_mm", v.far_off.worst_mm},
      {"first_light_s", v.first_light_s},
      {"first_light_wall_ms", v.first_light_wall_ms},
      {"search",
       {{"attempts", v.search.attempts},
        {"total_ms", v.search.total_ms},
        {"max_attempt_ms", v.search.max_attempt_ms},
        {"frames_waited", v.search.frames_waited}}},
      {"blank_after_removal_s", v.blank_after_removal_s},
      {"neighbours", neighbours_json(v.neighbours)},
      {"timeline", timeline_json(v)}};
}

}  // namespace

void write_report_json(const TourReport& report, const std::filesystem::path& path) {
  nlohmann::json visits = nlohmann::json::array();
  for (const auto& v : report.visits) visits.push_back(visit_json(v));
  const auto& k = report.projector;
  const FarOff all_off = far_off(report);
  const nlohmann::json out = {
      {"mode", to_string(report.mode)},
      {"predict", report.predict},
      {"depth_model", report.depth_model},
      {"seed", report.seed},
      {"processing_ms", report.processing_ms ? nlohmann::json(*report.processing_ms) : nlohmann::json(nullptr)},
      {"projector",
       {{"width", k.width_px}, {"height", k.height_px}, {"fx", k.fx_px}, {"fy", k.fy_px}, {"cx", k.cx_px}, {"cy", k.cy_px}}},
      {"paper_table1_mm", {{"target1", kPaperMm[0]}, {"target2", kPaperMm[1]}}},
      {"wall_s", report.wall_s},
      {"interrupted", report.interrupted},
      {"lit_far_off",
       {{"over_10mm_frames", all_off.over_10mm},
        {"over_20mm_frames", all_off.over_20mm},
        {"over_20mm_change_unseen_frames", all_off.over_20mm_change_unseen},
        {"worst_mm", all_off.worst_mm}}},
      {"visits", visits}};
  config::write_file_atomically(path, out.dump(2) + '\n');
}

}  // namespace projbot::twin
