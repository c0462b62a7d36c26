#pragma once
// A session from a recording (projbot record): the devices that answer what they answered then, the
// poses.csv it keeps of every frame's poses, and the check of a replay's poses against them.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/robot/navigator.hpp"
#include "projbot/robot/pan_tilt.hpp"
#include "projbot/session/session.hpp"

namespace projbot::session {

/// A recording's devices: what the base and pan-tilt answered at each stop, and each stop's dump played
/// at its recorded pace. The session must ask for the recorded stops in order; anything else is a
/// SessionError saying where the replay left the recording.
class ReplaySession final : public robot::Navigator, public robot::PanTilt {
 public:
  ReplaySession(const config::Scene& scene, const config::Recording& recording, const std::vector<session::Target>& targets);
  Session& session() { return *session_; }
  Dwell dwell();

  robot::StopReport drive_to(const robot::Pose2D& goal, int index) override;
  robot::Pose2D believed_pose() const override;
  robot::PanTiltStatus move_to(const robot::PanTiltAngles& angles) override;
  robot::PanTiltStatus position(robot::PanTiltAngles& out) override;

 private:
  const config::Recording& recording_;
  int stop_ = -1;  // the recorded stop the robot is at
  std::unique_ptr<alignment::FakenectDumpReader> camera_;
  std::unique_ptr<Session> session_;
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

}  // namespace projbot::session
