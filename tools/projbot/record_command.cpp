// projbot record: the projection session at every stop of the tour, written so that `projbot run
// --replay` runs it again with no device and no twin (issue 12, item 4): each stop's camera stream as a
// fakenect dump (it also replays through the real Kinect driver), what the base and pan-tilt answered
// there, and the pose every lit target's tracker gave for every frame, tracked in lockstep.

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/hardware/device_session.hpp"
#include "projbot/hardware/devices.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/session/replay.hpp"
#include "projbot/session/trackers.hpp"
#include "projbot/twin/twin_session.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
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
      throw hardware::DeviceError("the camera delivers no colour, and a fakenect dump holds depth and colour together");
    f.depth = alignment::kinect_quantised(std::move(f.depth));
    return f;
  }
};

// Writes each stop as it ends: its dump (frame by frame), then recording.yaml and poses.csv rewritten,
// so a recording cut short holds every stop that was left.
class RecordObserver final : public session::StopObserver {
 public:
  RecordObserver(const config::Scene& scene, config::Recording& recording, const fs::path& out, Progress& progress)
      : scene_(scene), rec_(recording), out_(out), progress_(progress) {}
  void lit(const session::Stop& stop, double) override {
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
  }
  void frame(const session::Stop& stop, int k, const alignment::RgbdFrame& f,
             const std::vector<std::optional<alignment::PoseSample>>& samples) override {
    if (t0_s_ < 0.0) t0_s_ = f.depth.capture_time_s;
    writer_->add({&f.depth, &f.colour, f.depth.capture_time_s - t0_s_});
    poses_.add(scene_, stop, k, samples);
    current_.frame_count = k + 1;
    progress_.step(++frames);
  }
  void left(const session::Stop&) override {
    rec_.stops.push_back(current_);
    save();
    std::cout << "stop " << rec_.stops.size() << ": " << current_.target << ", " << current_.frame_count << " frames recorded"
              << std::endl;
  }
  void save() const {
    if (!scans.empty()) {  // written whole, then renamed: a reader never sees half a rawlog
      robot::write_rawlog(out_ / "laser.rawlog.tmp", scans);
      fs::rename(out_ / "laser.rawlog.tmp", out_ / "laser.rawlog");
      rec_.laser = "laser.rawlog";
    }
    config::write_file_atomically(out_ / "poses.csv", poses_.text());
    config::write_file_atomically(out_ / "recording.yaml", config::recording_yaml(rec_));
  }
  int frames = 0;
  std::vector<robot::RawlogStep> scans;  // the robot's laser and odometry so far

 private:
  const config::Scene& scene_;
  config::Recording& rec_;
  fs::path out_;
  Progress& progress_;
  config::RecordedStop current_;
  std::unique_ptr<alignment::FakenectDumpWriter> writer_;
  session::PoseLog poses_;
  double t0_s_ = -1.0;
};

}  // namespace

const Command kRecord{
    "record",
    "run the session through the tour and record it (camera, base, pan-tilt, poses) to replay with run --replay",
    "projbot record --out DIR [--config site.yaml] [--sim] [--visits N] [--dwell S] [--seed K]\n\n"
    "Runs the projection session at every stop of the config's tour, as run does, with every camera frame\n"
    "tracked in lockstep (each frame tracked before the next is read; a search bounded by its work, not by\n"
    "wall time), and writes into DIR:\n"
    "  stopNN/         each stop's depth + colour frames, in libfreenect's fakenect format (INDEX.txt, raw\n"
    "                  11-bit depth PGMs, RGB PPMs, the capture times kept)\n"
    "  recording.yaml  the scene, and per stop what the session asked and the devices answered: the stop\n"
    "                  driven to, where the robot then believed it stood, the pan-tilt's angles\n"
    "  poses.csv       the pose each lit target's tracker gave for every frame (the session's decisions)\n"
    "  laser.rawlog    the robot's laser scans and wheel odometry while driving and settling (the twin's, or\n"
    "                  a configured laser's with the base's odometry), as an MRPT rawlog (projbot slam and\n"
    "                  MRPT's own tools read it)\n"
    "`projbot run --replay DIR` runs the same session from them with no device and no twin, and compares\n"
    "its poses with poses.csv frame for frame. A stop's dump also replays through the real Kinect driver:\n"
    "  fakenect DIR/stop01 projbot run --config site.yaml   (camera: {driver: freenect, registered: false})\n"
    "The devices are the config's, as for run: a base, pan-tilt and camera together drive the robot with no\n"
    "twin, localised on a configured laser against devices.laser.map; a laser without a map is only\n"
    "recorded (a mapping run: projbot slam --rawlog DIR/laser.rawlog --start \"robot.start\" makes the site's\n"
    "map, in the scene's frame; record prints the command). A\n"
    "camera alone is read with the twin's robot; none, or --sim, is the twin's. Depth is kept to\n"
    "the Kinect's disparity steps, for the trackers too. Ctrl-C ends the stop in progress and keeps every\n"
    "stop recorded.\n",
    {{"out", "DIR", "the recording's folder (new or empty)", cli::PathRole::output_folder},
     {"config", "FILE", "scene (default: assets/scenes/tour.yaml)", cli::PathRole::input_file},
     {"sim", "", "record the twin's camera whatever `devices:` configures"},
     {"visits", "N", "visits, cycling through the tour (default: the list once)"},
     {"dwell", "S", "seconds at each stop (default 2)"},
     {"seed", "K", "seed of the twin's drive and noise (default 1, as run's)"}},
    [](const cli::Args& args) {
      const auto out = args.get("out");
      if (!out) throw cli::UsageError("--out DIR is required");
      const double dwell_s = args.get_double("dwell", 2.0);
      if (!(dwell_s > 0.0 && dwell_s <= 3600.0)) throw cli::UsageError("--dwell must be in (0, 3600] seconds");
      const auto seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
      args.check_clashes({{"the default scene", (asset_dir() / "scenes" / "tour.yaml"), false}});
      const config::Scene scene = config::load_scene(args.get_or("config", (asset_dir() / "scenes" / "tour.yaml").string()));
      if (scene.visits.empty())
        throw config::ConfigError(scene.source.string() + ": `projbot record` needs a 'tour: {visits: [...]}' section");
      const int visits = args.get_int("visits", static_cast<int>(scene.visits.size()), 1, 1000);
      std::error_code ec;
      if (fs::exists(*out, ec) && !fs::is_empty(*out, ec))
        throw cli::UsageError(*out + ": not empty; a recording needs a new folder");
      catch_interrupts();  // Ctrl-C: during set-up nothing is written; later, end the stop in progress, keep every stop

      hardware::Devices devices;
      config::Recording rec;
      rec.camera = "the twin's camera";
      bool robot = false;
      if (!args.flag("sim")) {
        config::DevicesConfig wanted = scene.devices;
        wanted.projector.reset();  // nothing is projected while recording
        std::vector<hardware::DeviceCheck> checks;
        devices = hardware::open_session_devices(wanted, checks, robot, false);  // a laser without a map: a mapping run
        for (const auto& c : checks)
          if (c.role == "camera") rec.camera = c.config;
      }
      rec.scene = fs::absolute(scene.source);
      rec.seed = seed;
      rec.dwell_s = dwell_s;
      session::SceneTrackers trackers = session::make_trackers(scene, session::worker_config(true, true));
      // The robot: the configured base, pan-tilt and camera together, or the twin's (with the configured camera, if any).
      std::unique_ptr<hardware::DeviceSession> device_rig;
      std::unique_ptr<twin::TwinSession> twin_rig;
      if (robot)
        device_rig = std::make_unique<hardware::DeviceSession>(scene, trackers.targets, devices);
      else
        twin_rig = std::make_unique<twin::TwinSession>(
            scene, trackers.targets, seed, devices.camera.get(), [] { return interrupted(); }, true);
      session::Session& session = robot ? device_rig->session() : twin_rig->session();
      session::Dwell dwell = robot ? device_rig->dwell(dwell_s, true) : twin_rig->dwell(dwell_s, true);
      if (interrupted()) return nothing_written("while setting up");  // no folder made
      fs::create_directories(*out, ec);  // only now: a set-up that fails or is stopped leaves no folder behind
      if (ec) throw cli::UsageError(*out + ": cannot create: " + ec.message());
      Progress progress("frame", static_cast<int>(std::ceil(visits * dwell_s * 30.0)));
      RecordObserver observer(scene, rec, *out, progress);
      // The robot's laser scans and wheel odometry, as an MRPT rawlog: the twin's, or the configured laser's.
      auto scans = [&observer, last = std::optional<robot::Pose2D>()](const robot::LaserScan& scan,
                                                                      const robot::Pose2D& odometry) mutable {
        robot::RawlogStep step;
        step.timestamp_s = scan.timestamp_s;
        if (last) step.odometry_increment = robot::between(*last, odometry);
        step.scan = scan;
        observer.scans.push_back(std::move(step));
        last = odometry;
      };
      if (twin_rig) twin_rig->twin().robot().on_scan(scans);
      if (device_rig) device_rig->navigator().on_scan(scans);
      QuantisedCamera quantised;
      dwell.camera = [&, camera = dwell.camera](const session::Stop& stop, double since_s) -> alignment::RgbdCamera& {
        quantised.inner = &camera(stop, since_s);
        return quantised;
      };
      dwell.over = [over = dwell.over](const session::Stop& stop, int frames, double elapsed_s) {
        return interrupted() || over(stop, frames, elapsed_s);
      };
      const std::stop_source never;
      for (int v = 0; v < visits && !interrupted(); ++v) session.visit(v, trackers.workers, dwell, observer, never.get_token());
      rec.interrupted = interrupted();
      observer.save();
      std::cout << "recorded " << rec.stops.size() << " stop(s), " << observer.frames << " frames from " << rec.camera << " to "
                << *out << "\nreplay: projbot run --replay " << *out << "\n";
      if (!rec.laser.empty())  // the rawlog's odometry starts at robot.start: the map goes in the scene's frame
        std::cout << "map: projbot slam --rawlog " << (fs::path(*out) / rec.laser).string() << " --start \""
                  << scene.robot_start.x() << " " << scene.robot_start.y() << " " << scene.robot_start.z()
                  << "\" --out-map MAP --out-trajectory MAP.txt\n";
      return interrupt_exit_code();
    }};

}  // namespace projbot::tools
