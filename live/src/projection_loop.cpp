#include "projbot/live/projection_loop.hpp"

#include <algorithm>
#include <cmath>

#include "projbot/config/clock.hpp"

namespace projbot::live {

ProjectionLoop::ProjectionLoop(engine::Renderer& renderer, const config::ProjectorConfig& projector,
                               std::vector<engine::DrawItem> items, ProjectionLoopConfig config, config::Clock clock)
    : renderer_(renderer),
      projector_(projector),
      items_(std::move(items)),
      cfg_(config),
      clock_(std::move(clock)),
      frames_(config.projection) {}

// What the frame whose poses are read at now_s draws (ProjectionFrames); a loop given no camera to watch
// takes it as never silent.
std::vector<DrawnPose> ProjectionLoop::decide(const LitStop& stop, const ProjectionInputs& in, double now_s) {
  decided_s_ = now_s;
  const double camera_last_s = in.camera_last_s ? in.camera_last_s() : now_s;
  return frames_.compose(now_s, {stop.targets, stop.since_s, camera_last_s}, in.poses);
}

// This frame's draw items: each lit target found, at its pose for the display time, with its content on
// that display time's clock. A lit target's video runs before its pose is found (the acquisition's first
// second), so that it has caught up with its clock when it is first drawn.
void ProjectionLoop::compose(const LitStop& stop, const ProjectionInputs& in, std::vector<engine::DrawItem>& out,
                             std::vector<DrawnPose>& drawn) {
  out.clear();
  const double now_s = clock_.now_s();
  drawn = decide(stop, in, now_s);
  const auto content_s = [&](int target, double display_s) { return display_s - content_->start_s(target, t0_s_, stop.since_s); };
  if (content_) {
    const double display_s = frames_.display_time_s(now_s);
    for (const int target : stop.targets)
      if (content_->has_video(target) &&
          std::none_of(drawn.begin(), drawn.end(), [&](const DrawnPose& d) { return d.target == target; }))
        content_->show(target, content_s(target, display_s));
  }
  for (const DrawnPose& d : drawn) {
    const auto t = static_cast<std::size_t>(d.target);
    out.push_back({items_.at(t).model, d.T_projector_target,
                   plan_ ? plan_->at(t, stop.visit, projector_, d.T_projector_target, d.display_s) : engine::Compensation{}});
    if (content_ && content_->has(d.target)) {  // on the display clock of this frame, as its pose
      const auto shown = content_->apply(d.target, content_s(d.target, d.display_s), out.back());
      if (!std::isnan(shown.pts_s)) figures_.content_offsets_ms.push_back(1000.0 * (shown.content_s - shown.pts_s));
      if (&d == &drawn.front()) first_content_ = shown;
    }
  }
}

// Each drawn target's error against the truth at its display time; the row (and the pose's age, capture
// to the expected display time) is the first drawn one's.
void ProjectionLoop::measure(const std::vector<DrawnPose>& drawn, const DisplayMeter& meter, double start_ms, double start_s,
                             bool uniform) {
  const double nan = std::nan("");
  const double clock_s = start_s - t0_s_;
  if (drawn.empty()) {
    ++(uniform ? figures_.uniform : figures_.blank);
    figures_.rows.push_back({start_ms, -1.0, nan, nan, nan, -1, clock_s, nan, nan, Eigen::Vector3d::Constant(nan)});
    return;
  }
  double first_error = nan;
  for (const DrawnPose& d : drawn) {
    const DisplayError e = meter ? meter(d) : DisplayError{nan, false};
    if (!std::isnan(e.error_mm)) (e.moving ? figures_.moving_mm : figures_.still_mm).push_back(e.error_mm);
    if (&d == &drawn.front()) first_error = e.error_mm;
  }
  if (drawn.size() > 1) ++figures_.with_neighbours;
  const DrawnPose& first = drawn.front();
  const double age_ms = 1000.0 * (std::max(clock_.now_s(), first.display_s) - first.capture_s);
  figures_.ages_ms.push_back(age_ms);
  figures_.rows.push_back({start_ms, age_ms, start_ms + 1000.0 * (first.capture_s - start_s),
                           start_ms + 1000.0 * (first.display_s - start_s), first_error, first.target, clock_s,
                           first_content_.content_s, first_content_.pts_s,
                           1000.0 * first.T_projector_target.topRightCorner<3, 1>()});
}

void ProjectionLoop::begin() {
  figures_ = {};
  t0_s_ = clock_.now_s();
}

std::optional<DecidedFrame> ProjectionLoop::frame(engine::RenderTarget* target, const ProjectionInputs& in,
                                                  engine::FrameProfiler* profiler) {
  const LitStop stop = in.stop();  // after the wait: on a replay's clock, the robot has done all before it
  DecidedFrame f;
  f.start_s = clock_.now_s();
  const double start_ms = profiler ? profiler->now_ms() : 1000.0 * (f.start_s - t0_s_);
  frames_.frame_started(f.start_s);
  first_content_ = {std::nan(""), std::nan(""), false};
  const std::optional<std::array<std::uint8_t, 3>> uniform = in.uniform ? in.uniform() : std::nullopt;
  if (uniform) decided_s_ = f.start_s;  // nothing decided: no target drawn
  if (target) {
    const auto read = [&](std::vector<engine::DrawItem>& out) {
      if (uniform)
        out.clear();
      else
        compose(stop, in, out, f.drawn);
    };
    if (uniform) renderer_.set_background(*uniform);
    const bool drawn = renderer_.draw_frame(*target, projector_, read, profiler);
    if (uniform) renderer_.set_background({0, 0, 0});
    if (!drawn) return std::nullopt;
  } else if (!uniform) {
    f.drawn = decide(stop, in, f.start_s);
  }
  f.display_s = frames_.display_time_s(decided_s_);
  f.uniform = uniform.has_value();
  if (in.after_frame) in.after_frame(f);
  measure(f.drawn, in.meter, start_ms, f.start_s, uniform.has_value());
  return f;
}

// The next frame's start: one period after the last (Clock::pace), or at once when the inputs' sleep is
// woken for something to show now, the cadence going on from there.
void ProjectionLoop::pace(double& next_s, const ProjectionInputs& in) {
  if (!in.pace_sleep) return clock_.pace(next_s, 1.0 / cfg_.paced_hz);
  next_s += 1.0 / cfg_.paced_hz;
  const double now = in.pace_sleep(next_s) ? clock_.now_s() : std::max(next_s, clock_.now_s());
  if (now < next_s || now > next_s + 0.05) next_s = now;
}

ProjectionFigures ProjectionLoop::run(engine::RenderTarget& target, const ProjectionInputs& in, engine::FrameProfiler& profiler) {
  begin();
  double next_s = t0_s_;
  while (in.keep_going() && !target.poll_close() && (cfg_.seconds == 0.0 || clock_.now_s() - t0_s_ < cfg_.seconds)) {
    if (cfg_.paced_hz > 0.0) pace(next_s, in);  // no vsync: paced like a projector
    frame(&target, in, &profiler);
  }
  return std::move(figures_);
}

}  // namespace projbot::live
