#pragma once
// A session from a recording (projbot record): the devices that answer what they answered then, the
// poses.csv it keeps of every frame's poses, and the check of a replay's poses against them.

#include <Eigen/Core>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/robot/navigator.hpp"
#include "projbot/robot/pan_tilt.hpp"

namespace projbot::live {

/// A replay's one clock: seconds on the recording's time line (0 where the replay starts), kept by the
/// projector's frames (the render thread) and the session (the robot thread) together, so that a replay is
/// the same frame for frame however fast the machine: the robot does what it did at time t (a frame handed
/// to the trackers and tracked, a drive) only once the projector has reached t, and the projector draws
/// its frame of time T only once the robot has done everything up to T and waits for something later.
/// Nothing sleeps on the wall clock: a headless replay runs as fast as it can track and draw.
class ReplayClock {
 public:
  /// The render thread's: now is the frame's time; sleep_until(T) moves it on to T, then waits for the
  /// robot to be past T (or finished).
  config::Clock projector();
  /// The robot thread's: now is the time of what it does; sleep_until(t) moves it on to t, then waits
  /// for the projector to reach t (or to be closed).
  config::Clock robot();
  /// The session is over (or failed): the projector no longer waits for it.
  void robot_finished();
  /// The projector draws no more (the run ends): the robot no longer waits for it.
  void close();

 private:
  void projector_until(double t_s);
  void robot_until(double t_s);
  std::mutex mutex_;
  std::condition_variable moved_;
  double projector_s_ = 0.0, robot_s_ = 0.0;
  bool robot_waiting_ = false, finished_ = false, closed_ = false;
};

/// A recording's devices: what the base and pan-tilt answered at each stop, and each stop's dump played
/// at its recorded pace. The session must ask for the recorded stops in order; anything else is a
/// SessionError saying where the replay left the recording.
class ReplayRig final : public Rig, public robot::Navigator, public robot::PanTilt {
 public:
  /// Its drives, frames and stops keep time on `clock` (the robot's side of a ReplayClock).
  ReplayRig(const config::Scene& scene, const config::Recording& recording, const std::vector<Target>& targets,
            config::Clock clock);
  StopSequence& session() override { return *session_; }
  /// Each recorded stop's frames, tracked in lockstep (`dwell_s` does not apply: a stop lasts its frames).
  Dwell dwell(double dwell_s) override;
  int visits(int /*asked*/) const override { return static_cast<int>(recording_.stops.size()); }

  robot::StopReport drive_to(const robot::Pose2D& goal, int index) override;
  robot::Pose2D believed_pose() const override;
  robot::PanTiltStatus move_to(const robot::PanTiltAngles& angles) override;
  robot::PanTiltStatus position(robot::PanTiltAngles& out) override;

 private:
  const config::Recording& recording_;
  int stop_ = -1;  // the recorded stop the robot is at
  std::unique_ptr<alignment::FakenectDumpReader> camera_;
  std::unique_ptr<StopSequence> session_;
};

/// poses.csv: what each lit target's worker published for every frame of a lockstep session.
class PoseLog {
 public:
  /// The file's first line: what PoseCheck checks before it reads one.
  static constexpr const char* kHeader = "visit,frame,target,published,lost,r00,r01,r02,tx,r10,r11,r12,ty,r20,r21,r22,tz";
  /// One row per lit target of a frame (stop.lit's order). Appended to the text.
  void add(const config::Scene& scene, const Stop& stop, int frame,
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
  void compare(const config::Scene& scene, const Stop& stop, int frame,
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

}  // namespace projbot::live
