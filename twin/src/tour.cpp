#include "projbot/twin/tour.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <optional>
#include <stop_token>
#include <tuple>
#include <utility>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/projection.hpp"
#include "projbot/live/projection_loop.hpp"
#include "projbot/twin/display_error.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/world.hpp"
#include "sim_clock_devices.hpp"
#include "tour_frames.hpp"

namespace projbot::twin {
namespace {

using namespace detail;  // the tour's frame measurement (tour_frames.hpp)

using Clock = std::chrono::steady_clock;

constexpr double kConvergedMm = 3.0;    // the goal for a visit's mean error
constexpr double kMovingSampleS = 0.1;  // TourOptions::appearance: a moving target's frames scored this far apart
// ... and the first this long of a motion scored apart: a 30 Hz camera's frames, tracked, reach the
// projector 50-67 ms after they are taken, and the prediction needs two of them to see the new speed.
constexpr double kStartingS = 0.2;

// Where --frames writes one of a visit's pictures: DIR/visitNN_TARGET<suffix>.png.
std::filesystem::path frame_path(const TourOptions& options, const VisitReport& r, const char* suffix) {
  char file[96];
  std::snprintf(file, sizeof file, "visit%02d_%s%s.png", r.visit, r.target.c_str(), suffix);
  return options.frames_dir / file;
}

// The projector as the twin's light follows it and as the session believes it (options.calibration).
ProjectorModels projector_models(const config::Scene& scene, const TourOptions& options) {
  ProjectorModels models{scene.projector, scene.projector, scene.pan_tilt.T_projector_camera};
  if (options.calibration) {
    static_cast<config::Pinhole&>(models.believed) = options.calibration->projector;
    models.believed.distortion = options.calibration->projector.distortion;
    if (options.calibration->photometry) {  // its response and mixing; the lumens stay the scene's unless it gave them
      models.believed.photometry = *options.calibration->photometry;
      if (!options.calibration->photometry_brightness)
        models.believed.photometry.brightness_lm = scene.projector.photometry.brightness_lm;
    }
    models.T_projector_camera = options.calibration->T_projector_camera;
  }
  return models;
}

// The trackers' policy for the tour's mode. The paper aligned once per stop with plain ICP from the
// initial guess; ours is point-to-plane, coarse to fine, rejects correspondences whose normals disagree,
// and adds local restarts, FPFH re-initialisation and the quality gate.
alignment::WorkerConfig follower_config(const TourOptions& options) {
  alignment::WorkerConfig follow;
  follow.predict = options.predict;
  follow.motion = options.motion;
  if (options.mode == TourMode::odometry) {
    alignment::AcquisitionConfig& acquisition = follow.acquisition;
    acquisition.restart_angle_deg = 0.0;
    acquisition.reinitialise = false;
    // Plain ICP as the paper ran it: point-to-point (PCL's SVD estimation), one pass with a fixed
    // correspondence distance and iteration budget, on the scan near the expected target.
    acquisition.point_to_plane = false;
    acquisition.icp_distances_m = {0.05};
    acquisition.icp_iterations = 30;
    acquisition.max_normal_angle_deg = 180.0;
    acquisition.icp_median_factor = 0.0;
  }
  return follow;
}

// Each target's content and the surface the scene gives it, as the session knows them.
std::vector<engine::CompensationPlan::Target> compensation_targets(const Twin& twin) {
  std::vector<engine::CompensationPlan::Target> out;
  for (const TwinTarget& t : twin.targets()) out.push_back({&t.model, t.config.surface.albedo, t.surface_texture});
  return out;
}

// What every stop of a tour shares: the twin, its camera on the simulated clock, and a follower and its
// tracker per target (the follower's aligner acquires at each stop, its policy tracks while projecting: the
// same one the live engine's TrackerWorker runs).
struct Tour {
  Tour(const config::Scene& s, const TourOptions& o, engine::Renderer& r, Twin& t);
  const config::Scene& scene;
  const TourOptions& options;
  engine::Renderer& renderer;
  Twin& twin;
  ProjectorModels models;
  SimClock clock;
  TourCamera camera{twin, clock};
  std::vector<alignment::TargetFollower> followers;       // by index into Twin::targets()
  std::vector<SimClockTracker> trackers;                  // likewise
  std::vector<alignment::PoseTracker*> by_scene;          // the trackers by scene index, for StopSequence::visit
  std::unique_ptr<engine::RenderTarget> projector_frame;  // with --frames or appearance
  std::unique_ptr<SpectatorView> spectator;
  std::unique_ptr<SpectatorView> colour_camera;          // the RGB-D camera's colour under the projector's light
  engine::CompensationPlan plan;                         // by index into Twin::targets()
  std::vector<engine::ReflectanceMap> reflectance_maps;  // likewise: TourOptions::reflectance_map's
};

Tour::Tour(const config::Scene& s, const TourOptions& o, engine::Renderer& r, Twin& t)
    : scene(s),
      options(o),
      renderer(r),
      twin(t),
      models(projector_models(s, o)),
      plan(compensation_targets(t), s.room.ambient_lux, true) {
  clock.processing_ms = options.processing_ms;
  reflectance_maps.resize(twin.targets().size());
  const alignment::WorkerConfig follow = follower_config(options);
  followers.reserve(twin.targets().size());
  for (const auto& target : twin.targets()) followers.emplace_back(target.cloud, twin.camera(), follow);
  trackers.reserve(followers.size());
  for (auto& f : followers) trackers.emplace_back(options.mode, f, twin, clock);
  by_scene.assign(scene.targets.size(), nullptr);
  for (const live::Target& target : twin.session_targets())
    by_scene[static_cast<std::size_t>(target.scene_index)] =
        &trackers[twin.target_index(scene.targets[static_cast<std::size_t>(target.scene_index)].name)];
  if (!options.frames_dir.empty()) std::filesystem::create_directories(options.frames_dir);
  if (!options.frames_dir.empty() || options.appearance) {
    projector_frame = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
    spectator = std::make_unique<SpectatorView>(renderer, scene.projector);
  }
  if (options.measure_reflectance)
    colour_camera = std::make_unique<SpectatorView>(renderer, scene.projector, twin.camera_pinhole());
}

// One visit of the tour as the session runs it (live::StopSequence::visit, in lockstep). On the stop's
// first frame: the acquisitions' errors (the visited target's and each neighbour's) and, with --frames,
// the pictures. Then, while the robot dwells (tracking mode, or a target that moves), projection on the
// simulated clock: the projector at its refresh rate; each frame is a step of `run`'s projection loop
// (live::ProjectionLoop::frame on the simulated clock: each lit target's newest result ready when the frame
// starts, blanked when lost, else predicted to the frame's display time and moved to the projector by
// Eq. 2), and its error is measured against the target's true pose at its display time. The frames are
// measured, not drawn (drawn only for --frames and appearance).
class TourStop final : public live::StopObserver {
 public:
  TourStop(Tour& tour, int visit) : tour_(tour), visit_(visit) {}
  // Dwell::camera: the robot has arrived and aimed; the camera is set for the stop.
  alignment::RgbdCamera& arrived(const live::Stop& at);
  void frame(const live::Stop& at, int k, const alignment::RgbdFrame& f,
             const std::vector<std::optional<alignment::PoseSample>>& samples) override;
  // Dwell::over: asked to stop, or the dwell's projector frames are all measured.
  bool over() const { return interrupted || !dwelling_ || next_ > frames_; }
  // After the session's visit: the neighbours' reports, and a moved target's last picture.
  void finish();
  std::size_t target() const { return target_index_; }  // index into Twin::targets()
  VisitReport report;
  bool interrupted = false;  // the tour was asked to stop in the middle of the dwell

 private:
  void at_arrival(const live::Stop& at, const alignment::RgbdFrame& f);
  // compensate: the plan's compensation (TourOptions::compensation unless said otherwise).
  // neighbours: the stop's lit neighbours drawn too (false: the visited target alone).
  assets::Image projector_image(bool lit, const Eigen::Matrix4d& T_projector_target, std::optional<bool> compensate = {},
                                bool neighbours = true);
  // on_picture: the visitor's picture with compensation on, kept there.
  std::array<AppearanceSample, 2> measure_appearance(bool moving, bool lit, const Eigen::Matrix4d& T_projector_target,
                                                     const Eigen::Matrix4d* T_projector_still = nullptr,
                                                     assets::Image* on_picture = nullptr);
  void sample_motion(const TimelineSample& s, const live::DrawnPose* visited);
  void measure_reflectance();
  assets::Image spectator_picture(const assets::Image& projector);
  void write_pictures(const assets::Image& colour);
  void start_projection();
  void take_results(double start_s);
  void project(double start_s);
  void end_dwell();

  Tour& tour_;
  int visit_;
  std::size_t target_index_ = 0;  // the visited target, in Twin::targets()
  std::vector<std::size_t> lit_;  // the stop's lit targets, likewise: the visited one first
  robot::HeadPoses truth_;
  std::uint32_t noise_seed_ = 0;
  std::vector<NeighbourLight> lights_;
  std::optional<DwellContext> dwell_;
  // The dwell.
  bool dwelling_ = false;
  int frames_ = 0, next_ = 1;  // projector frames: in all, and the next to measure (1-based)
  double period_s_ = 0.0;
  std::optional<live::ProjectionLoop> loop_;   // `run`'s projection loop, stepped on the simulated clock
  live::ProjectionInputs inputs_;              // to it: the lit targets by their place in lit_, newest_
  double now_s_ = 0.0;                         // the simulated clock: the stop's time, the loop's too
  std::vector<alignment::PoseSample> newest_;  // each lit target's newest result: at first its arrival's
  alignment::PoseSample drawn_;                // the visited target's newest result not lost
  bool shown_ = false;                         // the visited target is lit in the newest frame
  double wall_to_light_ms_ = 0.0, seen_track_ms_ = 0.0;
  double motion_end_s_ = 0.0;
  double back_under_ = -1.0;  // when the error went back under the goal for good, -1 while it is not
  bool ever_over_ = false;
  // TourOptions::appearance: the frames scored while the target moves (starting: off, on; then: off, on),
  // and when the next is due.
  std::array<std::vector<AppearanceSample>, 4> moving_samples_;
  double next_moving_sample_s_ = 0.0;
  // --frames: the worst compensated frame of each part of the motion (starting, then), for the pictures.
  std::array<std::pair<double, assets::Image>, 2> worst_moving_{};
};

alignment::RgbdCamera& TourStop::arrived(const live::Stop& at) {
  const std::string& name = tour_.scene.targets[static_cast<std::size_t>(at.target)].name;
  target_index_ = tour_.twin.target_index(name);
  report.visit = visit_ + 1;
  report.target_visit = at.target_visit;
  report.target = name;
  report.drive_s = at.drive.drive_seconds;
  report.base_error_cm = 100.0 * at.drive.error_m;
  report.base_error_deg = config::degrees(at.drive.error_rad);
  report.odometry_error_cm = 100.0 * at.drive.odometry_error_m;
  truth_ = tour_.twin.true_head();
  TwinTarget& target = tour_.twin.targets()[target_index_];
  target.in_world = tour_.twin.scripted_presence(target_index_, report.target_visit, 0.0);
  report.target_present = target.in_world;
  report.moved = target.config.motion_on(report.target_visit) != nullptr;
  const bool tracking = tour_.options.mode == TourMode::tracking;
  dwelling_ = tracking || report.moved;
  for (const live::LitTarget& l : at.lit)
    lit_.push_back(tour_.twin.target_index(tour_.scene.targets[static_cast<std::size_t>(l.target)].name));
  noise_seed_ = static_cast<std::uint32_t>(tour_.options.seed * 100003 + static_cast<std::uint64_t>(visit_) * 1009);
  const auto wanted = [this](double t_s) {
    return std::any_of(lit_.begin(), lit_.end(), [&](std::size_t j) { return tour_.trackers[j].free_at(t_s); });
  };
  tour_.camera.at_stop({target_index_, report.target_visit, truth_.T_world_camera.matrix(), noise_seed_,
                        tour_.options.mode != TourMode::odometry, tracking, report.target_present, wanted});
  return tour_.camera;
}

void TourStop::frame(const live::Stop& at, int k, const alignment::RgbdFrame& f,
                     const std::vector<std::optional<alignment::PoseSample>>& /*samples: ready later, see SimClockTracker*/) {
  if (k == 0) at_arrival(at, f);
  if (!dwelling_) return;
  // The projector frames that start before the next camera frame is taken.
  const double next_frame_s = (k + 1) / kCameraHz;
  for (; next_ <= frames_ && next_frame_s > next_ * period_s_ + 1e-9; ++next_) {
    if (tour_.options.stop_requested && tour_.options.stop_requested()) {
      interrupted = true;
      return;
    }
    project(next_ * period_s_);
  }
  if (next_ > frames_) end_dwell();
}

// Capture, Eq. 1, acquisition (the trackers', from the session), Eq. 2, and the errors at the markers.
void TourStop::at_arrival(const live::Stop& at, const alignment::RgbdFrame& f) {
  const TwinTarget& target = tour_.twin.targets()[target_index_];
  report.capture_ms = tour_.camera.arrival_ms();
  std::tie(report.guess_error_cm, report.guess_error_deg) = guess_error(truth_, target, at.lit.front().T_camera_target_guess);
  const Acquired& a = tour_.trackers[target_index_].acquired();
  report.icp = a.icp;
  report.free_space = a.free_space;
  report.projected = a.projected;
  report.align_ms = a.align_ms;
  if (report.projected) {
    report.first_light_s = 0.0;
    report.first_light_wall_ms = report.align_ms;
    report.lit_frames = 1;
  }
  const Eigen::Matrix4d T_world_projector = truth_.T_world_projector.matrix();
  report.view = alignment::view_constraints(target.cloud, report.icp.T_scan_model, tour_.twin.camera());
  report.T_projector_target_estimated = tour_.models.projector_from_target(report.icp.T_scan_model);
  report.T_projector_target_true = alignment::rigid_inverse(T_world_projector) * target.T_world_target_true;
  const MarkerErrors e = marker_errors(tour_.twin, target_index_, tour_.models, T_world_projector, report.icp.T_scan_model);
  report.markers = e.markers;
  report.mean_mm = e.mean_mm;
  report.max_mm = e.max_mm;
  if (report.projected) report.far_off.count(e.mean_mm);
  for (std::size_t k = 1; k < at.lit.size(); ++k)
    lights_.push_back(neighbour_light(tour_.twin, tour_.trackers[lit_[k]].acquired(), lit_[k], at.lit[k], truth_, tour_.models));
  if (!tour_.options.frames_dir.empty()) write_pictures(f.colour);
  if (tour_.options.measure_reflectance && report.projected) measure_reflectance();
  if (tour_.options.appearance)
    for (const AppearanceSample& sample : measure_appearance(false, report.projected, report.T_projector_target_estimated))
      report.appearance.push_back(sample);

  dwell_.emplace(DwellContext{tour_.twin, target_index_, tour_.models, truth_, tour_.options, lights_});
  start_projection();
  wall_to_light_ms_ = report.align_ms;
  const config::TargetMotion* motion = target.config.motion_on(report.target_visit);
  motion_end_s_ = motion ? motion->end_s() : 0.0;
  frames_ = static_cast<int>(std::lround(tour_.options.dwell_s * tour_.models.truth.refresh_hz));
}

// The dwell's projection from the arrival's estimates: the projector's frames as the twin's projector
// paces them (its refresh and input lag), Eq. 2 with the believed R_cp, T_cp; the camera is not watched for
// silence (the tour runs in lockstep with it).
void TourStop::start_projection() {
  live::ProjectionLoopConfig config;
  config.projection.T_projector_camera = tour_.models.T_projector_camera;
  config.projection.refresh_hz = tour_.models.truth.refresh_hz;
  config.projection.input_lag_ms = tour_.models.truth.input_lag_ms;
  config.projection.predict = tour_.options.predict;
  config.projection.silent_camera_s = 0.0;
  period_s_ = 1.0 / config.projection.refresh_hz;
  live::LitStop lit{{}, 0.0, visit_};
  for (std::size_t k = 0; k < lit_.size(); ++k) {
    lit.targets.push_back(static_cast<int>(k));
    alignment::PoseSample arrival;
    const Acquired& a = tour_.trackers[lit_[k]].acquired();
    arrival.T_camera_target = arrival.motion.T = a.icp.T_scan_model;
    arrival.lost = !a.projected;
    newest_.push_back(arrival);
  }
  drawn_ = newest_.front();
  shown_ = report.projected;
  inputs_.stop = [lit] { return lit; };
  inputs_.poses = [this](int k, alignment::PoseSample& out) { return (out = newest_[static_cast<std::size_t>(k)]), true; };
  const config::Clock simulated{[this] { return now_s_; }, [this](double until_s) { now_s_ = std::max(now_s_, until_s); }};
  loop_.emplace(tour_.renderer, tour_.models.believed, std::vector<engine::DrawItem>{}, config, simulated);
  loop_->begin();
}

// The projector's frame: the target drawn at T_projector_target when lit, its neighbours where lit, else
// all black.
assets::Image TourStop::projector_image(bool lit, const Eigen::Matrix4d& T_projector_target, std::optional<bool> compensate,
                                        bool neighbours) {
  std::vector<engine::DrawItem> items;
  const bool on = compensate.value_or(tour_.options.compensation);
  // The estimator's side: the scene's surfaces and room light, the believed projector, the drawn poses.
  const auto item = [&](std::size_t target, const Eigen::Matrix4d& T) {
    const engine::Compensation comp = on ? tour_.plan.at(target, visit_, tour_.models.believed, T) : engine::Compensation{};
    items.push_back({tour_.twin.target_model_ids()[target], T, comp});
  };
  if (lit) item(target_index_, T_projector_target);
  for (const NeighbourLight& n : lights_)
    if (n.shown && neighbours) item(n.target, tour_.models.projector_from_target(n.drawn.T_camera_target));
  tour_.renderer.draw_frame(*tour_.projector_frame, tour_.models.believed, items);
  return tour_.projector_frame->read_back();
}

// What a visitor beside the robot sees of the projector's frame, looking at the target where it truly
// stands now.
assets::Image TourStop::spectator_picture(const assets::Image& projector) {
  const TwinTarget& target = tour_.twin.targets()[target_index_];
  const Eigen::Matrix4d T_world_spectator =
      spectator_pose(truth_.T_world_camera.translation(), model_middle(target, target.T_world_target_true));
  return tour_.spectator->draw(tour_.twin, T_world_spectator, truth_.T_world_projector.matrix(), projector);
}

// The visited target's reflectance, measured at its estimated pose; the compensation takes the mean of
// its measurements so far from now on.
void TourStop::measure_reflectance() {
  const std::vector<engine::ReflectancePoint> points = measured_reflectance(
      *tour_.colour_camera, tour_.twin, target_index_, truth_.T_world_camera.matrix(), truth_.T_world_projector.matrix(),
      report.icp.T_scan_model, tour_.models.believed, report.T_projector_target_estimated);
  report.measured_albedo = engine::median_albedo(points);
  if (!tour_.options.reflectance_map) {
    if (report.measured_albedo) tour_.plan.add_measured_albedo(target_index_, *report.measured_albedo);
    return;
  }
  engine::ReflectanceMap& map = tour_.reflectance_maps[target_index_];  // refined over its visits
  map.add(points);
  if (const std::optional<assets::Image> image = map.image()) {
    auto surface = std::make_shared<const assets::Image>(*image);
    tour_.renderer.set_surface(tour_.twin.target_model_ids()[target_index_], *surface);
    tour_.plan.set_surface(target_index_, std::move(surface));
  }
}

// What a visitor sees of the visited target drawn at T_projector_target, compensation off and on, against
// its content under the reference light scaled by the visit's gain; with --frames both pictures. With
// T_projector_still (moving), each also drawn there: the target tracked exactly, as if it stood still.
std::array<AppearanceSample, 2> TourStop::measure_appearance(bool moving, bool lit, const Eigen::Matrix4d& T_projector_target,
                                                             const Eigen::Matrix4d* T_projector_still,
                                                             assets::Image* on_picture) {
  const TwinTarget& target = tour_.twin.targets()[target_index_];
  const Eigen::Matrix4d T_world_spectator =
      spectator_pose(truth_.T_world_camera.translation(), model_middle(target, target.T_world_target_true));
  tour_.plan.at(target_index_, visit_, tour_.models.believed, T_projector_target);  // the visit's gain, if not yet chosen
  const double gain = tour_.plan.gain(target_index_);
  // The geometry and the content once; each frame's light on them.
  const SpectatorScene scene = tour_.spectator->look(tour_.twin, T_world_spectator, truth_.T_world_projector.matrix());
  const ContentView view = tour_.spectator->content(tour_.twin, target_index_, T_world_spectator, scene);
  const auto score = [&](const SpectatorPicture& seen) {
    return score_appearance(seen, view, gain, tour_.scene.room.ambient_lux, tour_.models.truth.photometry);
  };
  std::array<AppearanceSample, 2> samples;
  for (const bool on : {false, true}) {
    const auto t0 = Clock::now();
    const auto image = projector_image(lit, T_projector_target, on);
    const double ms = ms_since(t0);
    const SpectatorPicture seen = tour_.spectator->light(scene, image);
    AppearanceSample sample{.compensation = on, .moving = moving, .gain = gain, .ms_per_frame = ms, .score = score(seen)};
    if (T_projector_still)
      sample.still_psnr_db = score(tour_.spectator->light(scene, projector_image(true, *T_projector_still, on))).psnr_db;
    samples[on ? 1 : 0] = sample;
    if (on && on_picture) *on_picture = seen.image;
    if (!moving && !tour_.options.frames_dir.empty())
      assets::write_png(frame_path(tour_.options, report, on ? "_spectator_on" : "_spectator_off"), seen.image);
  }
  if (!moving && lit)  // the gain's own measure: the projector's pixels on the target alone
    samples[1].projector_saturated_share = saturated_share(projector_image(true, T_projector_target, true, false),
                                                           projector_image(true, T_projector_target, false, false));
  return samples;
}

// While the visited target moves: its frames scored every kMovingSampleS of display time, from the first
// frame of the motion on (the sudden start included), each beside itself drawn at the true pose.
void TourStop::sample_motion(const TimelineSample& s, const live::DrawnPose* visited) {
  if (!tour_.options.appearance || !s.moving || s.t_s < next_moving_sample_s_) return;
  next_moving_sample_s_ = s.t_s + kMovingSampleS - 1e-9;
  const Eigen::Matrix4d T_camera_target = light_pose(visited, drawn_, s.t_s, tour_.options.predict);
  const Eigen::Matrix4d T_camera_true =
      alignment::rigid_inverse(truth_.T_world_camera.matrix()) * tour_.twin.targets()[target_index_].T_world_target_true;
  const Eigen::Matrix4d T_projector_still = tour_.models.projector_from_target(T_camera_true);
  assets::Image picture;
  const auto samples = measure_appearance(true, shown_, tour_.models.projector_from_target(T_camera_target), &T_projector_still,
                                          tour_.options.frames_dir.empty() ? nullptr : &picture);
  const config::TargetMotion* motion = tour_.twin.targets()[target_index_].config.motion_on(report.target_visit);
  const bool starting = motion && s.t_s < motion->start_s + kStartingS;
  auto& worst = worst_moving_[starting ? 0 : 1];
  const AppearanceScore& on = samples[1].score;
  if (!picture.rgba.empty() && on.pixels > 0 && (worst.second.rgba.empty() || on.psnr_db < worst.first))
    worst = {on.psnr_db, std::move(picture)};
  for (AppearanceSample a : samples) {
    a.starting = starting;
    moving_samples_[(starting ? 0 : 2) + (a.compensation ? 1 : 0)].push_back(a);
  }
}

// --frames at arrival: the projector's frame, the RGB-D camera's colour (registered to the depth that
// was used) and the visitor's view.
void TourStop::write_pictures(const assets::Image& colour) {
  const auto t0 = Clock::now();
  const auto image = projector_image(report.projected, report.T_projector_target_estimated);
  report.frame_ms = ms_since(t0);
  assets::write_png(frame_path(tour_.options, report, ""), image);
  assets::write_png(frame_path(tour_.options, report, "_camera"),
                    !colour.rgba.empty() ? colour : tour_.twin.capture_colour(truth_.T_world_camera.matrix(), noise_seed_));
  assets::write_png(frame_path(tour_.options, report, "_spectator"), spectator_picture(image));
}

// The results each lit target's tracker has ready by start_s (tracking mode): the newest of each is what
// the frame starting then may draw.
void TourStop::take_results(double start_s) {
  for (std::size_t k = 0; k < lit_.size(); ++k)
    for (const auto& sample : tour_.trackers[lit_[k]].ready_by(start_s)) {
      newest_[k] = sample;
      if (sample.drawable()) (k == 0 ? drawn_ : lights_[k - 1].drawn) = sample;
    }
  const double track_ms = tour_.trackers[target_index_].track_ms();  // the visited target's frames tracked since the last
  if (report.first_light_s < 0.0) wall_to_light_ms_ += track_ms - seen_track_ms_;
  seen_track_ms_ = track_ms;
}

// One projector frame of the dwell, starting at start_s: what it draws decided as in `run`, and its error
// measured at its display time.
void TourStop::project(double start_s) {
  const DwellContext& c = *dwell_;
  now_s_ = start_s;
  if (tour_.options.mode == TourMode::tracking) take_results(start_s);
  const live::DecidedFrame frame = *loop_->frame(nullptr, inputs_, nullptr);  // not drawn: always a frame
  const std::vector<live::DrawnPose>& drawn = frame.drawn;
  const auto drawn_of = [&drawn](int k) {
    const auto it = std::find_if(drawn.begin(), drawn.end(), [k](const live::DrawnPose& d) { return d.target == k; });
    return it == drawn.end() ? nullptr : &*it;
  };
  const live::DrawnPose* visited = drawn_of(0);
  shown_ = visited != nullptr;
  if (visited && tour_.options.compensation)  // the gain follows the pose, as run's loop has it do
    tour_.plan.at(target_index_, visit_, tour_.models.believed, visited->T_projector_target, frame.display_s);
  const TimelineSample s = measure_frame(c, report, frame.display_s, visited, drawn_);
  sample_motion(s, visited);
  for (std::size_t k = 1; k < lit_.size(); ++k) measure_neighbour(c, lights_[k - 1], drawn_of(static_cast<int>(k)));
  report.timeline.push_back(s);
  report.lit_frames += shown_ ? 1 : 0;
  if (shown_ && s.in_world) report.far_off.count(s.mean_mm, s.change_unseen);
  if (shown_ && report.first_light_s < 0.0) {
    report.first_light_s = s.t_s;
    report.first_light_wall_ms = wall_to_light_ms_;
  }
  const double gone_s = tour_.camera.gone_s();
  if (!shown_ && gone_s >= 0.0 && report.blank_after_removal_s < 0.0) report.blank_after_removal_s = s.t_s - gone_s;
  if (s.moving) report.max_mm_moving = std::max(report.max_mm_moving, s.mean_mm);
  if (std::isnan(s.mean_mm) && shown_) return;  // no marker in the projector's light: nothing measured
  const bool good = shown_ && s.mean_mm <= kConvergedMm;
  if (!good && tour_.twin.targets()[target_index_].in_world) {
    ever_over_ = true;
    back_under_ = -1.0;
  } else if (good && back_under_ < 0.0 && s.t_s >= motion_end_s_) {
    back_under_ = s.t_s;
  }
}

// The dwell's figures once its last projector frame is measured.
void TourStop::end_dwell() {
  const bool tracking = tour_.options.mode == TourMode::tracking;
  SimClockTracker& tracker = tour_.trackers[target_index_];
  report.shown_at_end = shown_;
  report.T_camera_target_at_end = drawn_.T_camera_target;
  report.track_ms_mean = tracking && tracker.tracked() > 0 ? tracker.track_ms() / tracker.tracked() : 0.0;
  report.tracked_frames = tracker.tracked();
  report.dropped_frames = tour_.camera.frames() - tracker.tracked();
  if (tracking) {
    report.search = tracker.follower().search_stats();
    report.second_pass_frames = tracker.follower().second_passes();
  }
  report.reconverge_s = !ever_over_ ? 0.0 : back_under_ >= 0.0 ? std::max(0.0, back_under_ - motion_end_s_) : -1.0;
  summarise_timeline(report);
}

void TourStop::finish() {
  for (const NeighbourLight& l : lights_) report.neighbours.push_back(finished(l));
  for (const auto& samples : moving_samples_)
    if (!samples.empty()) report.appearance.push_back(mean_appearance(samples));
  for (std::size_t part = 0; part < worst_moving_.size(); ++part)
    if (!worst_moving_[part].second.rgba.empty())
      assets::write_png(frame_path(tour_.options, report, part == 0 ? "_spectator_starting_worst" : "_spectator_moving_worst"),
                        worst_moving_[part].second);
  if (!tour_.options.frames_dir.empty() && report.moved && !interrupted) {
    // A moved target: what the visitor sees at the end of the dwell, where the target went and where
    // the light went (followed, or left where the target was).
    const auto image = projector_image(report.shown_at_end, tour_.models.projector_from_target(report.T_camera_target_at_end));
    assets::write_png(frame_path(tour_.options, report, "_spectator_end"), spectator_picture(image));
  }
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
  // Otherwise TwinOptions' own: localised where the build has MRPT, odometry in a portable build.
  if (options.mode == TourMode::odometry) twin_options.pose_source = robot::PoseSource::odometry;
  twin_options.seed = options.seed;
  twin_options.depth_noise = options.depth_noise;
  twin_options.depth_model = options.fitted_depth ? alignment::KinectNoiseConfig::fitted() : alignment::KinectNoiseConfig{};
  twin_options.stop_requested = options.stop_requested;
  Twin twin(scene, twin_options, renderer);
  Tour tour(scene, options, renderer, twin);
  // The stop sequence (drive, aim, Eq. 1 for the visited target and its neighbours, capture, acquire,
  // track) is the session's, as in `projbot run`; the twin serves its base, pan-tilt and camera, and
  // the tour's trackers track on the simulated clock.
  live::StopSequence session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());

  TourReport report;
  report.mode = options.mode;
  report.seed = options.seed;
  report.predict = options.predict;
  report.processing_ms = options.processing_ms;
  report.depth_model = !options.depth_noise ? "none" : options.fitted_depth ? "fitted" : "kinect";
  report.projector = scene.projector;
  const int visits = options.visits > 0 ? options.visits : static_cast<int>(scene.visits.size());
  const auto stop_requested = [&] { return options.stop_requested && options.stop_requested(); };
  const std::stop_source never;  // the tour asks options.stop_requested between projector frames
  for (int v = 0; v < visits && !(report.interrupted = stop_requested()); ++v) {
    TourStop stop(tour, v);
    live::Dwell dwell;
    dwell.camera = [&](const live::Stop& at, double) -> alignment::RgbdCamera& { return stop.arrived(at); };
    dwell.over = [&](const live::Stop&, int, double) { return stop.over(); };
    dwell.lockstep = true;
    session.visit(v, tour.by_scene, dwell, stop, never.get_token());
    stop.finish();
    twin.end_visit(stop.target(), stop.report.target_visit);  // back home, or left where it was moved
    if ((report.interrupted = stop.interrupted)) break;       // this visit did not finish: keep the finished ones only
    if (options.on_visit) options.on_visit(stop.report);
    report.visits.push_back(std::move(stop.report));
  }
  report.wall_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return report;
}

}  // namespace projbot::twin
