#include "projbot/twin/tour.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <deque>
#include <optional>
#include <tuple>
#include <utility>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/projection.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr double kCameraHz = 30.0;
constexpr double kConvergedMm = 3.0;  // the goal for a visit's mean error

struct Errors {
  std::vector<MarkerError> markers;
  double mean_mm = 0.0, max_mm = 0.0;
};

// Whether a point in the projector frame falls inside the projector's image (Eq. 3).
bool lit_by(const config::ProjectorConfig& k, const Eigen::Vector3d& p) {
  if (p.z() <= 0.0) return false;
  const Eigen::Vector2d x = k.project_lit(p);
  return x.x() >= 0.0 && x.y() >= 0.0 && x.x() < k.width_px && x.y() < k.height_px;
}

// The projector as the twin's light follows it (the scene's: the truth) and as the session believes it
// (a calibration's A_p and R_cp, T_cp when the tour is given one; else the truth): Eq. 2 and the
// drawing use what the session believes.
struct ProjectorModels {
  config::ProjectorConfig truth, believed;
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  // believed R_cp, T_cp
  Eigen::Matrix4d projector_from_target(const Eigen::Matrix4d& T_camera_target) const {
    return alignment::projector_from_target(T_projector_camera, T_camera_target);  // Eq. 2
  }
};

// The error at the target's markers. A marker the projector cannot light (outside its image, turned
// away, or hidden by the target itself or something in front), or lights edge-on (seen_edge_on), has no
// error to measure and is left out; mean and max are NaN when no marker is left (such frames are left
// out of the visit's statistics).
Errors marker_errors(const Twin& twin, std::size_t target, const ProjectorModels& projector,
                     const Eigen::Matrix4d& T_world_projector, const Eigen::Matrix4d& T_camera_target_estimated) {
  const Eigen::Matrix4d T_projector_target_estimated = projector.projector_from_target(T_camera_target_estimated);
  const Eigen::Matrix4d T_projector_world = alignment::rigid_inverse(T_world_projector);
  const auto scene = twin.true_scene(T_projector_world);
  const TwinTarget& t = twin.targets()[target];
  const Eigen::Matrix4d T_true = T_projector_world * t.T_world_target_true;
  Errors e;
  int visible = 0;
  for (const auto& m : t.config.markers_m) {
    const Eigen::Vector3d truth = (T_true * m.homogeneous()).head<3>();
    if (!lit_by(projector.truth, truth)) continue;  // outside the projector's image: it cannot be lit
    const auto first = cast_ray(scene, Eigen::Vector3d::Zero(), truth.normalized());
    if (!first || (*first - truth).norm() > 0.002) continue;
    if (seen_edge_on(scene, truth)) continue;  // a pose's error cannot be measured there
    e.markers.push_back(measure_marker(projector.believed, projector.truth, T_projector_target_estimated, T_true, m, scene));
    e.mean_mm += e.markers.back().error_mm;
    e.max_mm = std::max(e.max_mm, e.markers.back().error_mm);
    ++visible;
  }
  if (visible == 0)
    e.mean_mm = e.max_mm = std::nan("");
  else
    e.mean_mm /= visible;
  return e;
}

// One acquisition at arrival. Odometry and localized modes: the whole acquisition once (the paper's
// one alignment per stop; odometry projects whatever it gives). Tracking mode: the follower's first
// step, the bounded start of its search, as the live engine's worker does it.
void acquire(TourMode mode, alignment::TargetFollower& follower, const Twin& twin, const alignment::DepthImage& depth,
             const Eigen::Matrix4d& T_init, const alignment::Footing& footing, const assets::Image* colour, VisitReport& r) {
  const auto t0 = Clock::now();
  r.icp.T_scan_model = T_init;  // too little in view: nothing to align
  r.icp.converged = false;
  if (mode == TourMode::tracking) {
    follower.set_initial_guess(T_init, footing);
    const auto sample = follower.step(depth, colour);
    if (follower.last_attempt()) r.icp = *follower.last_attempt();
    if (sample && !sample->lost) r.icp.T_scan_model = sample->T_camera_target;  // colour may have moved it
    r.icp.colour_shift_mm = follower.search_stats().colour_shift_mm;
    r.icp.colour_agreement = follower.search_stats().colour_agreement;
    if (sample && !sample->lost && !follower.last_attempt()) {  // the projective tracker found it from the guess
      r.icp.T_scan_model = sample->T_camera_target;
      r.icp.converged = true;
      r.icp.inlier_ratio = sample->inlier_ratio;
      r.icp.rmse_mm = sample->rmse_mm;
    }
    r.free_space = follower.last_check();
    r.projected = sample && !sample->lost;
  } else {
    try {
      // Ours leaves out the floor (known from the map and where the robot believes its camera is) and
      // what lies outside the guess's silhouette, and takes only a pose that stands as surveyed; the
      // paper's set-up aligns to everything near the guess.
      r.icp = mode == TourMode::localized ? follower.acquire(depth, T_init, footing, follower.silhouette_grow_m(), colour)
                                          : follower.aligner().align(alignment::depth_to_cloud(depth, twin.camera()), T_init);
    } catch (const alignment::AlignmentError&) {
    }
    // Ours also checks the estimate against free space; the paper's set-up projects whatever ICP gives.
    r.free_space = follower.verify(depth, r.icp.T_scan_model);
    if (mode == TourMode::localized && !follower.passes(r.free_space)) r.icp.converged = false;
    r.projected = mode == TourMode::odometry || r.icp.converged;
  }
  r.align_ms = ms_since(t0);
  if (r.projected) {
    r.first_light_s = 0.0;
    r.first_light_wall_ms = r.align_ms;
    r.lit_frames = 1;
  }
}

// A neighbour lit with the visited target (issue 11, item 5): what the projector draws for it, and the
// error of its lit frames so far.
struct NeighbourLight {
  std::size_t target = 0;  // index into Twin::targets()
  alignment::PoseSample drawn;
  bool shown = false;
  double sum_mm = 0.0;     // over the lit frames with a marker in the light...
  int measured = 0;        // ...this many
  NeighbourReport report;  // frames, lit_frames and worst_mm counted as the frames come
};

// One projector frame of a neighbour: counted, and its error added when it was lit and measured.
void count_frame(NeighbourLight& n, double mean_mm) {
  ++n.report.frames;
  if (!n.shown) return;
  ++n.report.lit_frames;
  if (std::isnan(mean_mm)) return;
  n.sum_mm += mean_mm;
  n.report.worst_mm = n.measured == 0 ? mean_mm : std::max(n.report.worst_mm, mean_mm);
  ++n.measured;
}

// Eq. 1's guess against the truth: how far off it is (cm, degrees).
std::pair<double, double> guess_error(const robot::HeadPoses& truth, const TwinTarget& t, const Eigen::Matrix4d& guess) {
  const Eigen::Matrix4d T_camera_true = alignment::rigid_inverse(truth.T_world_camera.matrix()) * t.T_world_target_true;
  const Eigen::Matrix4d error = alignment::rigid_inverse(T_camera_true) * guess;
  return {100.0 * alignment::translation_norm_m(error), alignment::rotation_angle_deg(error)};
}

struct DwellContext {
  Twin& twin;
  std::size_t target;
  const ProjectorModels& models;
  const robot::HeadPoses& truth;
  const TourOptions& options;
  std::uint32_t noise_seed;
  std::vector<NeighbourLight>& neighbours;
};

// A tracker result on the simulated clock: usable by projector frames that start at or after ready_s.
struct InFlight {
  std::optional<alignment::PoseSample> sample;
  double ready_s = 0.0;
};

// One target's tracker worker on the simulated clock (`projbot run` runs one per target).
struct Lane {
  alignment::TargetFollower* follower = nullptr;
  std::deque<InFlight> in_flight;
  double free_s = 0.0;  // when its current step ends
  double track_ms = 0.0;
  int tracked = 0;  // frames it took
};

// The camera side of the dwell, on the simulated clock: frames captured at 30 Hz and handed to the
// tracker workers (the visited target's first, then its neighbours'), as in `projbot run`. A frame
// reaches a worker after its capture time (the twin's rendering, standing in for the camera's
// readout); a worker takes it when it is free before the next frame arrives, else the frame is dropped
// for it (a worker always takes the newest). Its result is ready when the worker's step ends: measured
// wall time, or options.processing_ms for both together.
class CameraSide {
 public:
  CameraSide(const DwellContext& c, const std::vector<alignment::TargetFollower*>& followers, VisitReport& r) : c_(c), r_(r) {
    for (auto* f : followers) lanes_.push_back(Lane{f, {}, 0.0, 0.0, 0});
  }
  // Captures and tracks every frame taken up to t_s; returns, per lane, the results ready by then,
  // oldest first.
  std::vector<std::vector<alignment::PoseSample>> ready_by(double t_s);
  const Lane& visited() const { return lanes_.front(); }
  int frames = 0;        // captured
  double gone_s = -1.0;  // capture time of the first frame without the target (motion.removed)

 private:
  const DwellContext& c_;
  VisitReport& r_;
  std::vector<Lane> lanes_;
};

std::vector<std::vector<alignment::PoseSample>> CameraSide::ready_by(double t_s) {
  TwinTarget& target = c_.twin.targets()[c_.target];
  for (double t_k = (frames + 1) / kCameraHz; t_k <= t_s + 1e-9; t_k = (frames + 1) / kCameraHz) {
    ++frames;
    target.T_world_target_true = c_.twin.scripted_pose(c_.target, r_.target_visit, t_k);
    target.in_world = c_.twin.scripted_presence(c_.target, r_.target_visit, t_k);
    if (!target.in_world && r_.target_present && gone_s < 0.0) gone_s = t_k;
    const double next_s = t_k + 1.0 / kCameraHz;
    if (std::none_of(lanes_.begin(), lanes_.end(), [&](const Lane& l) { return l.free_s <= next_s; })) continue;
    const auto t0 = Clock::now();
    alignment::DepthImage frame =
        c_.twin.capture(c_.truth.T_world_camera.matrix(), c_.noise_seed + static_cast<std::uint32_t>(frames));
    frame.capture_time_s = t_k;  // the exposure, on the simulated clock
    const double capture_ms = ms_since(t0);
    for (Lane& l : lanes_) {
      if (l.free_s > next_s) continue;  // still busy when the next frame comes: dropped
      const auto tt = Clock::now();
      InFlight f{l.follower->step(frame), 0.0};
      const double step_ms = ms_since(tt);
      l.track_ms += step_ms;
      ++l.tracked;
      const double start_s = std::max(l.free_s, t_k + (c_.options.processing_ms ? 0.0 : 1e-3 * capture_ms));
      f.ready_s = l.free_s = start_s + 1e-3 * c_.options.processing_ms.value_or(step_ms);
      l.in_flight.push_back(std::move(f));
    }
  }
  std::vector<std::vector<alignment::PoseSample>> out(lanes_.size());
  for (std::size_t k = 0; k < lanes_.size(); ++k) {
    auto& q = lanes_[k].in_flight;
    while (!q.empty() && q.front().ready_s <= t_s + 1e-9) {
      if (q.front().sample) out[k].push_back(*q.front().sample);
      q.pop_front();
    }
  }
  return out;
}

// The error of one projector frame, against the target's true pose at the frame's display time.
TimelineSample measure_frame(const DwellContext& c, const VisitReport& r, double display_s, bool shown,
                             const alignment::PoseSample& drawn, bool predict) {
  TwinTarget& target = c.twin.targets()[c.target];
  target.T_world_target_true = c.twin.scripted_pose(c.target, r.target_visit, display_s);
  target.in_world = c.twin.scripted_presence(c.target, r.target_visit, display_s);
  const config::TargetMotion* motion = target.config.motion_on(r.target_visit);
  TimelineSample s;
  s.t_s = display_s;
  s.shown = shown;
  s.moving = motion && motion->moving_at(display_s);
  s.age_ms = 1000.0 * (display_s - drawn.capture_time_s);
  s.in_world = target.in_world;
  const Eigen::Matrix4d T_camera_target = predict ? alignment::predict_pose(drawn.motion, display_s) : drawn.T_camera_target;
  const Errors e = marker_errors(c.twin, c.target, c.models, c.truth.T_world_projector.matrix(), T_camera_target);
  s.mean_mm = e.mean_mm;
  s.max_mm = e.max_mm;
  return s;
}

// A neighbour's projector frame: counted, and its error measured at display time when it is lit
// (neighbours stand still: their motion scripts run on their own visits).
void measure_neighbour(const DwellContext& c, NeighbourLight& n, double display_s) {
  if (!n.shown) return count_frame(n, std::nan(""));
  const Eigen::Matrix4d T_camera_target =
      c.options.predict ? alignment::predict_pose(n.drawn.motion, display_s) : n.drawn.T_camera_target;
  const Errors e = marker_errors(c.twin, n.target, c.models, c.truth.T_world_projector.matrix(), T_camera_target);
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

// Projection while the robot dwells at the stop, on a simulated clock: the camera at 30 Hz, its frames
// tracked (tracking mode), and the projector at its refresh rate drawing the newest result ready when
// its frame starts, predicted to the frame's display time (one refresh later, plus the projector's
// input lag). Each projector frame's error is measured against the target's true pose at its display
// time. Returns false when the tour was asked to stop in the middle.
bool dwell(const DwellContext& c, const std::vector<alignment::TargetFollower*>& followers, VisitReport& r) {
  const TwinTarget& target = c.twin.targets()[c.target];
  const bool tracking = c.options.mode == TourMode::tracking;
  const double period_s = 1.0 / c.models.truth.refresh_hz;
  const double display_delay_s = period_s + 1e-3 * c.models.truth.input_lag_ms;
  alignment::PoseSample drawn;  // the newest result: at first the arrival's estimate
  drawn.T_camera_target = drawn.motion.T = r.icp.T_scan_model;
  bool shown = r.projected;
  CameraSide camera(c, followers, r);
  double wall_to_light_ms = r.align_ms;
  const config::TargetMotion* motion = target.config.motion_on(r.target_visit);
  const double motion_end_s = motion ? motion->end_s() : 0.0;
  double back_under = -1.0;  // when the error went back under the goal for good, -1 while it is not
  bool ever_over = false;
  const int frames = static_cast<int>(std::lround(c.options.dwell_s * c.models.truth.refresh_hz));
  for (int j = 1; j <= frames; ++j) {
    if (c.options.stop_requested && c.options.stop_requested()) return false;
    const double start_s = j * period_s;
    if (tracking) {
      const double before_ms = camera.visited().track_ms;
      const auto ready = camera.ready_by(start_s);
      for (const auto& sample : ready.front()) {
        shown = !sample.lost;
        if (shown) drawn = sample;
      }
      for (std::size_t k = 0; k < c.neighbours.size(); ++k)
        for (const auto& sample : ready[k + 1]) {
          c.neighbours[k].shown = !sample.lost;
          if (!sample.lost) c.neighbours[k].drawn = sample;
        }
      if (r.first_light_s < 0.0) wall_to_light_ms += camera.visited().track_ms - before_ms;
    }
    const TimelineSample s = measure_frame(c, r, start_s + display_delay_s, shown, drawn, c.options.predict);
    for (NeighbourLight& n : c.neighbours) measure_neighbour(c, n, start_s + display_delay_s);
    r.timeline.push_back(s);
    r.lit_frames += shown ? 1 : 0;
    if (shown && r.first_light_s < 0.0) {
      r.first_light_s = s.t_s;
      r.first_light_wall_ms = wall_to_light_ms;
    }
    if (!shown && camera.gone_s >= 0.0 && r.blank_after_removal_s < 0.0) r.blank_after_removal_s = s.t_s - camera.gone_s;
    if (s.moving) r.max_mm_moving = std::max(r.max_mm_moving, s.mean_mm);
    if (std::isnan(s.mean_mm) && shown) continue;  // no marker in the projector's light: nothing measured
    const bool good = shown && s.mean_mm <= kConvergedMm;
    if (!good && c.twin.targets()[c.target].in_world) {
      ever_over = true;
      back_under = -1.0;
    } else if (good && back_under < 0.0 && s.t_s >= motion_end_s) {
      back_under = s.t_s;
    }
  }
  r.shown_at_end = shown;
  r.T_camera_target_at_end = drawn.T_camera_target;
  const Lane& lane = camera.visited();
  r.track_ms_mean = tracking && lane.tracked > 0 ? lane.track_ms / lane.tracked : 0.0;
  r.tracked_frames = lane.tracked;
  r.dropped_frames = camera.frames - lane.tracked;
  if (tracking) {
    r.search = followers.front()->search_stats();
    r.second_pass_frames = followers.front()->second_passes();
  }
  r.reconverge_s = !ever_over ? 0.0 : back_under >= 0.0 ? std::max(0.0, back_under - motion_end_s) : -1.0;
  summarise_timeline(r);
  return true;
}

// A neighbour at arrival: acquired from the stop's capture (and colour) from its own Eq. 1 guess, as
// the visited target is, and its error at the markers measured.
NeighbourLight acquire_neighbour(TourMode mode, const Twin& twin, alignment::TargetFollower& follower, std::size_t target,
                                 const session::LitTarget& n, const robot::HeadPoses& truth, const alignment::DepthImage& depth,
                                 const std::optional<assets::Image>& colour, const ProjectorModels& models) {
  const TwinTarget& t = twin.targets()[target];
  VisitReport scratch;
  acquire(mode, follower, twin, depth, n.T_camera_target_guess, n.footing, colour ? &*colour : nullptr, scratch);
  NeighbourLight l;
  l.target = target;
  l.shown = scratch.projected;
  l.drawn.T_camera_target = l.drawn.motion.T = scratch.icp.T_scan_model;
  NeighbourReport& r = l.report;
  r.target = t.config.name;
  r.projected = scratch.projected;
  r.align_ms = scratch.align_ms;
  std::tie(r.guess_error_cm, r.guess_error_deg) = guess_error(truth, t, n.T_camera_target_guess);
  const Errors e = marker_errors(twin, target, models, truth.T_world_projector.matrix(), scratch.icp.T_scan_model);
  r.mean_mm = e.mean_mm;
  r.max_mm = e.max_mm;
  count_frame(l, e.mean_mm);  // the arrival's frame
  return l;
}

// A neighbour's report after the stop: the mean over its lit frames added.
NeighbourReport finished(const NeighbourLight& l) {
  NeighbourReport r = l.report;
  r.lit_mean_mm = l.measured > 0 ? l.sum_mm / l.measured : std::nan("");
  return r;
}

// Where --frames writes one of a visit's pictures: DIR/visitNN_TARGET<suffix>.png.
std::filesystem::path frame_path(const TourOptions& options, const VisitReport& r, const char* suffix) {
  char file[96];
  std::snprintf(file, sizeof file, "visit%02d_%s%s.png", r.visit, r.target.c_str(), suffix);
  return options.frames_dir / file;
}

}  // namespace

const char* to_string(TourMode mode) {
  switch (mode) {
    case TourMode::odometry:
      return "odometry";
    case TourMode::localized:
      return "localized";
    case TourMode::tracking:
      return "tracking";
  }
  return "?";
}

TourReport run_tour(const config::Scene& scene, const TourOptions& options) {
  const auto wall0 = Clock::now();
  engine::Renderer renderer(engine::RendererOptions{});
  TwinOptions twin_options;
  twin_options.pose_source = options.mode == TourMode::odometry ? robot::PoseSource::odometry : robot::PoseSource::localized;
  twin_options.seed = options.seed;
  twin_options.depth_noise = options.depth_noise;
  Twin twin(scene, twin_options, renderer);
  auto& targets = twin.targets();
  ProjectorModels models{scene.projector, scene.projector, scene.pan_tilt.T_projector_camera};
  if (options.calibration) {
    static_cast<config::Pinhole&>(models.believed) = options.calibration->projector;
    models.believed.distortion = options.calibration->distortion;
    models.T_projector_camera = options.calibration->T_projector_camera;
  }

  // The paper aligned once per stop with plain ICP from the initial guess; ours is point-to-plane, coarse
  // to fine, rejects correspondences whose normals disagree, and adds local restarts, FPFH
  // re-initialisation and the quality gate.
  alignment::AcquisitionConfig acquisition;
  if (options.mode == TourMode::odometry) {
    acquisition.restart_angle_deg = 0.0;
    acquisition.reinitialise = false;
    // Plain ICP as the paper ran it: point-to-point (PCL's SVD estimation), one pass with a fixed
    // correspondence distance and iteration budget, on the scan near the expected target.
    acquisition.point_to_plane = false;
    acquisition.icp_distances_m = {0.05};
    acquisition.icp_iterations = 30;
    acquisition.max_normal_angle_deg = 180.0;
  }
  // One follower per target: its aligner acquires at each stop, its policy tracks while projecting
  // (the same one the live engine's TrackerWorker runs).
  alignment::WorkerConfig follow;
  follow.acquisition = acquisition;
  follow.predict = options.predict;
  follow.motion = options.motion;
  std::vector<alignment::TargetFollower> followers;
  for (const auto& t : targets) followers.emplace_back(t.cloud, twin.camera(), follow);
  // The stop sequence (drive, aim, Eq. 1 for the visited target and its neighbours) is the session's;
  // the twin serves its base and pan-tilt.
  session::Session session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());
  std::unique_ptr<engine::RenderTarget> projector_frame;
  std::unique_ptr<SpectatorView> spectator;
  if (!options.frames_dir.empty()) {
    std::filesystem::create_directories(options.frames_dir);
    projector_frame = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
    spectator = std::make_unique<SpectatorView>(renderer, scene.projector);
  }

  TourReport report;
  report.mode = options.mode;
  report.seed = options.seed;
  report.predict = options.predict;
  report.projector = scene.projector;
  const int visits = options.visits > 0 ? options.visits : static_cast<int>(scene.visits.size());
  const auto stop = [&] { return options.stop_requested && options.stop_requested(); };
  for (int v = 0; v < visits && !(report.interrupted = stop()); ++v) {
    // Drive to the stop, closing the loop on localisation (or odometry, the paper's set-up), and aim at
    // where the map says the target is, from where the robot believes it is.
    const session::Stop arrival = session.arrive(v);
    const std::string& name = scene.targets[static_cast<std::size_t>(arrival.target)].name;
    const std::size_t i = twin.target_index(name);
    TwinTarget& target = targets[i];
    VisitReport r;
    r.visit = v + 1;
    r.target_visit = arrival.target_visit;
    r.target = name;
    r.drive_s = arrival.drive.drive_seconds;
    r.base_error_cm = 100.0 * arrival.drive.error_m;
    r.base_error_deg = arrival.drive.error_rad * 180.0 / M_PI;
    r.odometry_error_cm = 100.0 * arrival.drive.odometry_error_m;
    const robot::HeadPoses truth = twin.true_head();
    // A visitor beside the robot, looking at the target where it truly stands now.
    // The projector's frame: the target drawn at T_projector_target when lit, its neighbours where lit, else all black.
    std::vector<NeighbourLight> lights;
    const auto projector_image = [&](bool lit, const Eigen::Matrix4d& T_projector_target) {
      std::vector<engine::DrawItem> items;
      if (lit) items.push_back({twin.target_model_ids()[i], T_projector_target});
      for (const NeighbourLight& n : lights)
        if (n.shown) items.push_back({twin.target_model_ids()[n.target], models.projector_from_target(n.drawn.T_camera_target)});
      renderer.draw_frame(*projector_frame, models.believed, items);
      return projector_frame->read_back();
    };
    const auto spectator_at = [&](const TwinTarget& t) {
      return spectator_pose(truth.T_world_camera.translation(), model_middle(t, t.T_world_target_true));
    };
    target.in_world = twin.scripted_presence(i, r.target_visit, 0.0);
    r.target_present = target.in_world;

    // Capture, Eq. 1, acquisition, Eq. 2.
    auto t0 = Clock::now();
    const std::uint32_t noise_seed = static_cast<std::uint32_t>(options.seed * 100003 + static_cast<std::uint64_t>(v) * 1009);
    const alignment::DepthImage depth = twin.capture(truth.T_world_camera.matrix(), noise_seed);
    r.capture_ms = ms_since(t0);
    const session::LitTarget& visited = arrival.lit.front();
    const Eigen::Matrix4d& T_init = visited.T_camera_target_guess;
    std::tie(r.guess_error_cm, r.guess_error_deg) = guess_error(truth, target, T_init);
    // Localized and tracking: the colour the RGB-D camera registers to the depth, taken with it (before
    // any light).
    std::optional<assets::Image> colour;
    if (options.mode != TourMode::odometry) colour = twin.capture_colour(truth.T_world_camera.matrix(), noise_seed);
    acquire(options.mode, followers[i], twin, depth, T_init, visited.footing, colour ? &*colour : nullptr, r);
    const Eigen::Matrix4d T_world_projector = truth.T_world_projector.matrix();
    r.view = alignment::view_constraints(target.cloud, r.icp.T_scan_model, twin.camera());
    r.T_projector_target_estimated = models.projector_from_target(r.icp.T_scan_model);
    r.T_projector_target_true = alignment::rigid_inverse(T_world_projector) * target.T_world_target_true;
    Errors e = marker_errors(twin, i, models, T_world_projector, r.icp.T_scan_model);
    r.markers = e.markers;
    r.mean_mm = e.mean_mm;
    r.max_mm = e.max_mm;
    for (std::size_t k = 1; k < arrival.lit.size(); ++k) {
      const session::LitTarget& n = arrival.lit[k];
      const std::size_t j = twin.target_index(scene.targets[static_cast<std::size_t>(n.target)].name);
      lights.push_back(acquire_neighbour(options.mode, twin, followers[j], j, n, truth, depth, colour, models));
    }

    if (projector_frame) {
      t0 = Clock::now();
      const auto image = projector_image(r.projected, r.T_projector_target_estimated);
      r.frame_ms = ms_since(t0);
      assets::write_png(frame_path(options, r, ""), image);
      // What the RGB-D camera saw at the capture: its colour, registered to the depth that was used.
      assets::write_png(frame_path(options, r, "_camera"),
                        colour ? *colour : twin.capture_colour(truth.T_world_camera.matrix(), noise_seed));
      // What a visitor beside the robot sees: the frame's light on the true surfaces.
      assets::write_png(frame_path(options, r, "_spectator"),
                        spectator->draw(twin, spectator_at(target), T_world_projector, image));
    }

    // Projecting: the target may be moved or taken away; the tracker (tracking mode) follows it at
    // camera rate, and a lost or missing target is searched for within the follower's budget.
    r.moved = target.config.motion_on(r.target_visit) != nullptr;
    if (options.mode == TourMode::tracking || r.moved) {
      std::vector<alignment::TargetFollower*> lanes{&followers[i]};
      for (const NeighbourLight& n : lights) lanes.push_back(&followers[n.target]);
      report.interrupted = !dwell(DwellContext{twin, i, models, truth, options, noise_seed, lights}, lanes, r);
    }
    for (const NeighbourLight& l : lights) r.neighbours.push_back(finished(l));
    if (spectator && r.moved && !report.interrupted) {
      // A moved target: what the visitor sees at the end of the dwell, where the target went and where
      // the light went (followed, or left where the target was).
      const auto image = projector_image(r.shown_at_end, models.projector_from_target(r.T_camera_target_at_end));
      assets::write_png(frame_path(options, r, "_spectator_end"),
                        spectator->draw(twin, spectator_at(target), T_world_projector, image));
    }
    twin.end_visit(i, r.target_visit);  // back home, or left where it was moved
    if (report.interrupted) break;      // this visit did not finish: keep the finished ones only
    if (options.on_visit) options.on_visit(r);
    report.visits.push_back(std::move(r));
  }
  report.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return report;
}

}  // namespace projbot::twin
