// projbot run: the live engine. The render thread (this one) draws every frame from the newest accepted
// pose of each target's tracker worker; the robot thread drives the tour, aims, hands each stop's
// initial guess (Eq. 1) to the worker and, in the twin, plays the depth camera at 30 Hz.

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/latest_value.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/hardware/device_session.hpp"
#include "projbot/hardware/devices.hpp"
#include "projbot/session/live_loop.hpp"
#include "projbot/session/replay.hpp"
#include "projbot/session/session.hpp"
#include "projbot/session/trackers.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/display_error.hpp"
#include "projbot/twin/twin_session.hpp"
#include "projbot/twin/world.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

// What the render thread draws at a stop (session::LitTarget, as the render thread needs it): the visited
// target or a neighbour expected in the projector's view there (issue 11, item 5), with the twin's truth.
struct DrawnTarget {
  int target = -1;       // scene index: its worker and draw item
  int target_visit = 0;  // this target's n-th visit (its motion script); 0: still
  std::size_t twin = 0;  // its index in the twin (when a twin serves the session)
};

// What the robot thread tells the render thread: which targets the robot is projecting onto (none while
// it drives; the visited one first) and since when; poses captured before that belong to an earlier stop.
struct RobotState {
  std::vector<DrawnTarget> lit;
  double since_s = 0.0;
  int visit = 0;
  bool done = false;
  // The twin's truth at the stop, so the render thread measures each frame at its display time; null
  // where nothing serves a truth (a replay, the configured robot).
  std::shared_ptr<const twin::StopMeter> meter{};
};

// The error of the frames drawn, against the twin's truth at each frame's display time: the mean distance
// between where the projector's light lands and where the markers truly are then (mm; the tour's
// definition, twin::marker_errors).
void print_display_errors(std::ostream& out, const session::LiveFigures& f) {
  double still = 0.0, moving = 0.0;
  for (const double e : f.still_mm) still += e / static_cast<double>(f.still_mm.size());
  for (const double e : f.moving_mm) moving += e / static_cast<double>(f.moving_mm.size());
  out << "error at display (markers drawn vs true, twin): ";
  if (f.moving_mm.empty())
    out << "no frame while a target moved";
  else
    out << "while moving mean " << moving << " mm, p95 " << engine::percentile(f.moving_mm, 0.95) << " mm, max "
        << engine::percentile(f.moving_mm, 1.0) << " mm over " << f.moving_mm.size() << " frames";
  out << "; still mean " << (f.still_mm.empty() ? std::nan("") : still) << " mm over " << f.still_mm.size() << " frames\n";
}

// The mean marker error of a target drawn (at its display time and pose), against the twin's truth then;
// NaN where no marker can be measured or the stop has no truth (a replay, the configured robot).
session::DisplayError marker_error(const config::Scene& scene, const RobotState& robot, const session::DrawnPose& drawn) {
  const auto lit =
      std::find_if(robot.lit.begin(), robot.lit.end(), [&](const DrawnTarget& l) { return l.target == drawn.target; });
  if (!robot.meter || lit == robot.lit.end()) return {std::nan(""), false};
  const double t = drawn.display_s - robot.since_s;
  const config::TargetMotion* m = scene.targets[static_cast<std::size_t>(drawn.target)].motion_on(lit->target_visit);
  return {robot.meter->measure(lit->twin, lit->target_visit, drawn.T_camera_target, t).mean_mm, m && m->moving_at(t)};
}

struct RunOptions {
  int visits = 0;
  double dwell_s = 4.0;
  std::uint64_t seed = 1;
  double seconds = 0.0;  // 0: until the tour ends
  bool headless = false, predict = true, compensate = true;
};

// Per live frame: from the camera's capture stamp, and from its next() returning, to the frame handed to
// every lit worker (ms).
struct Handoffs {
  std::vector<double> from_capture_ms, in_session_ms;
  std::atomic<double> last_s{0.0};  // the newest live hand-off (steady clock), read by the render thread
};

// What the robot thread tells the render thread at each step of the session, with the twin's truth when
// the twin serves the robot; in a replay, each lockstep frame's poses are also checked against the recording's.
class RunObserver final : public session::StopObserver {
 public:
  RunObserver(const config::Scene& scene, alignment::LatestValue<RobotState>& state, Handoffs& handoffs, twin::Twin* twin,
              session::PoseCheck* check)
      : scene_(scene), state_(state), handoffs_(handoffs), twin_(twin), check_(check) {}
  void driving(int visit) override { state_.publish({.lit = {}, .since_s = config::steady_now_s(), .visit = visit + 1}); }
  void lit(const session::Stop& stop, double since_s) override {
    std::cout << "visit " << stop.visit + 1 << ": " << scene_.targets[static_cast<std::size_t>(stop.target)].name << ", drove "
              << std::fixed << std::setprecision(1) << stop.drive.drive_seconds << " s"
              << (stop.drive.arrived ? "" : " (not arrived)") << ", believed at x " << std::setprecision(3)
              << stop.drive.estimate.x_m << " m, y " << stop.drive.estimate.y_m << " m, heading " << std::setprecision(1)
              << stop.drive.estimate.theta_rad * 180.0 / M_PI << " deg; lit " << stop.lit.size() << " target(s)";
    if (stop.drive.corrections > 0)  // localised on a laser: how far odometry alone had drifted from that
      std::cout << "; " << stop.drive.corrections << " laser scans matched (" << stop.drive.rejected
                << " rejected), odometry alone " << std::setprecision(0)
                << 1000.0 * robot::distance_m(stop.drive.estimate, stop.drive.odometry) << " mm away";
    std::cout << std::endl;
    std::vector<DrawnTarget> lit;
    for (const session::LitTarget& l : stop.lit)
      lit.push_back({l.target, l.target == stop.target ? stop.target_visit : 0, twin_ ? twin_index(l.target) : 0});
    std::shared_ptr<const twin::StopMeter> meter{};
    if (twin_)
      meter = std::make_shared<const twin::StopMeter>(
          *twin_, twin::ProjectorModels{scene_.projector, scene_.projector, scene_.pan_tilt.T_projector_camera},
          twin_->true_head().T_world_projector.matrix());
    state_.publish({lit, since_s, stop.visit + 1, false, std::move(meter)});
  }
  void frame(const session::Stop& stop, int k, const alignment::RgbdFrame& f,
             const std::vector<std::optional<alignment::PoseSample>>& samples) override {
    if (samples.empty()) {  // live: at the hand-off
      const double now = config::steady_now_s();
      handoffs_.from_capture_ms.push_back(1000.0 * (now - f.depth.capture_time_s));
      handoffs_.in_session_ms.push_back(1000.0 * (now - f.delivered_s));
      handoffs_.last_s = now;
    }
    if (check_) check_->compare(scene_, stop, k, samples);
  }
  void left(const session::Stop& stop) override {
    if (twin_) twin_->end_visit(twin_index(stop.target), stop.target_visit);  // back home, or left where it was moved
  }

 private:
  std::size_t twin_index(int target) const { return twin_->target_index(scene_.targets[static_cast<std::size_t>(target)].name); }
  const config::Scene& scene_;
  alignment::LatestValue<RobotState>& state_;
  Handoffs& handoffs_;
  twin::Twin* twin_;
  session::PoseCheck* check_;
};

// The robot thread: the session at each stop of the tour (the twin's robot, the configured camera or the
// twin's), or at each stop of a recording (`replay`, in lockstep, checked by `check`).
void drive(const config::Scene& scene, const RunOptions& o, session::SceneTrackers& trackers,
           alignment::LatestValue<RobotState>& state, Handoffs& handoffs, const std::stop_token& cancel,
           hardware::Devices& devices, const config::Recording* replay, session::PoseCheck* check) {
  const auto tour = [&](session::Session& session, const session::Dwell& dwell, twin::Twin* twin, int visits) {
    RunObserver observer(scene, state, handoffs, twin, check);
    for (int v = 0; v < visits && !cancel.stop_requested(); ++v) session.visit(v, trackers.workers, dwell, observer, cancel);
  };
  const int visits = o.visits > 0 ? o.visits : static_cast<int>(scene.visits.size());
  if (devices.base) {  // the configured robot: no twin
    hardware::DeviceSession rig(scene, trackers.targets, devices);
    tour(rig.session(), rig.dwell(o.dwell_s, false), nullptr, visits);
  } else if (replay) {
    session::ReplaySession rig(scene, *replay, trackers.targets);
    tour(rig.session(), rig.dwell(), nullptr, static_cast<int>(replay->stops.size()));
  } else {
    twin::TwinSession rig(scene, trackers.targets, o.seed, devices.camera.get(), [] { return interrupted(); });
    tour(rig.session(), rig.dwell(o.dwell_s, false), &rig.twin(), visits);
  }
  RobotState last;
  state.read(last);
  state.publish({.lit = {}, .since_s = config::steady_now_s(), .visit = last.visit, .done = true});
}

// Without --sim: the devices the config names, opened and read once (each absent one an error naming it);
// the twin serves the rest. A config naming none runs the twin and says so.
hardware::Devices open_configured(const config::Scene& scene, bool headless) {
  config::DevicesConfig wanted = scene.devices;
  if (headless && wanted.projector) {  // drawn offscreen: no monitor to check
    std::cout << "devices.projector is not used with --headless" << std::endl;
    wanted.projector.reset();
  }
  if (!wanted.any()) {
    if (!scene.devices.any())
      std::cout
          << "no devices configured in " << scene.source.filename().string()
          << " (a `devices:` section; projbot devices lists what this machine has): running against the digital twin (--sim)"
          << std::endl;
    return {};
  }
  std::vector<hardware::DeviceCheck> checks;
  bool robot = false;
  hardware::Devices devices =
      hardware::open_session_devices(wanted, checks, robot);  // an absent device, part of a robot or a laser: refused
  for (const auto& c : checks) std::cout << "opened " << c.config << ": " << c.detail << '\n';
  if (robot)
    std::cout << "the configured base, pan-tilt and camera serve the session"
              << (wanted.laser ? ", the base localised on the laser against " + wanted.laser->map.string() : std::string())
              << ": no twin (nothing is measured against a truth)" << std::endl;
  else
    std::cout << "the twin serves the robot" << (scene.devices.camera ? "" : " and the camera") << std::endl;
  return devices;
}

void print_robot(std::ostream& out, const RobotState& robot, bool configured_camera, const Handoffs& h, std::size_t tracked) {
  out << "robot: " << robot.visit << " visit(s); " << (configured_camera ? "the configured" : "the twin's")
      << " camera delivered " << h.from_capture_ms.size() << " frames (capture to hand-off to the workers p50 "
      << engine::percentile(h.from_capture_ms, 0.5) << " ms, p95 " << engine::percentile(h.from_capture_ms, 0.95) << " ms"
      << (configured_camera ? "" : ": the twin's render and Kinect noise")
      << "; of that, from the camera's next() to the hand-off p50 " << std::setprecision(3)
      << engine::percentile(h.in_session_ms, 0.5) << " ms, p95 " << engine::percentile(h.in_session_ms, 0.95)
      << " ms); the tracker workers processed " << tracked << "\n";
}

// --replay DIR: the recording, read before anything else starts (and the options it rules out refused).
std::optional<config::Recording> replay_of(const cli::Args& args) {
  const auto dir = args.get("replay");
  if (!dir) return std::nullopt;
  if (args.flag("sim")) throw cli::UsageError("--sim does not apply to --replay: the recording serves every device");
  for (const char* k : {"visits", "dwell", "seed"})
    if (args.get(k)) throw cli::UsageError(std::string("--") + k + " does not apply to --replay: it plays the recording's stops");
  return config::load_recording(*dir);
}

// The run's options beyond the scene and the recording: a bad value is a usage error before anything opens.
RunOptions run_options(const cli::Args& args) {
  RunOptions o;
  o.visits = args.get_int("visits", 0, 1, 1000);
  o.dwell_s = args.get_double("dwell", 4.0);
  if (!(o.dwell_s > 0.0 && o.dwell_s <= 3600.0)) throw cli::UsageError("--dwell must be in (0, 3600] seconds");
  o.seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  o.seconds = args.get_double("seconds", 0.0);
  if (!(o.seconds >= 0.0 && o.seconds <= 1e6)) throw cli::UsageError("--seconds must be 0 (until the tour ends) to 1e6");
  o.headless = args.flag("headless");
  present_mode(args.get_or("present-mode", "fifo"));  // a bad mode is an error with --headless too
  args.get_int("monitor", 0, 0, 64);                  // so is a bad monitor
  o.compensate = on_off(args, "compensation", true);
  o.predict = !args.flag("no-predict");
  return o;
}

// The projector's output: offscreen at its size with --headless, else a window; on the config's projector
// (its monitor, fullscreen) when `configured`, unless the command line says otherwise.
std::unique_ptr<engine::RenderTarget> open_output(engine::Renderer& renderer, const cli::Args& args, const config::Scene& scene,
                                                  bool headless, bool configured) {
  if (headless) return renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  engine::WindowOptions wo = window_options(args, scene.projector, "projbot run: " + scene.source.filename().string());
  if (configured && scene.devices.projector) {
    wo.fullscreen = args.flag("fullscreen") || scene.devices.projector->fullscreen;
    if (!args.get("monitor")) wo.monitor = scene.devices.projector->monitor;
  }
  return open_window(renderer, wo, scene.projector);
}

void print_frames(std::ostream& out, const session::LiveFigures& f, const engine::FrameSummary& summary,
                  std::size_t silent_frames, double silent_s, engine::SceneContent& content) {
  out << engine::format_summary(summary) << '\n';
  out << std::fixed << std::setprecision(1) << "pose age at display (depth capture to expected display), " << f.ages_ms.size()
      << " frames with a target: p50 " << engine::percentile(f.ages_ms, 0.5) << " ms, p95 " << engine::percentile(f.ages_ms, 0.95)
      << " ms, p99 " << engine::percentile(f.ages_ms, 0.99) << " ms, max " << engine::percentile(f.ages_ms, 1.0) << " ms; "
      << f.blank << " frames blank (driving, acquiring or lost)";
  if (f.with_neighbours > 0) out << "; " << f.with_neighbours << " frames lit a neighbour too";
  if (silent_frames > 0)
    out << "; " << silent_frames << " frames blanked because the camera had handed over no frame for "
        << std::lround(1000.0 * silent_s) << " ms";
  out << "\n";
  if (const std::string played = content.summary(); !played.empty())
    out << "content: " << played << "; content time less the shown frame's: p50 " << engine::percentile(f.content_offsets_ms, 0.5)
        << " ms, p99 " << engine::percentile(f.content_offsets_ms, 0.99) << " ms; upload on the render thread p50 "
        << std::setprecision(3) << summary.upload_p50_ms << " ms, p99 " << summary.upload_p99_ms << " ms" << std::setprecision(1)
        << "\n";
}

void print_replay(std::ostream& out, const config::Recording& recording, int visits, std::size_t tracked,
                  const session::PoseCheck& check) {
  out << "replay of " << recording.folder().string() << ": " << visits << " of " << recording.stops.size() << " stops, "
      << tracked << " poses tracked in lockstep (each lit target's, every frame); against the recording's: " << check.compared
      << " compared, largest difference " << std::setprecision(4) << check.max_mm << " mm, " << check.max_deg << " deg; "
      << check.mismatched << " found or lost in one and not the other; " << check.unreached()
      << " recorded rows for frames the replay did not reach\n";
}

// Per frame: when it started, the capture time of the depth its pose came from and its expected display
// time (empty for a blank frame), all on the frame profiler's clock.
void write_profile(const std::string& csv, const std::vector<session::LiveRow>& rows, const config::Scene& scene) {
  std::ostringstream f;
  f << "frame,start_ms,pose_age_ms,target,capture_ms,display_ms,error_mm\n";
  const auto opt = [](double v) { return std::isnan(v) ? std::string() : std::to_string(v); };
  for (std::size_t i = 0; i < rows.size(); ++i)
    f << i << ',' << rows[i].start_ms << ',' << (rows[i].age_ms >= 0 ? std::to_string(rows[i].age_ms) : std::string()) << ','
      << (rows[i].target >= 0 ? scene.targets[static_cast<std::size_t>(rows[i].target)].name : std::string()) << ','
      << opt(rows[i].capture_ms) << ',' << opt(rows[i].display_ms) << ',' << opt(rows[i].error_mm) << '\n';
  config::write_file_atomically(csv, f.str());
  std::cout << "per-frame profile written to " << csv << '\n';
}

// The robot thread of a run: the session (drive()), publishing what the render thread draws; a failure is
// kept for the render thread to report.
class RobotThread {
 public:
  RobotThread(const config::Scene& scene, const RunOptions& o, session::SceneTrackers& trackers, hardware::Devices& devices,
              const config::Recording* replay, session::PoseCheck* check)
      : thread_([this, &scene, &o, &trackers, &devices, replay, check](std::stop_token cancel) {
          try {
            drive(scene, o, trackers, state_, handoffs_, cancel, devices, replay, check);
          } catch (...) {
            error_ = std::current_exception();
          }
          done_ = true;
        }) {}
  bool done() const { return done_; }
  alignment::LatestValue<RobotState>& state() { return state_; }
  const Handoffs& handoffs() const { return handoffs_; }  // the robot thread's until finish()
  // After the frame loop: a device (or the twin) that failed while projecting blanks the projector at once,
  // so nothing it last showed stays lit; then the thread is stopped and joined. The failure's message
  // (empty: none); a failure that is not a std::exception is rethrown.
  std::string finish(engine::Renderer& renderer, engine::RenderTarget& target, const config::ProjectorConfig& projector) {
    std::string failure;
    if (done_ && error_) {
      renderer.draw_frame(target, projector, std::span<const engine::DrawItem>{});
      try {
        std::rethrow_exception(error_);
      } catch (const std::exception& e) {
        failure = e.what();
      }
    }
    renderer.finish(target);
    thread_.request_stop();
    thread_.join();
    if (error_ && failure.empty()) std::rethrow_exception(error_);
    return failure;
  }

 private:
  alignment::LatestValue<RobotState> state_;
  Handoffs handoffs_;
  std::exception_ptr error_;
  std::atomic<bool> done_{false};
  std::jthread thread_;  // last: starts once the above exist
};

// What the projector draws in a run: the scene's models uploaded, their compensation and content, and
// the output (offscreen, or a window on the configured projector unless the command line says otherwise).
struct RunOutput {
  RunOutput(engine::Renderer& renderer, const cli::Args& args, const config::Scene& scene, const RunOptions& o, bool configured)
      : items(upload_scene(renderer, scene, &models)),
        plan(surfaces(models, scene), scene.room.ambient_lux, o.compensate),
        content(renderer, scene, models, items),  // a bad video: one line, exit 1
        target(open_output(renderer, args, scene, o.headless, configured)) {}
  static std::vector<engine::CompensationPlan::Target> surfaces(const std::vector<assets::Model>& models,
                                                                const config::Scene& scene) {
    std::vector<engine::CompensationPlan::Target> out;
    for (std::size_t i = 0; i < models.size(); ++i) out.push_back({&models[i], scene.targets[i].surface.albedo});
    return out;
  }
  std::vector<assets::Model> models;
  std::vector<engine::DrawItem> items;
  engine::CompensationPlan plan;
  engine::SceneContent content;
  std::unique_ptr<engine::RenderTarget> target;
};

session::LiveLoopConfig loop_config(const config::Scene& scene, const RunOptions& o, bool replay) {
  session::LiveLoopConfig c;
  c.projection.T_projector_camera = scene.pan_tilt.T_projector_camera;
  c.projection.refresh_hz = scene.projector.refresh_hz;
  c.projection.input_lag_ms = scene.projector.input_lag_ms;
  c.projection.predict = o.predict;
  if (replay) c.projection.silent_camera_s = 0.0;  // a replay's frames play in lockstep
  c.seconds = o.seconds;
  c.paced_hz = o.headless ? 60.0 : 0.0;  // offscreen, no vsync: like a 60 Hz projector
  return c;
}

// What the frame loop reads: the robot's state (into `seen`, which the meter measures against), the
// workers' poses, the camera's hand-offs; the content's messages after each frame.
session::LiveInputs live_inputs(const config::Scene& scene, RobotThread& robot, RobotState& seen,
                                const session::SceneTrackers& trackers, engine::SceneContent& content) {
  session::LiveInputs in;
  in.stop = [&robot, &seen] {
    robot.state().read(seen);
    session::LiveStop stop{{}, seen.since_s, seen.visit};
    for (const DrawnTarget& lit : seen.lit) stop.targets.push_back(lit.target);
    return stop;
  };
  in.poses = [&trackers](int index, alignment::PoseSample& pose) {
    return trackers.owned[static_cast<std::size_t>(index)]->latest(pose);
  };
  in.camera_last_s = [&robot] { return robot.handoffs().last_s.load(); };
  in.keep_going = [&robot] { return !interrupted() && !robot.done(); };
  in.meter = [&scene, &seen](const session::DrawnPose& drawn) { return marker_error(scene, seen, drawn); };
  in.after_frame = [&content] {
    for (const std::string& e : content.take_errors())  // the last good frame stays up; said once
      std::cerr << "content: " << e << " (its last good frame stays)" << std::endl;
    for (const std::string& e : content.reload_changed(config::steady_now_s()))  // a video changed on disk
      std::cout << "content: " << e << std::endl;
  };
  return in;
}
}  // namespace

const Command kRun{
    "run",
    "the live engine: project onto the tracked targets while the robot tours (the twin with --sim)",
    "projbot run [--config C.yaml] [--sim | --replay DIR] [--fullscreen] [--monitor N] [--headless] [--profile p.csv]\n"
    "            [--seconds S] [--visits N] [--dwell S] [--seed K] [--present-mode fifo|mailbox|immediate]\n"
    "            [--no-predict]\n\n"
    "Opens the projector output and draws, every frame, each target the robot is projecting onto (the\n"
    "visited one and the others it expects in the projector's view at that stop) at the\n"
    "newest pose its tracker worker accepted (Eq. 2, Eq. 3), moved on by its measured motion to the frame's\n"
    "expected display time (one frame period as measured, plus the projector's input_lag_ms); targets not\n"
    "yet found or lost are blanked.\n"
    "The robot thread drives the tour of the config's `tour.visits`, aims the pan-tilt, gives each worker\n"
    "the initial guess (Eq. 1), the target's surveyed footing and the colour taken on arrival, and dwells\n"
    "while the camera streams depth. Per frame it records the pose's\n"
    "age at display (depth capture to the frame's expected display time), the frame time and, in the twin,\n"
    "the error at the markers at that display time (where the projector's light lands against where they\n"
    "truly are, as the tour measures it: markers it cannot light or lights edge-on are left out); it prints\n"
    "percentiles at the end (the error while a target moves and while it stands still, mm).\n"
    "Devices come from the config's `devices:` section (projbot devices --help shows it): each one configured\n"
    "is opened and read once at start, and one that is absent stops the run with a message naming it.\n"
    "A configured camera replaces the twin's (its frames at its own rate, its colour on arrival) and a\n"
    "configured projector sets the window's monitor and fullscreen. A configured base, pan_tilt and camera\n"
    "(together) make the whole robot: the base is driven to each stop over its ROS 2 topics on its odometry\n"
    "(placed in the map at robot.start), the pan-tilt aims, and no twin runs (so no error is measured); a\n"
    "configured laser localises the base against devices.laser.map (projbot slam's map) while it drives and\n"
    "at each stop. Part of a robot, or a laser without a base or a map, stops the run saying so. With none\n"
    "configured, or with --sim, the digital twin serves every device. A live camera that hands over no frame\n"
    "for 100 ms blanks the projection until its frames come back. A device that fails while projecting\n"
    "blanks the projector at once; what was measured until then is printed and written, and the failure is\n"
    "reported (exit 1).\n"
    "With --replay DIR the session runs from a recording (projbot record): the base and pan-tilt answer\n"
    "what they answered then, each stop's frames play at their recorded pace and are tracked in lockstep,\n"
    "and every pose is compared with the recording's (the largest difference is printed); no device and\n"
    "no twin is used, so nothing is measured against a truth.\n"
    "Targets with `content:` (a video, a timeline) play it on each frame's display time; a video file that\n"
    "changes on disk is loaded again and swapped in at a later frame (tracking goes on), and one that fails\n"
    "to load leaves the old one playing and says why.\n"
    "Without --config the shipped demo tour runs in the twin.\n",
    {{"config", "FILE", "tour scene (default: assets/scenes/tour.yaml)", cli::PathRole::input_file},
     {"sim", "", "run against the digital twin, whatever `devices:` configures (the default without one)"},
     {"replay", "DIR", "run the session from a recording (projbot record): no device, no twin; its scene unless --config",
      cli::PathRole::input_folder},
     {"fullscreen", "", "fullscreen on --monitor (the projector)"},
     {"monitor", "N", "monitor index for --fullscreen (default 0)"},
     {"headless", "", "draw offscreen at 60 Hz instead of a window (profiling without a display)"},
     {"present-mode", "MODE", "fifo (default, vsync), mailbox or immediate"},
     {"profile", "FILE", "write one CSV row per frame: start, pose age, capture and display time, error",
      cli::PathRole::output_file},
     {"seconds", "S", "stop after S seconds (default 0: when the tour ends, the window is closed or Ctrl-C)"},
     {"visits", "N", "visits, cycling through the tour (default: the list once)"},
     {"dwell", "S", "seconds the robot projects at each stop (default 4)"},
     {"seed", "K", "seed of the twin's noise (default 1)"},
     {"no-predict", "", "draw the newest measured pose, not the one predicted for display time"},
     {"compensation", "on|off",
      "radiometric compensation of each target's surface and the room's light (default on; off: the content as stored)"}},
    [](const cli::Args& args) {
      catch_interrupts();  // Ctrl-C / SIGTERM: leave the frame loop at the next frame, then write what was measured
      const std::optional<config::Recording> recording = replay_of(args);
      const std::string scene_path =
          args.get_or("config", recording ? recording->scene.string() : (asset_dir() / "scenes" / "tour.yaml").string());
      args.check_clashes({{recording ? "the recording's scene" : "the default scene", scene_path, false}});
      const config::Scene scene = config::load_scene(scene_path);
      if (scene.visits.empty())
        throw config::ConfigError(scene.source.string() + ": `projbot run` needs a 'tour: {visits: [...]}' section");
      std::optional<session::PoseCheck> check;
      if (recording) check.emplace(recording->folder() / "poses.csv");
      hardware::Devices devices =
          args.flag("sim") || recording ? hardware::Devices{} : open_configured(scene, args.flag("headless"));
      const RunOptions o = run_options(args);

      engine::RendererOptions ro;
      ro.windowing = !o.headless;
      engine::Renderer renderer(ro);
      std::cout << "device: " << renderer.device_info().name << std::endl;  // flushed: a log shows it has started
      if (!devices.base && !recording) note_twin_on_odometry(std::cout);
      RunOutput out(renderer, args, scene, o, !args.flag("sim") && !recording);
      const session::LiveLoopConfig lc = loop_config(scene, o, recording.has_value());
      session::LiveLoop loop(renderer, scene.projector, out.items, lc);
      loop.set_compensation(&out.plan);
      loop.set_content(&out.content);
      // One tracker worker per target on the map.
      session::SceneTrackers trackers = session::make_trackers(scene, session::worker_config(o.predict, recording.has_value()));
      RobotThread robot_thread(scene, o, trackers, devices, recording ? &*recording : nullptr, check ? &*check : nullptr);
      RobotState robot;  // as the render thread last read it
      engine::FrameProfiler profiler;
      const session::LiveFigures figures =
          loop.run(*out.target, live_inputs(scene, robot_thread, robot, trackers, out.content), profiler);
      const std::string failure = robot_thread.finish(renderer, *out.target, scene.projector);
      for (const auto& w : trackers.owned)
        if (w && w->error()) std::rethrow_exception(w->error());

      print_frames(std::cout, figures, profiler.summary(), loop.silent_frames(), lc.projection.silent_camera_s, out.content);
      std::size_t tracked = 0;
      for (const auto& w : trackers.owned) tracked += w ? w->frames_processed() : 0;
      if (recording) {
        print_replay(std::cout, *recording, robot.visit, tracked, *check);
      } else {
        if (devices.base)
          std::cout << "error at display: not measured (the configured robot: no truth to measure against)\n";
        else
          print_display_errors(std::cout, figures);
        print_robot(std::cout, robot, devices.camera != nullptr, robot_thread.handoffs(), tracked);
      }
      if (const auto csv = args.get("profile")) write_profile(*csv, figures.rows, scene);
      if (!failure.empty()) {
        std::cerr << "projbot run: " << failure << " (the projection was blanked; what was measured until then is above)\n";
        return 1;
      }
      return interrupt_exit_code();  // 0, or 130 / 143 after Ctrl-C / SIGTERM
    }};

}  // namespace projbot::tools
