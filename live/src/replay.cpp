#include "projbot/live/replay.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/rigid.hpp"

namespace projbot::live {

config::Clock ReplayClock::projector() {
  return {[this] {
            std::lock_guard lock(mutex_);
            return projector_s_;
          },
          [this](double t_s) { projector_until(t_s); }};
}

config::Clock ReplayClock::robot() {
  return {[this] {
            std::lock_guard lock(mutex_);
            return robot_s_;
          },
          [this](double t_s) { robot_until(t_s); }};
}

void ReplayClock::projector_until(double t_s) {
  std::unique_lock lock(mutex_);
  projector_s_ = std::max(projector_s_, t_s);
  moved_.notify_all();
  moved_.wait(lock, [&] { return finished_ || closed_ || (robot_waiting_ && robot_s_ > projector_s_); });
}

void ReplayClock::robot_until(double t_s) {
  std::unique_lock lock(mutex_);
  robot_s_ = std::max(robot_s_, t_s);
  robot_waiting_ = true;
  moved_.notify_all();
  moved_.wait(lock, [&] { return closed_ || projector_s_ >= robot_s_; });
  robot_waiting_ = false;
}

void ReplayClock::robot_finished() {
  std::lock_guard lock(mutex_);
  finished_ = true;
  moved_.notify_all();
}

void ReplayClock::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  moved_.notify_all();
}

ReplayRig::ReplayRig(const config::Scene& scene, const config::Recording& recording, const std::vector<Target>& targets,
                     config::Clock clock)
    : recording_(recording), session_(std::make_unique<StopSequence>(scene, targets, *this, *this, std::move(clock))) {}

Dwell ReplayRig::dwell(double /*dwell_s*/) {
  Dwell d;
  d.camera = [this](const Stop&, double) -> alignment::RgbdCamera& {
    const config::RecordedStop& s = recording_.stops.at(static_cast<std::size_t>(stop_));
    camera_ = std::make_unique<alignment::FakenectDumpReader>(recording_.folder() / s.frames, true, session_->clock());
    if (camera_->frames() < s.frame_count)
      throw SessionError(recording_.source.string() + ": stop " + std::to_string(stop_ + 1) + " lists " +
                         std::to_string(s.frame_count) + " frames but its dump " + s.frames + " holds " +
                         std::to_string(camera_->frames()));
    return *camera_;
  };
  d.over = [this](const Stop&, int frames, double) {
    return frames >= recording_.stops.at(static_cast<std::size_t>(stop_)).frame_count;
  };
  d.lockstep = true;
  return d;
}

robot::StopReport ReplayRig::drive_to(const robot::Pose2D& goal, int index) {
  if (index < 0 || index >= static_cast<int>(recording_.stops.size()))
    throw SessionError(recording_.source.string() + ": the replay asked for stop " + std::to_string(index + 1) +
                       " but the recording holds " + std::to_string(recording_.stops.size()));
  const config::RecordedStop& s = recording_.stops[static_cast<std::size_t>(index)];
  if (std::abs(goal.x_m - s.goal.x()) > 1e-9 || std::abs(goal.y_m - s.goal.y()) > 1e-9 ||
      std::abs(goal.theta_rad - s.goal.z()) > 1e-9)
    throw SessionError(recording_.source.string() + ": stop " + std::to_string(index + 1) + " of the recording went to '" +
                       s.target + "''s stop, but the scene's tour asks for another one here (a different scene or tour?)");
  stop_ = index;
  const config::Clock& clock = session_->clock();
  clock.sleep_until(clock.now_s() + s.drive_s);  // the drive takes its recorded time on the replay's clock
  robot::StopReport r;
  r.index = index;
  r.goal = goal;
  r.estimate = believed_pose();
  r.arrived = s.arrived;
  r.drive_seconds = s.drive_s;
  return r;
}

robot::Pose2D ReplayRig::believed_pose() const {
  if (stop_ < 0) return {};
  const Eigen::Vector3d& b = recording_.stops[static_cast<std::size_t>(stop_)].believed;
  return {b.x(), b.y(), b.z()};
}

robot::PanTiltStatus ReplayRig::move_to(const robot::PanTiltAngles&) { return {}; }

robot::PanTiltStatus ReplayRig::position(robot::PanTiltAngles& out) {
  const config::RecordedStop& s = recording_.stops.at(static_cast<std::size_t>(stop_));
  out = {s.pan_rad, s.tilt_rad};
  return {};
}

void PoseLog::add(const config::Scene& scene, const Stop& stop, int frame,
                  const std::vector<std::optional<alignment::PoseSample>>& samples) {
  std::ostringstream row;
  row << std::setprecision(17);
  for (std::size_t j = 0; j < samples.size() && j < stop.lit.size(); ++j) {
    row << stop.visit << ',' << frame << ',' << scene.targets[static_cast<std::size_t>(stop.lit[j].target)].name << ','
        << (samples[j] ? 1 : 0) << ',' << (samples[j] && samples[j]->lost ? 1 : 0);
    const Eigen::Matrix4d T = samples[j] ? samples[j]->T_camera_target : Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) row << ',' << T(r, c);
    row << '\n';
  }
  text_ += row.str();
}

namespace {

// A whole number >= 0 written as digits only, or -1.
int whole_number(const std::string& text) {
  int out = -1;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && end == text.data() + text.size() && out >= 0 ? out : -1;
}

}  // namespace

PoseCheck::PoseCheck(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  if (!in) throw config::ConfigError(csv.string() + ": cannot read the recording's poses");
  std::string line;
  if (!std::getline(in, line) || line != PoseLog::kHeader)
    throw config::ConfigError(csv.string() +
                              ":1: not the poses of a recording (its first line is the header projbot record writes)");
  for (int n = 2; std::getline(in, line); ++n) {
    std::istringstream fields(line);
    std::string visit, frame, target, cell;
    Row r;
    std::vector<double> v;
    std::getline(fields, visit, ',');
    std::getline(fields, frame, ',');
    std::getline(fields, target, ',');
    while (std::getline(fields, cell, ',')) {
      try {
        v.push_back(std::stod(cell));
      } catch (const std::exception&) {
        v.clear();
        break;
      }
    }
    const std::string where = csv.string() + ":" + std::to_string(n);
    if (v.size() != 14 || target.empty()) throw config::ConfigError(where + ": expected visit, frame, target and 14 numbers");
    // As strictly as any reader: a NaN or a non-rotation once replayed as "largest difference 0.0000 mm".
    for (const double x : v)
      if (!std::isfinite(x)) throw config::ConfigError(where + ": a value is not a finite number");
    if ((v[0] != 0.0 && v[0] != 1.0) || (v[1] != 0.0 && v[1] != 1.0))
      throw config::ConfigError(where + ": published and lost must be 0 or 1");
    r.published = v[0] != 0.0;
    r.lost = v[1] != 0.0;
    for (int i = 0; i < 12; ++i) r.T(i / 4, i % 4) = v[static_cast<std::size_t>(2 + i)];
    r.T = config::orthonormalised_rigid(r.T, where + ": pose", 1e-6);  // written with 17 digits: exact to 1e-6
    const int visit_n = whole_number(visit), frame_n = whole_number(frame);
    if (visit_n < 0 || frame_n < 0) throw config::ConfigError(where + ": visit and frame must be whole numbers >= 0");
    if (!rows_.emplace(std::make_tuple(visit_n, frame_n, target), r).second)
      throw config::ConfigError(where + ": a second row for visit " + visit + ", frame " + frame + ", target " + target);
  }
}

int PoseCheck::unreached() const {
  int n = 0;
  for (const auto& [key, row] : rows_) n += !reached_.contains(key);
  return n;
}

namespace {

// The angle between two poses' rotations from their difference: for rotations ||R1 - R2|| (Frobenius) is
// 2 sqrt(2) sin(angle / 2), exactly 0 for the same matrix (the trace of R1^T R2 reads 1e-6 degrees there).
double rotation_difference_deg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const double s = std::min(1.0, (a.topLeftCorner<3, 3>() - b.topLeftCorner<3, 3>()).norm() / (2.0 * std::sqrt(2.0)));
  return 2.0 * config::degrees(std::asin(s));
}

}  // namespace

void PoseCheck::compare(const config::Scene& scene, const Stop& stop, int frame,
                        const std::vector<std::optional<alignment::PoseSample>>& samples) {
  for (std::size_t j = 0; j < samples.size() && j < stop.lit.size(); ++j) {
    const std::string& name = scene.targets[static_cast<std::size_t>(stop.lit[j].target)].name;
    const auto it = rows_.find({stop.visit, frame, name});
    if (it != rows_.end()) reached_.insert(it->first);
    if (it == rows_.end() || it->second.published != samples[j].has_value() ||
        (samples[j] && it->second.lost != samples[j]->lost)) {
      ++mismatched;
      continue;
    }
    if (!samples[j]) continue;
    // As the recorded pose was read: its rotation made orthonormal (a tracker's float steps leave ~1e-7).
    const Eigen::Matrix4d T = config::orthonormalised_rigid(samples[j]->T_camera_target, "the replay's pose", 1e-3);
    const Eigen::Matrix4d d = alignment::rigid_inverse(it->second.T) * T;
    max_mm = std::max(max_mm, 1000.0 * alignment::translation_norm_m(d));
    max_deg = std::max(max_deg, rotation_difference_deg(it->second.T, T));
    ++compared;
  }
}

}  // namespace projbot::live
