#include "projbot/live/show_control.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "projbot/config/clock.hpp"

namespace projbot::live {

std::vector<SiteTarget> site_targets(const config::Scene& scene) {
  std::vector<SiteTarget> out;
  for (const config::TargetConfig& t : scene.targets) {
    SiteTarget s{t.name, false, std::nullopt};
    const std::optional<Eigen::Matrix4d>& pose = t.T_map_target ? t.T_map_target : t.T_world_target;
    if (pose) s.at = std::array<double, 2>{(*pose)(0, 3), (*pose)(1, 3)};
    s.reachable = pose.has_value() && t.stop.has_value();
    out.push_back(std::move(s));
  }
  return out;
}

ShowControl::ShowControl(std::vector<SiteTarget> targets)
    : targets_(std::move(targets)), state_(std::make_shared<const ShowState>()) {}

void ShowControl::set_blackout(bool on, double asked_s) {
  {
    const std::lock_guard lock(mutex_);
    if (on && !blackout_) blackout_asked_s_ = asked_s;
    if (!on) blackout_asked_s_ = -1.0;
  }
  blackout_ = on;
  asked_.notify_all();
}

bool ShowControl::sleep_until(double until_s) const {
  std::unique_lock lock(mutex_);
  const auto wait = std::chrono::duration<double>(std::max(0.0, until_s - config::steady_now_s()));
  return asked_.wait_for(lock, wait, [this] { return blackout_asked_s_ >= 0.0; });
}

bool ShowControl::go_to(const std::string& target) {
  const auto it = std::find_if(targets_.begin(), targets_.end(), [&](const SiteTarget& t) { return t.name == target; });
  if (it == targets_.end() || !it->reachable) return false;
  go_to_ = static_cast<int>(it - targets_.begin());
  return true;
}

std::optional<int> ShowControl::take_go_to() {
  const int t = go_to_.exchange(-1);
  return t >= 0 ? std::optional<int>(t) : std::nullopt;
}

std::optional<int> ShowControl::pending_go_to() const {
  const int t = go_to_.load();
  return t >= 0 ? std::optional<int>(t) : std::nullopt;
}

std::optional<double> ShowControl::take_blackout_asked() {
  const std::lock_guard lock(mutex_);
  if (blackout_asked_s_ < 0.0) return std::nullopt;
  const double t = blackout_asked_s_;
  blackout_asked_s_ = -1.0;
  return t;
}

std::shared_ptr<const ShowState> ShowControl::state() const {
  const std::lock_guard lock(mutex_);
  return state_;
}

std::shared_ptr<const ShowState> ShowControl::wait_newer(std::uint64_t sequence, int timeout_ms) const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, std::chrono::milliseconds(timeout_ms), [&] { return state_->sequence > sequence; });
  return state_;
}

void ShowControl::publish(ShowState state) {
  auto next = std::make_shared<ShowState>(std::move(state));  // built outside the lock
  {
    const std::lock_guard lock(mutex_);
    next->sequence = state_->sequence + 1;
    state_ = std::move(next);
  }
  changed_.notify_all();
}

void ShowReporter::frame(const DecidedFrame& f, const StopView& stop, const ProjectionFigures& figures, double now_s,
                         double clock_s) {
  starts_.push_back(now_s);
  if (!f.uniform) drawn_ = f.drawn;
  while (!starts_.empty() && starts_.front() < now_s - 1.0) starts_.pop_front();
  if (!stop.lit.empty() && stop.visit != stops_visit_) {
    stops_.push_back(stop.believed);
    stops_visit_ = stop.visit;
  }
  if (now_s - last_published_s_ < period_s_) return;
  last_published_s_ = now_s;
  control_.publish(build(stop, figures, clock_s));
}

// The targets' states say what the projector shows when not blacked out (or black or grey for a
// reflectance): the newest frame that showed the targets.
ShowState ShowReporter::build(const StopView& stop, const ProjectionFigures& figures, double clock_s) const {
  ShowState s;
  s.clock_s = clock_s;
  s.visit = stop.visit;
  s.phase = stop.done          ? "stopped"
            : stop.lit.empty() ? (stop.visit == 0 ? "starting" : "driving")
            : drawn_.empty()   ? "acquiring"
                               : "lit";
  const std::vector<SiteTarget>& site = control_.targets();
  if (!stop.lit.empty()) s.visiting = site.at(static_cast<std::size_t>(stop.lit.front())).name;
  s.stops = stops_;
  const ProjectionRow* newest = figures.rows.empty() ? nullptr : &figures.rows.back();
  for (std::size_t i = 0; i < site.size(); ++i) {
    TargetShowState t;
    t.name = site[i].name;
    t.at = site[i].at;
    const int index = static_cast<int>(i);
    const bool lit = std::find(stop.lit.begin(), stop.lit.end(), index) != stop.lit.end();
    const bool drawn = std::any_of(drawn_.begin(), drawn_.end(), [&](const DrawnPose& d) { return d.target == index; });
    t.state = drawn ? "lit" : lit ? "blank" : "idle";
    t.visited = !stop.lit.empty() && stop.lit.front() == index;
    if (drawn && newest && newest->target == index && !std::isnan(newest->error_mm)) t.error_mm = newest->error_mm;
    s.targets.push_back(std::move(t));
  }
  const double span_s = starts_.empty() ? 0.0 : starts_.back() - starts_.front();
  s.frame_rate_hz = span_s > 0.0 ? static_cast<double>(starts_.size() - 1) / span_s : 0.0;
  s.pose_age_ms = newest ? newest->age_ms : -1.0;
  s.blackout = control_.blackout();
  s.paused = control_.paused();
  if (const auto g = control_.pending_go_to()) s.go_to = site.at(static_cast<std::size_t>(*g)).name;
  return s;
}

}  // namespace projbot::live
