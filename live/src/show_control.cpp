#include "projbot/live/show_control.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "projbot/config/clock.hpp"

namespace projbot::live {

std::vector<SiteTarget> site_targets(const config::Scene& scene) {
  std::vector<SiteTarget> out;
  for (const config::TargetConfig& t : scene.targets) {
    SiteTarget s{t.name, false, std::nullopt, ""};
    const std::optional<Eigen::Matrix4d>& pose = t.T_map_target ? t.T_map_target : t.T_world_target;
    if (pose) s.at = std::array<double, 2>{(*pose)(0, 3), (*pose)(1, 3)};
    s.reachable = pose.has_value() && t.stop.has_value();
    if (t.content && !t.content->video.empty()) s.content = t.content->video.filename().string();
    out.push_back(std::move(s));
  }
  return out;
}

ShowControl::ShowControl(std::vector<SiteTarget> targets, std::filesystem::path content_folder)
    : targets_(std::move(targets)), state_(std::make_shared<const ShowState>()), content_folder_(std::move(content_folder)) {
  for (const SiteTarget& t : targets_) content_.push_back(t.content);
}

std::vector<std::string> ShowControl::content_files() const {
  std::vector<std::string> out;
  std::error_code ec;
  if (content_folder_.empty()) return out;
  const std::filesystem::path folder = std::filesystem::canonical(content_folder_, ec);
  if (ec) return out;
  for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.front() == '.') continue;
    const std::filesystem::path real = std::filesystem::canonical(entry.path(), ec);  // a link followed
    if (ec || real.parent_path() != folder || !std::filesystem::is_regular_file(real, ec)) continue;
    out.push_back(name);
  }
  std::sort(out.begin(), out.end());
  return out;
}

ShowControl::ContentAnswer ShowControl::switch_content(const std::string& target, const std::string& file) {
  if (content_folder_.empty()) return ContentAnswer::no_folder;
  const auto it = std::find_if(targets_.begin(), targets_.end(), [&](const SiteTarget& t) { return t.name == target; });
  if (it == targets_.end()) return ContentAnswer::no_target;
  if (it->content.empty()) return ContentAnswer::no_video;
  const std::vector<std::string> files = content_files();  // a name listed, never a path
  if (std::find(files.begin(), files.end(), file) == files.end()) return ContentAnswer::no_file;
  const auto index = static_cast<std::size_t>(it - targets_.begin());
  const std::lock_guard lock(mutex_);
  content_[index] = file;
  switches_.emplace_back(static_cast<int>(index), content_folder_ / file);
  return ContentAnswer::switched;
}

std::string ShowControl::said(ContentAnswer answer, const std::string& target, const std::string& file) const {
  switch (answer) {
    case ContentAnswer::no_folder:
      return "the site file names no content_folder: no content to switch to";
    case ContentAnswer::no_target:
      return "no target '" + target + "'";
    case ContentAnswer::no_video:
      return "target '" + target + "' plays no video to switch";
    case ContentAnswer::no_file:
      return "no file '" + file + "' in the content folder (GET /api/content lists them)";
    default:
      return "";
  }
}

std::vector<std::pair<int, std::filesystem::path>> ShowControl::take_content_switches() {
  const std::lock_guard lock(mutex_);
  return std::exchange(switches_, {});
}

std::string ShowControl::content_of(std::size_t index) const {
  const std::lock_guard lock(mutex_);
  return index < content_.size() ? content_[index] : std::string();
}

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
  count(f, stop, figures);
  if (now_s - last_published_s_ < period_s_) return;
  last_published_s_ = now_s;
  control_.publish(build(stop, figures, clock_s));
}

// The tour's row for the stop's visit: each frame at a stop counted, those that drew its visited target,
// and that target's error at display where measured (the newest row measured is the frame before's).
void ShowReporter::count(const DecidedFrame& f, const StopView& stop, const ProjectionFigures& figures) {
  if (stop.lit.empty() || stop.visit <= 0) return;
  const int visited = stop.lit.front();
  if (tour_.empty() || tour_.back().visit != stop.visit) {
    tour_.emplace_back();
    tour_.back().visit = stop.visit;
    tour_.back().target = control_.targets().at(static_cast<std::size_t>(visited)).name;
  }
  VisitShowRow& row = tour_.back();
  ++row.frames;
  if (!f.uniform && std::any_of(f.drawn.begin(), f.drawn.end(), [&](const DrawnPose& d) { return d.target == visited; }))
    ++row.lit_frames;
  const ProjectionRow* newest = figures.rows.empty() ? nullptr : &figures.rows.back();
  if (!newest || newest->target != visited || std::isnan(newest->error_mm) || newest->clock_s == last_counted_s_) return;
  last_counted_s_ = newest->clock_s;
  const double sum = (row.measured > 0 ? row.mean_mm * static_cast<double>(row.measured) : 0.0) + newest->error_mm;
  row.mean_mm = sum / static_cast<double>(++row.measured);
  row.worst_mm = std::max(row.worst_mm, newest->error_mm);
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
  s.robot = stop.moving ? stop.moving : stops_.empty() ? std::nullopt : std::optional(stops_.back());
  if (!stop.lit.empty()) s.T_map_projector = stop.T_map_projector;
  const ProjectionRow* newest = figures.rows.empty() ? nullptr : &figures.rows.back();
  for (std::size_t i = 0; i < site.size(); ++i) {
    TargetShowState t;
    t.name = site[i].name;
    t.at = site[i].at;
    const int index = static_cast<int>(i);
    const bool lit = std::find(stop.lit.begin(), stop.lit.end(), index) != stop.lit.end();
    const auto d = std::find_if(drawn_.begin(), drawn_.end(), [&](const DrawnPose& p) { return p.target == index; });
    const bool drawn = d != drawn_.end();
    t.state = drawn ? "lit" : lit ? "blank" : "idle";
    if (drawn && stop.T_map_camera) {
      t.T_map_target = *stop.T_map_camera * Eigen::Isometry3d(d->T_camera_target);
      t.quality = d->quality;
    }
    t.visited = !stop.lit.empty() && stop.lit.front() == index;
    t.content = control_.content_of(i);
    if (drawn && newest && newest->target == index && !std::isnan(newest->error_mm)) t.error_mm = newest->error_mm;
    s.targets.push_back(std::move(t));
  }
  const double span_s = starts_.empty() ? 0.0 : starts_.back() - starts_.front();
  s.frame_rate_hz = span_s > 0.0 ? static_cast<double>(starts_.size() - 1) / span_s : 0.0;
  s.pose_age_ms = newest ? newest->age_ms : -1.0;
  s.blackout = control_.blackout();
  s.paused = control_.paused();
  if (const auto g = control_.pending_go_to()) s.go_to = site.at(static_cast<std::size_t>(*g)).name;
  s.tour = tour_;
  return s;
}

}  // namespace projbot::live
