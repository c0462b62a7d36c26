#include "projbot/live/record.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/live/devices.hpp"
#include "projbot/live/replay.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/trackers.hpp"
#include "projbot/robot/localization.hpp"

namespace projbot::live {
namespace {

namespace fs = std::filesystem;

// The camera's frames as a fakenect dump holds them (depth through the Kinect's 11-bit disparity), so the
// trackers see here what a replay of the dump will see.
class QuantisedCamera final : public alignment::RgbdCamera {
 public:
  alignment::RgbdCamera* inner = nullptr;
  alignment::RgbdFrame next() override {
    alignment::RgbdFrame f = inner->next();
    if (f.colour.rgba.empty())
      throw live::DeviceError("the camera delivers no colour, and a fakenect dump holds depth and colour together");
    f.depth = alignment::kinect_quantised(std::move(f.depth));
    return f;
  }
};

// Writes each stop as it ends: its dump (frame by frame), then recording.yaml and poses.csv rewritten,
// so a recording cut short holds every stop that was left.
class RecordObserver final : public live::StopObserver {
 public:
  RecordObserver(const config::Scene& scene, config::Recording& recording, const fs::path& out, const RecordHooks& hooks,
                 SurfaceSurvey* survey)
      : scene_(scene), rec_(recording), out_(out), hooks_(hooks), survey_(survey) {}
  void lit(const live::Stop& stop, double) override {
    char name[32];
    std::snprintf(name, sizeof name, "stop%02d", stop.visit + 1);
    current_ = config::RecordedStop{};
    current_.visit = stop.visit;
    current_.target = scene_.targets[static_cast<std::size_t>(stop.target)].name;
    current_.goal = {stop.drive.goal.x_m, stop.drive.goal.y_m, stop.drive.goal.theta_rad};
    current_.believed = {stop.drive.estimate.x_m, stop.drive.estimate.y_m, stop.drive.estimate.theta_rad};
    current_.pan_rad = stop.angles.pan_rad;
    current_.tilt_rad = stop.angles.tilt_rad;
    current_.drive_s = stop.drive.drive_seconds;
    current_.arrived = stop.drive.arrived;
    current_.frames = name;
    writer_ = std::make_unique<alignment::FakenectDumpWriter>(out_ / name);
    accepted_.assign(stop.lit.size(), std::nullopt);
  }
  void frame(const live::Stop& stop, int k, const alignment::RgbdFrame& f,
             const std::vector<std::optional<alignment::PoseSample>>& samples) override {
    if (t0_s_ < 0.0) t0_s_ = f.depth.capture_time_s;
    writer_->add({&f.depth, &f.colour, f.depth.capture_time_s - t0_s_});
    poses_.add(scene_, stop, k, samples);
    for (std::size_t j = 0; j < samples.size() && j < accepted_.size(); ++j)
      if (samples[j]) accepted_[j] = samples[j]->lost ? std::nullopt : std::optional(samples[j]->T_camera_target);
    current_.frame_count = k + 1;
    ++frames;
    if (hooks_.frame) hooks_.frame(frames);
  }
  void left(const live::Stop& stop) override {
    rec_.stops.push_back(current_);
    const std::string measured = measure_reflectance(stop);
    save();
    *hooks_.log << "stop " << rec_.stops.size() << ": " << current_.target << ", " << current_.frame_count << " frames recorded"
                << measured << std::endl;
  }
  // A laser scan with the odometry then, as a rawlog step (its odometry the increment since the last).
  void scan(const robot::LaserScan& scan, const robot::Pose2D& odometry) {
    robot::RawlogStep step;
    step.timestamp_s = scan.timestamp_s;
    if (last_odometry_) step.odometry_increment = robot::between(*last_odometry_, odometry);
    step.scan = scan;
    scans_.push_back(std::move(step));
    last_odometry_ = odometry;
  }
  void save() const {
    if (!scans_.empty()) {  // written whole, then renamed: a reader never sees half a rawlog
      robot::write_rawlog(out_ / "laser.rawlog.tmp", scans_);
      fs::rename(out_ / "laser.rawlog.tmp", out_ / "laser.rawlog");
      rec_.laser = "laser.rawlog";
    }
    if (survey_) save_reflectance();
    config::write_file_atomically(out_ / "poses.csv", poses_.text());
    config::write_file_atomically(out_ / "recording.yaml", config::recording_yaml(rec_));
  }
  int frames = 0;

 private:
  // With a camera that sees its own projector's light (the twin's): each lit target whose last pose was accepted, measured at
  // that pose; what the log line says of it.
  std::string measure_reflectance(const live::Stop& stop) {
    if (!survey_) return "";
    std::string said;
    for (std::size_t j = 0; j < accepted_.size() && j < stop.lit.size(); ++j) {
      if (!accepted_[j]) continue;
      const std::string& name = scene_.targets[static_cast<std::size_t>(stop.lit[j].target)].name;
      said += (said.empty() ? "; reflectance measured: " : ", ") + name + " (" +
              std::to_string(survey_->measure(name, *accepted_[j])) + " points)";
    }
    return said;
  }
  // What was learnt so far, in recording.yaml: a map as reflectance/NAME.png, a target without texture
  // coordinates as its albedo.
  void save_reflectance() const {
    for (const auto& [name, learnt] : survey_->learnt()) {
      config::TargetSurface& surface = rec_.reflectance[name];
      surface.albedo = learnt.albedo;
      if (!learnt.map) continue;
      if (surface.texture.empty()) surface.texture = map_file(name);
      fs::create_directories(out_ / "reflectance");
      assets::write_png(out_ / surface.texture, *learnt.map);
    }
  }

  // reflectance/NAME.png, NAME's characters other than letters, digits, - and _ made _, and a number added
  // where that names another target's file.
  std::string map_file(const std::string& name) const {
    const std::string stem = config::file_stem(name);
    const auto taken = [&](const std::string& file) {
      return std::any_of(rec_.reflectance.begin(), rec_.reflectance.end(),
                         [&](const auto& r) { return r.second.texture == file; });
    };
    std::string file = "reflectance/" + stem + ".png";
    for (int k = 2; taken(file); ++k) file = "reflectance/" + stem + "_" + std::to_string(k) + ".png";
    return file;
  }

  const config::Scene& scene_;
  config::Recording& rec_;
  fs::path out_;
  const RecordHooks& hooks_;
  config::RecordedStop current_;
  std::unique_ptr<alignment::FakenectDumpWriter> writer_;
  live::PoseLog poses_;
  std::vector<robot::RawlogStep> scans_;  // the robot's laser and odometry so far
  std::optional<robot::Pose2D> last_odometry_;
  double t0_s_ = -1.0;
  SurfaceSurvey* survey_;                                 // null: no reflectance measured
  std::vector<std::optional<Eigen::Matrix4d>> accepted_;  // each lit target's last accepted pose at this stop
};

// The scene's devices for a recording (none with `sim`); the camera's name goes into the recording.
live::Devices open_devices(const config::Scene& scene, bool sim, config::Recording& rec) {
  rec.camera = "the twin's camera";
  if (sim) return {};
  config::DevicesConfig wanted = scene.devices;
  wanted.projector.reset();  // nothing is projected while recording
  std::vector<live::DeviceCheck> checks;
  bool robot = false;
  live::Devices devices = live::open_session_devices(wanted, checks, robot, false);  // a laser without a map: a mapping run
  for (const auto& c : checks)
    if (c.role == "camera") rec.camera = c.config;
  return devices;
}

// The rig's dwell with the camera quantised as the dump holds it and every stop ended by an interrupt.
live::Dwell recording_dwell(Rig& rig, double dwell_s, QuantisedCamera& quantised, const RecordHooks& hooks) {
  live::Dwell dwell = rig.dwell(dwell_s);
  dwell.camera = [&quantised, camera = dwell.camera](const live::Stop& stop, double since_s) -> alignment::RgbdCamera& {
    quantised.inner = &camera(stop, since_s);
    return quantised;
  };
  dwell.over = [&hooks, over = dwell.over](const live::Stop& stop, int frames, double elapsed_s) {
    return (hooks.interrupted && hooks.interrupted()) || over(stop, frames, elapsed_s);
  };
  return dwell;
}

}  // namespace

Recorded record(const config::Scene& scene, const RecordOptions& o, const fs::path& out, const RecordHooks& hooks) {
  if (!hooks.log || !hooks.open_rig) throw std::invalid_argument("live::record needs a log and open_rig in its RecordHooks");
  const auto interrupted = [&hooks] { return hooks.interrupted && hooks.interrupted(); };
  Recorded result;
  config::Recording& rec = result.recording;
  live::Devices devices = open_devices(scene, o.sim, rec);
  rec.scene = fs::absolute(scene.source);
  rec.seed = o.seed;
  rec.dwell_s = o.dwell_s;
  live::SceneTrackers trackers = live::make_trackers(scene, live::worker_config(true, true));
  // The robot: the configured base, pan-tilt and camera together, or the twin's (with the configured camera, if any).
  const std::unique_ptr<Rig> opened = hooks.open_rig(
      scene, trackers.targets, devices, {.recording = true, .interrupted = interrupted, .replay = nullptr, .replay_clock = {}});
  Rig& rig = *opened;
  QuantisedCamera quantised;
  const live::Dwell dwell = recording_dwell(rig, o.dwell_s, quantised, hooks);
  if (interrupted()) return result;  // no folder made
  std::error_code ec;
  fs::create_directories(out, ec);  // only now: a set-up that fails or is stopped leaves no folder behind
  if (ec) throw config::ConfigError(out.string() + ": cannot create: " + ec.message());
  result.started = true;
  const std::unique_ptr<SurfaceSurvey> survey = rig.reflectance_survey();
  RecordObserver observer(scene, rec, out, hooks, survey.get());
  rig.on_scan([&observer](const robot::LaserScan& scan, const robot::Pose2D& odometry) { observer.scan(scan, odometry); });
  const std::stop_source never;
  for (int v = 0; v < o.visits && !interrupted(); ++v)
    rig.session().visit(v, trackers.workers, dwell, observer, never.get_token());
  rec.interrupted = interrupted();
  observer.save();
  result.frames = observer.frames;
  return result;
}

}  // namespace projbot::live
