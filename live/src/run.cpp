#include "projbot/live/run.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <optional>
#include <stdexcept>
#include <thread>

#include "projbot/alignment/latest_value.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/stop_request.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/live/reflectance_probe.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/trackers.hpp"

namespace projbot::live {
namespace {

// What the render thread draws at a stop: the visited target or a neighbour expected in the projector's
// view there.
struct DrawnTarget {
  int target = -1;       // scene index: its worker and draw item
  int target_visit = 0;  // this target's n-th visit (its motion script); 0: still
};

// What the robot thread tells the render thread: which targets the robot is projecting onto (none while
// it drives; the visited one first) and since when; poses captured before that belong to an earlier stop.
struct RobotState {
  std::vector<DrawnTarget> lit;
  double since_s = 0.0;
  int visit = 0;
  bool done = false;
  std::array<double, 3> believed{};  // where the robot believed it was at the stop (x, y m; heading rad)
  // The truth at the stop (the twin's), so the render thread measures each frame at its display time;
  // null where nothing serves a truth (a replay, the configured robot).
  std::shared_ptr<const StopTruth> truth{};
  std::optional<std::array<double, 3>> moving{};  // while driving: where it believes it is now (none at a stop)
  robot::HeadPoses head{};                        // at a stop: where it believes its camera and projector are
};

// The mean marker error of a target drawn (at its display time and pose), against the truth then; NaN
// where no marker can be measured or the stop has no truth.
DisplayError marker_error(const config::Scene& scene, const RobotState& robot, const live::DrawnPose& drawn) {
  const auto lit =
      std::find_if(robot.lit.begin(), robot.lit.end(), [&](const DrawnTarget& l) { return l.target == drawn.target; });
  if (!robot.truth || lit == robot.lit.end()) return {std::nan(""), false};
  const double t = drawn.display_s - robot.since_s;
  const config::TargetMotion* m = scene.targets[static_cast<std::size_t>(drawn.target)].motion_on(lit->target_visit);
  return {robot.truth->error_mm(drawn.target, lit->target_visit, drawn.T_camera_target, t), m && m->moving_at(t)};
}

// The camera's hand-offs to the workers (RunResult's), and the newest (steady clock) for the render thread.
struct Handoffs {
  std::vector<double> from_capture_ms, in_session_ms;
  std::atomic<double> last_s{0.0};
};

// What the robot thread tells the render thread at each step of the session, with the truth when the rig
// knows it (the twin); in a replay, each lockstep frame's poses are also checked against the recording's.
class RunObserver final : public StopObserver {
 public:
  RunObserver(const config::Scene& scene, alignment::LatestValue<RobotState>& state, Handoffs& handoffs, Rig& rig,
              PoseCheck* check, std::ostream& log)
      : scene_(scene), state_(state), handoffs_(handoffs), rig_(rig), check_(check), log_(log), clock_(rig.session().clock()) {}
  /// Each stop's visited target's reflectance measured by `probe` from the trackers' poses.
  void learn(ReflectanceProbe* probe, live::PoseSource poses) { probe_ = probe, poses_ = std::move(poses); }
  /// The camera's colour view offered to the operator's page while it is wanted.
  void show_to(ShowPictures* pictures) { pictures_ = pictures; }
  void driving(int visit) override {
    visit_ = visit + 1;
    driving_since_s_ = clock_.now_s();
    state_.publish({.lit = {}, .since_s = driving_since_s_, .visit = visit_});
  }
  /// Where the robot believes it is while it drives, published about ten times a second (on the steady
  /// clock: a simulated drive steps faster than its own time) for the operator's map.
  void moving(const robot::Pose2D& believed) {
    const double now = config::steady_now_s();
    if (driving_since_s_ < 0.0 || now - moved_s_ < 0.1) return;
    moved_s_ = now;
    state_.publish({.lit = {},
                    .since_s = driving_since_s_,
                    .visit = visit_,
                    .moving = std::array<double, 3>{believed.x_m, believed.y_m, believed.theta_rad}});
  }
  /// The visit last published (1-based).
  int visit() const { return visit_; }
  void lit(const live::Stop& stop, double since_s) override {
    say_lit(stop);
    if (probe_) probe_->lit(stop, since_s);
    std::vector<DrawnTarget> lit;
    for (const LitTarget& l : stop.lit) lit.push_back({l.target, l.target == stop.target ? stop.target_visit : 0});
    visit_ = stop.visit + 1;
    driving_since_s_ = -1.0;  // at a stop: the map shows the stop's pose
    const robot::Pose2D& at = stop.drive.estimate;
    state_.publish({lit, since_s, visit_, false, {at.x_m, at.y_m, at.theta_rad}, rig_.truth(stop), {}, stop.believed});
  }
  void frame(const live::Stop& stop, int k, const alignment::RgbdFrame& f,
             const std::vector<std::optional<alignment::PoseSample>>& samples) override {
    if (samples.empty()) {  // live: at the hand-off
      const double now = config::steady_now_s();
      handoffs_.from_capture_ms.push_back(1000.0 * (now - f.depth.capture_time_s));
      handoffs_.in_session_ms.push_back(1000.0 * (now - f.delivered_s));
      handoffs_.last_s = now;
      if (pictures_ && !f.colour.rgba.empty() && pictures_->due(ShowPictures::Kind::camera))
        pictures_->offer(ShowPictures::Kind::camera, f.colour);
      if (probe_)
        if (const std::string said = probe_->frame(f, now, poses_); !said.empty()) log_ << said << std::endl;
    }
    if (check_) check_->compare(scene_, stop, k, samples);
  }
  void left(const live::Stop& stop) override {
    if (probe_) probe_->left();
    rig_.left(stop);
  }

 private:
  void say_lit(const live::Stop& stop) {
    log_ << "visit " << stop.visit + 1 << ": " << scene_.targets[static_cast<std::size_t>(stop.target)].name << ", drove "
         << std::fixed << std::setprecision(1) << stop.drive.drive_seconds << " s" << (stop.drive.arrived ? "" : " (not arrived)")
         << ", believed at x " << std::setprecision(3) << stop.drive.estimate.x_m << " m, y " << stop.drive.estimate.y_m
         << " m, heading " << std::setprecision(1) << config::degrees(stop.drive.estimate.theta_rad) << " deg; lit "
         << stop.lit.size() << " target(s)";
    if (!stop.lit.empty() && !stop.lit.front().map_pose_from.empty())  // a fleet's newer place than the survey
      log_ << "; placed by " << stop.lit.front().map_pose_from << ", " << std::setprecision(0)
           << 1000.0 * (stop.lit.front().T_map_target.block<3, 1>(0, 3) -
                        surveyed_pose(scene_.targets[static_cast<std::size_t>(stop.target)]).block<3, 1>(0, 3))
                           .norm()
           << " mm from its survey";
    if (stop.drive.corrections > 0)  // localised on a laser: how far odometry alone had drifted from that
      log_ << "; " << stop.drive.corrections << " laser scans matched (" << stop.drive.rejected << " rejected), odometry alone "
           << std::setprecision(0) << 1000.0 * robot::distance_m(stop.drive.estimate, stop.drive.odometry) << " mm away";
    log_ << std::endl;
  }
  const config::Scene& scene_;
  alignment::LatestValue<RobotState>& state_;
  Handoffs& handoffs_;
  Rig& rig_;
  PoseCheck* check_;
  std::ostream& log_;
  config::Clock clock_;  // the session's
  ReflectanceProbe* probe_ = nullptr;
  live::PoseSource poses_;
  ShowPictures* pictures_ = nullptr;
  int visit_ = 0;
  double driving_since_s_ = -1.0;  // the drive under way began (session clock); -1: none
  double moved_s_ = -1e9;          // the last pose published while driving (steady clock)
};

// The operator's pause and go-to during a dwell: not over while paused; over at once when a go-to is asked.
Dwell operated(Dwell dwell, ShowControl& show) {
  dwell.over = [over = dwell.over, &show](const Stop& stop, int frames, double elapsed_s) {
    if (show.paused()) return false;
    return show.pending_go_to().has_value() || over(stop, frames, elapsed_s);
  };
  return dwell;
}

bool asked_to_go(const ShowControl* show) { return show && show->pending_go_to().has_value(); }

// Between stops: the robot waits while paused, then takes a go-to asked for (a target it cannot reach is
// said and left; ShowControl only takes reachable ones).
void take_the_operators_turn(ShowControl& show, StopSequence& session, std::ostream& log, const std::stop_token& cancel) {
  while (show.paused() && !cancel.stop_requested()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const std::optional<int> target = show.take_go_to();
  if (!target) return;
  try {
    session.visit_next(*target);
  } catch (const SessionError& e) {
    log << "go to: " << e.what() << " (the tour goes on)" << std::endl;
  }
}

// How long a fleet robot waits at its start for the coordinator's plan before it sets off on its own tour.
constexpr double kFirstPlanWaitS = 5.0;

// A fleet robot's side of the coordinator's plan (RunSources::planned_targets): its targets in turn.
class PlanFollower {
 public:
  explicit PlanFollower(std::function<std::optional<std::vector<int>>()> plan) : plan_(std::move(plan)) {}
  bool on() const { return static_cast<bool>(plan_); }

  // Before a stop: the next of its targets, from the first of a new list (the one it stands at skipped),
  // waiting where it is while the plan gives it none and, before the first stop, up to kFirstPlanWaitS for
  // a plan. False while no plan was heard (the tour goes on as listed).
  bool next(StopSequence& session, std::ostream& log, const std::stop_token& cancel, bool first) {
    const double give_up_s = config::steady_now_s() + (first ? kFirstPlanWaitS : 0.0);
    std::optional<std::vector<int>> plan = plan_();
    for (; (plan ? plan->empty() : config::steady_now_s() < give_up_s) && !cancel.stop_requested(); plan = plan_())
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (first && !plan && !cancel.stop_requested())
      log << "fleet: no coordinator's plan heard in " << kFirstPlanWaitS
          << " s (is `projbot fleet` running on this robot's DDS domain?); the tour goes on as listed" << std::endl;
    if (!plan || plan->empty()) return plan.has_value();
    if (*plan != list_) list_ = *plan, next_ = list_.size() > 1 && list_.front() == at_ ? 1 : 0;
    at_ = list_[next_++ % list_.size()];
    try {
      session.visit_next(at_);
    } catch (const SessionError& e) {
      log << "fleet plan: " << e.what() << " (the tour goes on)" << std::endl;
    }
    return true;
  }

  // The dwell at a stop goes on while the plan gives the robot that stop's target alone: it stays lit.
  Dwell staying(Dwell dwell) const {
    dwell.over = [over = dwell.over, this](const Stop& stop, int frames, double elapsed_s) {
      const std::optional<std::vector<int>> plan = plan_();
      return over(stop, frames, elapsed_s) && !(plan && plan->size() == 1 && plan->front() == stop.target);
    };
    return dwell;
  }

 private:
  std::function<std::optional<std::vector<int>>()> plan_;
  std::vector<int> list_;
  std::size_t next_ = 0;
  int at_ = -1;  // the target it went to last
};

// The robot thread of a run: the session at each stop (the rig built on this thread: the twin renders on
// it), publishing what the render thread draws; a failure is kept for the render thread to report. A
// replay's session keeps time on `replay_clock` (null: the steady clock).
class RobotThread {
 public:
  RobotThread(const config::Scene& scene, const RunOptions& o, live::SceneTrackers& trackers, const RunSources& sources,
              live::ReplayClock* replay_clock, ReflectanceProbe* probe)
      : replay_clock_(replay_clock), probe_(probe), thread_([this, &scene, &o, &trackers, &sources](std::stop_token cancel) {
          try {
            drive(scene, o, trackers, sources, cancel);
          } catch (...) {
            error_ = std::current_exception();
          }
          done_ = true;
          if (replay_clock_) replay_clock_->robot_finished();
        }) {}
  bool failed() const { return done_ && error_; }
  /// Whether what served the session knew the truth (the twin): its display errors are measured.
  bool measured() const { return measured_; }
  alignment::LatestValue<RobotState>& state() { return state_; }
  Handoffs& handoffs() { return handoffs_; }  // the robot thread's until finish()
  // After the frame loop: a device (or the twin) that failed while projecting blanks the projector at once,
  // so nothing it last showed stays lit; then the thread is stopped and joined. The failure's message
  // (empty: none); a failure that is not a std::exception, or a stop asked during the set-up, is rethrown.
  std::string finish(engine::Renderer& renderer, engine::RenderTarget& target, const config::ProjectorConfig& projector);

 private:
  void drive(const config::Scene& scene, const RunOptions& o, live::SceneTrackers& trackers, const RunSources& sources,
             const std::stop_token& cancel);
  live::ReplayClock* replay_clock_;
  ReflectanceProbe* probe_;  // null: no reflectance measured
  alignment::LatestValue<RobotState> state_;
  Handoffs handoffs_;
  std::exception_ptr error_;
  std::atomic<bool> done_{false};
  std::atomic<bool> measured_{false};
  std::jthread thread_;  // last: starts once the above exist
};

void RobotThread::drive(const config::Scene& scene, const RunOptions& o, live::SceneTrackers& trackers, const RunSources& sources,
                        const std::stop_token& cancel) {
  const std::unique_ptr<Rig> opened =
      sources.open_rig(scene, trackers.targets, *sources.devices,
                       {.recording = false,
                        .interrupted = sources.interrupted,
                        .replay = sources.replay,
                        .replay_clock = replay_clock_ ? replay_clock_->robot() : config::Clock{}});
  Rig& rig = *opened;
  measured_ = rig.knows_truth();
  const config::Clock& clock = rig.session().clock();
  RunObserver observer(scene, state_, handoffs_, rig, sources.check, *sources.log);
  if (sources.show) {
    ShowPictures& pictures = sources.show->pictures();
    observer.show_to(&pictures);
    rig.colour_wanted([&pictures] { return pictures.due(ShowPictures::Kind::camera); });
    rig.session().navigator().watch_drive([&observer](const robot::Pose2D& believed) { observer.moving(believed); });
  }
  if (probe_) {
    observer.learn(probe_, [&trackers](int index, alignment::PoseSample& pose) {
      return trackers.owned[static_cast<std::size_t>(index)]->latest(pose);
    });
    rig.projector_shows([probe = probe_] { return probe->showing(); });
  }
  const robot::Pose2D start = rig.session().navigator().believed_pose();  // on the operator's map (and the fleet's)
  state_.publish(
      {.lit = {}, .since_s = clock.now_s(), .visit = 0, .moving = std::array<double, 3>{start.x_m, start.y_m, start.theta_rad}});
  const int visits = rig.visits(o.visits > 0 ? o.visits : static_cast<int>(scene.visits.size()));
  if (sources.map_poses) rig.session().use_map_poses(sources.map_poses);
  PlanFollower plan(sources.planned_targets);
  const Dwell own = plan.on() ? plan.staying(rig.dwell(o.dwell_s)) : rig.dwell(o.dwell_s);
  const Dwell dwell = sources.show ? operated(own, *sources.show) : own;
  for (int v = 0; !cancel.stop_requested(); ++v) {
    const bool asked = asked_to_go(sources.show);
    const bool planned = plan.on() && plan.next(rig.session(), *sources.log, cancel, v == 0);
    if (!(v < visits || asked || planned) || cancel.stop_requested()) break;
    if (sources.show) take_the_operators_turn(*sources.show, rig.session(), *sources.log, cancel);
    rig.session().visit(v, trackers.workers, dwell, observer, cancel);
  }
  rig.session().navigator().watch_drive({});  // the observer goes with this scope
  state_.publish({.lit = {}, .since_s = clock.now_s(), .visit = observer.visit(), .done = true});
}

std::string RobotThread::finish(engine::Renderer& renderer, engine::RenderTarget& target,
                                const config::ProjectorConfig& projector) {
  std::string failure;
  if (done_ && error_) {
    renderer.draw_frame(target, projector, std::span<const engine::DrawItem>{});
    try {
      std::rethrow_exception(error_);
    } catch (const config::StopRequested&) {  // Ctrl-C while the robot set up: no failure; thrown on below
    } catch (const std::exception& e) {
      failure = e.what();
    }
  }
  renderer.finish(target);
  thread_.request_stop();
  if (replay_clock_) replay_clock_->close();  // the robot waits for no more frames
  thread_.join();
  if (error_ && failure.empty()) std::rethrow_exception(error_);
  return failure;
}

// What the projector draws: the scene's models uploaded, their compensation and content, and the output.
struct Output {
  Output(engine::Renderer& renderer, const config::Scene& scene, const RunOptions& o, const RunSources& sources)
      : items(engine::upload_scene(renderer, scene, &models)),
        plan(engine::upload_surfaces(renderer, scene, models, items), scene.room.ambient_lux, o.compensate),
        content(renderer, scene, models, items),  // a bad video: thrown, naming it
        target(sources.open_output(renderer)) {}
  std::vector<assets::Model> models;
  std::vector<engine::DrawItem> items;
  engine::CompensationPlan plan;
  engine::SceneContent content;
  std::unique_ptr<engine::RenderTarget> target;
};

live::ProjectionLoopConfig loop_config(const config::Scene& scene, const RunOptions& o, bool replay) {
  live::ProjectionLoopConfig c;
  c.projection.T_projector_camera = scene.pan_tilt.T_projector_camera;
  c.projection.refresh_hz = scene.projector.refresh_hz;
  c.projection.input_lag_ms = scene.projector.input_lag_ms;
  c.projection.predict = o.predict;
  if (replay) c.projection.silent_camera_s = 0.0;  // a replay's frames play in lockstep
  c.seconds = o.seconds;
  c.paced_hz = o.headless ? 60.0 : 0.0;  // offscreen, no vsync: like a 60 Hz projector
  // A replay's frames step its clock (window or not): one refresh each, so the same frames every time.
  if (replay) c.paced_hz = scene.projector.refresh_hz > 0.0 ? scene.projector.refresh_hz : 60.0;
  return c;
}

// What the frame loop reads: the robot's state (into `seen`, which the meter measures against), the
// workers' poses, the camera's hand-offs; the content's messages after each frame.
live::ProjectionInputs live_inputs(const config::Scene& scene, RobotThread& robot, RobotState& seen,
                                   const live::SceneTrackers& trackers, engine::SceneContent& content,
                                   const RunSources& sources) {
  live::ProjectionInputs in;
  in.stop = [&robot, &seen] {
    robot.state().read(seen);
    live::LitStop stop{{}, seen.since_s, seen.visit};
    for (const DrawnTarget& lit : seen.lit) stop.targets.push_back(lit.target);
    return stop;
  };
  in.poses = [&trackers](int index, alignment::PoseSample& pose) {
    return trackers.owned[static_cast<std::size_t>(index)]->latest(pose);
  };
  in.camera_last_s = [&robot] { return robot.handoffs().last_s.load(); };
  // Until the tour's end as last read (a replay ends on the same frame every time), or a failure.
  in.keep_going = [&robot, &seen, &sources] {
    return !(sources.interrupted && sources.interrupted()) && !seen.done && !robot.failed();
  };
  in.meter = [&scene, &seen](const live::DrawnPose& drawn) { return marker_error(scene, seen, drawn); };
  in.after_frame = [&content, &sources](const DecidedFrame&) {
    for (const std::string& e : content.take_errors())  // the last good frame stays up; said once
      *sources.errors << "content: " << e << " (its last good frame stays)" << std::endl;
    for (const std::string& e : content.reload_changed(config::steady_now_s()))  // a video changed on disk
      *sources.log << "content: " << e << std::endl;
  };
  return in;
}

// RunOptions::learn_reflectance (not in a replay: its frames were taken without the probe's light): the
// probe over the scene's models, each image taken once the projector has shown its colour for three
// refreshes and its input lag, and the camera has exposed a frame under it.
std::unique_ptr<ReflectanceProbe> reflectance_probe(const config::Scene& scene, const RunOptions& o,
                                                    const std::vector<assets::Model>& models, bool replay) {
  if (!o.learn_reflectance || replay) return nullptr;
  std::vector<const assets::Model*> pointers;
  for (const assets::Model& m : models) pointers.push_back(&m);
  const double refresh_hz = scene.projector.refresh_hz > 0.0 ? scene.projector.refresh_hz : 60.0;
  auto probe = std::make_unique<ReflectanceProbe>(scene, std::move(pointers),
                                                  3.0 / refresh_hz + scene.projector.input_lag_ms / 1000.0 + 1.0 / 30.0);
  if (!o.reflectance_out.empty()) probe->save_to(o.reflectance_out);
  return probe;
}

// The render thread's side of the probe: its colour shown instead of the targets while it asks, and what it
// learnt bound to the target's model and compensation after each frame.
void learn_in_loop(live::ProjectionInputs& in, ReflectanceProbe& probe, engine::Renderer& renderer, Output& out,
                   std::size_t& measured) {
  in.uniform = [&probe] { return probe.showing(); };
  in.after_frame = [after = in.after_frame, &probe, &renderer, &out, &measured](const DecidedFrame& f) {
    if (after) after(f);
    for (ReflectanceProbe::Learnt& l : probe.take_learnt()) {
      const auto target = static_cast<std::size_t>(l.target);
      if (l.map) {
        renderer.set_surface(out.items.at(target).model, *l.map);
        out.plan.set_surface(target, std::move(l.map));
      } else {
        out.plan.add_measured_albedo(target, l.albedo);
      }
      ++measured;
    }
  };
}

// The projector's frame, offered to the operator's page: a copy recorded into a frame's own commands when
// one is due and taken once that frame is done, so the render thread never waits for it. A window's
// frames are not copied, which the page is told once.
void picture_frame(ShowPictures& pictures, engine::RenderTarget& target) {
  if (std::optional<assets::Image> copy = target.take_copy()) pictures.offer(ShowPictures::Kind::frame, std::move(*copy));
  if (pictures.due(ShowPictures::Kind::frame) && !target.copy_next())
    pictures.set_unavailable(ShowPictures::Kind::frame,
                             "the projector's frames go to a window and are not read back (a --headless run shows them)");
}

// The videos the operator switched targets to, handed to the content (each swapped in at a later frame,
// and said, by reload_changed).
void switch_content(ShowControl& show, engine::SceneContent& content, std::ostream& errors) {
  for (const auto& [target, file] : show.take_content_switches()) try {
      content.switch_video(target, file);
    } catch (const engine::EngineError& e) {
      errors << "content: " << e.what() << std::endl;
    }
}

void operate_in_loop(ProjectionInputs& in, ShowControl& show, ShowReporter& reporter, const RobotState& seen,
                     const ProjectionLoop& loop, Output& out, std::ostream& errors, RunResult& r) {
  in.pace_sleep = [&show](double until_s) { return show.sleep_until(until_s); };  // a live loop: the steady clock
  in.uniform = [&show, other = in.uniform]() -> std::optional<std::array<std::uint8_t, 3>> {
    if (show.blackout()) return std::array<std::uint8_t, 3>{0, 0, 0};
    return other ? other() : std::nullopt;
  };
  in.after_frame = [after = in.after_frame, &show, &reporter, &seen, &loop, &out, &errors, &r](const DecidedFrame& f) {
    if (after) after(f);
    picture_frame(show.pictures(), *out.target);
    switch_content(show, out.content, errors);
    if (f.uniform && show.blackout()) {
      ++r.blackout_frames;
      if (const std::optional<double> asked = show.take_blackout_asked())
        r.blackout_latency_ms.push_back(1000.0 * (f.display_s - *asked));
    }
    StopView stop{{}, seen.visit, seen.done, seen.believed, seen.moving};
    for (const DrawnTarget& lit : seen.lit) stop.lit.push_back(lit.target);
    if (!seen.lit.empty()) stop.T_map_camera = seen.head.T_world_camera, stop.T_map_projector = seen.head.T_world_projector;
    reporter.frame(f, stop, loop.figures(), f.start_s, f.start_s - loop.started_s());
  };
}

}  // namespace

RunResult run(engine::Renderer& renderer, const config::Scene& scene, const RunOptions& options, const RunSources& sources) {
  if (!sources.devices || !sources.open_rig || !sources.open_output || !sources.log || !sources.errors)
    throw std::invalid_argument("live::run needs devices, open_rig, open_output, log and errors in its RunSources");
  if (sources.show && sources.replay)
    throw std::invalid_argument("live::run: a replay's frames wait on its robot, which an operator's pause would stall");
  Output out(renderer, scene, options, sources);
  const live::ProjectionLoopConfig lc = loop_config(scene, options, sources.replay != nullptr);
  // A replay runs on the recording's clock, the projector's frames and the session in step.
  std::unique_ptr<live::ReplayClock> replay_clock;
  if (sources.replay) {
    replay_clock = std::make_unique<live::ReplayClock>();
    out.content.set_exact(true);  // each frame's video frame waited for: the same every time
  }
  live::ProjectionLoop loop(renderer, scene.projector, out.items, lc,
                            replay_clock ? replay_clock->projector() : config::Clock::steady());
  loop.set_compensation(&out.plan);
  loop.set_content(&out.content);
  // One tracker worker per target on the map.
  live::SceneTrackers trackers = live::make_trackers(scene, live::worker_config(options.predict, sources.replay != nullptr));
  std::unique_ptr<ReflectanceProbe> probe = reflectance_probe(scene, options, out.models, sources.replay != nullptr);
  RobotThread robot(scene, options, trackers, sources, replay_clock.get(), probe.get());
  RobotState seen;  // as the render thread last read it
  engine::FrameProfiler profiler;
  RunResult r;
  live::ProjectionInputs in = live_inputs(scene, robot, seen, trackers, out.content, sources);
  if (probe) learn_in_loop(in, *probe, renderer, out, r.reflectance_measured);
  std::optional<ShowReporter> reporter;
  if (sources.show) operate_in_loop(in, *sources.show, reporter.emplace(*sources.show), seen, loop, out, *sources.errors, r);
  r.figures = loop.run(*out.target, in, profiler);
  r.failure = robot.finish(renderer, *out.target, scene.projector);
  for (const auto& w : trackers.owned)
    if (w && w->error()) std::rethrow_exception(w->error());
  r.summary = profiler.summary();
  r.silent_frames = loop.silent_frames();
  r.silent_camera_s = lc.projection.silent_camera_s;
  r.visits = seen.visit;
  r.handoff_from_capture_ms = std::move(robot.handoffs().from_capture_ms);
  r.handoff_in_session_ms = std::move(robot.handoffs().in_session_ms);
  for (const auto& w : trackers.owned) r.tracked += w ? w->frames_processed() : 0;
  r.content = out.content.summary();
  r.measured = robot.measured();
  return r;
}

}  // namespace projbot::live
