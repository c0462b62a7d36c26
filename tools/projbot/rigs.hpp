#pragma once
// The devices a projection session drives, by where they come from (issue 12): the twin's (its robot and
// pan-tilt, its camera unless the config names one), or a recording's (the base and pan-tilt answer what
// they answered then, the camera plays each stop's fakenect dump). `run`, `record` and `run --replay`
// drive the same session::Session through one of them; nothing in the session knows which.

#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>
#include <vector>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/hardware/devices.hpp"
#include "projbot/session/session.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::tools {

/// Every tracked target's model as the estimator knows it, and a tracker worker for each: the same for a
/// live run, a recording and its replay, so that the same frames give the same poses.
struct SceneTrackers {
  std::vector<std::unique_ptr<alignment::ModelCloud>> clouds;    ///< by scene index; null: not tracked
  std::vector<std::unique_ptr<alignment::TrackerWorker>> owned;  ///< by scene index
  std::vector<alignment::PoseTracker*> workers;                  ///< by scene index, for Session::visit
  std::vector<session::Target> targets;                          ///< for the session
};
/// The trackers' configuration: prediction on or off. In lockstep (record, replay) a search is bounded by
/// its work instead of wall time, so the same frames take the same steps however fast the machine is.
alignment::WorkerConfig worker_config(bool predict, bool lockstep);
/// Loads every target with a world or map pose (its model scaled and recentred, 50k surface samples).
SceneTrackers make_trackers(const config::Scene& scene, const alignment::WorkerConfig& config);

/// The twin serving the session's robot (and camera, unless `configured`). Renders on the thread that
/// builds it, which must be the one that drives it.
class TwinRig {
 public:
  TwinRig(const config::Scene& scene, const std::vector<session::Target>& targets, std::uint64_t seed,
          alignment::RgbdCamera* configured, bool colour_every_frame = false);
  session::Session& session() { return session_; }
  twin::Twin& twin() { return twin_; }
  /// The dwell: `dwell_s` at each stop, the camera the configured one or the twin's.
  session::Dwell dwell(double dwell_s, bool lockstep);

 private:
  engine::Renderer renderer_;
  twin::Twin twin_;
  twin::TwinCamera twin_camera_;
  alignment::RgbdCamera* configured_;
  session::Session session_;
};

/// The configured devices serving the whole session: the base over ROS 2 topics (closing the loop on its
/// odometry, started at the scene's robot.start), the PTU-D46 and the camera. No twin, so no truth.
class DeviceRig {
 public:
  /// `devices` (base, pan_tilt and camera opened; the laser when configured) outlive the rig. With a
  /// laser, the base localises on it against the scene's devices.laser.map (without a map its scans are
  /// only recorded: a mapping run). Throws RobotError when the
  /// base sends no odometry, the laser no scan or the map cannot be read.
  DeviceRig(const config::Scene& scene, const std::vector<session::Target>& targets, hardware::Devices& devices);
  session::Session& session() { return session_; }
  session::Dwell dwell(double dwell_s, bool lockstep);
  robot::Ros2Navigator& navigator() { return navigator_; }

 private:
  std::optional<robot::Localizer> map_;
  robot::Ros2Navigator navigator_;
  alignment::RgbdCamera& camera_;
  session::Session session_;
};

/// A recording's devices: what the base and pan-tilt answered at each stop, and each stop's dump played
/// at its recorded pace. The session must ask for the recorded stops in order; anything else is a
/// SessionError saying where the replay left the recording.
class ReplayRig final : public robot::Navigator, public robot::PanTilt {
 public:
  ReplayRig(const config::Scene& scene, const config::Recording& recording, const std::vector<session::Target>& targets);
  session::Session& session() { return *session_; }
  session::Dwell dwell();

  robot::StopReport drive_to(const robot::Pose2D& goal, int index) override;
  robot::Pose2D believed_pose() const override;
  robot::PanTiltStatus move_to(const robot::PanTiltAngles& angles) override;
  robot::PanTiltStatus position(robot::PanTiltAngles& out) override;

 private:
  const config::Recording& recording_;
  int stop_ = -1;  // the recorded stop the robot is at
  std::unique_ptr<alignment::FakenectDumpReader> camera_;
  std::unique_ptr<session::Session> session_;
};

/// poses.csv: what each lit target's worker published for every frame of a lockstep session.
class PoseLog {
 public:
  /// The file's first line: what PoseCheck checks before it reads one.
  static constexpr const char* kHeader = "visit,frame,target,published,lost,r00,r01,r02,tx,r10,r11,r12,ty,r20,r21,r22,tz";
  /// One row per lit target of a frame (stop.lit's order). Appended to the text.
  void add(const config::Scene& scene, const session::Stop& stop, int frame,
           const std::vector<std::optional<alignment::PoseSample>>& samples);
  const std::string& text() const { return text_; }

 private:
  std::string text_ = std::string(kHeader) + "\n";
};

/// A replay's poses against the recording's, frame for frame.
class PoseCheck {
 public:
  /// Reads poses.csv. Throws config::ConfigError naming the file and line for a malformed one.
  explicit PoseCheck(const std::filesystem::path& csv);
  void compare(const config::Scene& scene, const session::Stop& stop, int frame,
               const std::vector<std::optional<alignment::PoseSample>>& samples);
  int compared = 0;      ///< poses found in both
  int mismatched = 0;    ///< published or lost in one and not the other, or missing from the recording
  double max_mm = 0.0;   ///< largest translation difference, mm
  double max_deg = 0.0;  ///< largest rotation difference, degrees
  /// Rows of the recording the replay never compared (frames it did not reach, or that do not exist).
  int unreached() const;

 private:
  struct Row {
    bool published = false, lost = false;
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  };
  std::map<std::tuple<int, int, std::string>, Row> rows_;  // visit, frame, target
  std::set<std::tuple<int, int, std::string>> reached_;
};

}  // namespace projbot::tools
