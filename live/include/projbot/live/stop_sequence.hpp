#pragma once
// The projection session (issue 12): the stop sequence written once, against device interfaces. At each
// stop of the tour it drives the base to the visited target's stop (robot::Navigator), aims the pan-tilt
// at the middle of the target where the map says it stands, from where the robot believes it is
// (robot::PanTilt), reads the angles back, and takes Eq. 1's initial guess and the surveyed footing of
// the visited target and of each neighbour the robot expects in the projector's view. Acquiring,
// StopSequence::visit then hands the camera's frames (alignment::RgbdCamera) to the lit targets' trackers
// (alignment::PoseTracker) while the robot dwells, live (`projbot run`: TrackerWorker threads) or in
// lockstep (`record` and `run --replay`: the same; the twin's `tour`: trackers on its simulated clock).
// Nothing here knows which implementation of a device or tracker it drives (twin, hardware or
// recording).

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <stdexcept>
#include <stop_token>
#include <string>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/robot/navigator.hpp"
#include "projbot/robot/pan_tilt.hpp"

namespace projbot::live {

/// A scene the session cannot run (a visited target without a stop or a surveyed pose).
class SessionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Where the map says a target stands: its surveyed map_pose, else its world_pose.
Eigen::Matrix4d surveyed_pose(const config::TargetConfig& target);

/// A target the session can visit or light, as the estimator knows it.
struct Target {
  int scene_index = -1;                                    ///< into config::Scene::targets
  const alignment::ModelCloud* cloud = nullptr;            ///< its model's surface samples; outlives the session
  Eigen::Vector3d middle_model = Eigen::Vector3d::Zero();  ///< its model's bounding-box centre: where the pan-tilt aims
};

/// A target's place in the map known more recently than its survey (a fleet's shared estimate, issue 69),
/// with who found it.
struct MapPose {
  Eigen::Matrix4d T_map_target = Eigen::Matrix4d::Identity();
  std::string from;  ///< said in the log: "r1's estimate"
};
/// A target's newest MapPose (scene index), nullopt where the survey is all there is.
using MapPoses = std::function<std::optional<MapPose>(int target)>;

/// A target the robot projects onto at a stop.
struct LitTarget {
  int target = -1;                                                      ///< scene index
  Eigen::Matrix4d T_map_target = Eigen::Matrix4d::Identity();           ///< as surveyed, or as MapPoses said
  std::string map_pose_from;                                            ///< who placed it there; empty: the survey
  Eigen::Matrix4d T_camera_target_guess = Eigen::Matrix4d::Identity();  ///< Eq. 1, from the believed head
  alignment::Footing footing;                                           ///< the surveyed footing, seen from the believed camera
};

/// The robot at a stop, aimed.
struct Stop {
  int visit = 0;         ///< 0-based, over the whole tour
  int target = -1;       ///< scene index of the visited target
  int target_visit = 0;  ///< 1-based: the visited target's n-th visit
  robot::StopReport drive;
  robot::PanTiltAngles angles;  ///< as the pan-tilt reported them after aiming
  robot::HeadPoses believed;    ///< where the robot believes its camera and projector are
  std::vector<LitTarget> lit;   ///< the visited target first, then its neighbours, nearest first
};

/// Drives to the target's stop, aims at `middle_world` from the believed pose and reads the angles back.
/// Fills drive, angles and believed; throws robot::RobotError naming the pan-tilt when it fails.
void drive_and_aim(const config::Scene& scene, const config::TargetConfig& target, const Eigen::Vector3d& middle_world,
                   robot::Navigator& base, robot::PanTilt& pan_tilt, int index, Stop& stop);

/// What a session's stops tell whoever runs them (run's render thread, record's writer, replay's check).
class StopObserver {
 public:
  virtual ~StopObserver() = default;
  /// The robot sets off for the `visit`-th stop: nothing is lit while it drives.
  virtual void driving(int /*visit*/) {}
  /// Aimed, each lit target's worker given its guess: the stop's lit targets, from `since_s` on (steady
  /// clock; poses of frames captured before belong to an earlier stop).
  virtual void lit(const Stop& /*stop*/, double /*since_s*/) {}
  /// The stop's k-th frame (0-based) was handed to the lit targets' workers. In lockstep, `samples`
  /// holds what each one's worker published for it (stop.lit's order); live, it is empty.
  virtual void frame(const Stop& /*stop*/, int /*k*/, const alignment::RgbdFrame& /*frame*/,
                     const std::vector<std::optional<alignment::PoseSample>>& /*samples*/) {}
  /// The dwell at the stop is over.
  virtual void left(const Stop& /*stop*/) {}
};

/// How a stop's dwell runs.
struct Dwell {
  /// The camera to read at this stop (the robot has just aimed; frames from `since_s` on count).
  std::function<alignment::RgbdCamera&(const Stop&, double since_s)> camera;
  /// Whether the dwell is over after `frames` frames, `elapsed_s` after since_s.
  std::function<bool(const Stop&, int frames, double elapsed_s)> over;
  /// Every frame tracked, in order, before the next is read (record and replay: the same frames give the
  /// same poses); otherwise the workers take the newest frame when they are free (live).
  bool lockstep = false;
};

class StopSequence {
 public:
  /// `targets` are those the tour may visit or light; every visit in scene.visits must name one with a
  /// stop. Throws SessionError naming the first that does not. The devices outlive the session.
  /// Stops and frames are timed on `clock` (a replay's, or the steady clock).
  StopSequence(const config::Scene& scene, std::vector<Target> targets, robot::Navigator& base, robot::PanTilt& pan_tilt,
               config::Clock clock = config::Clock::steady());
  /// The clock its stops and frames are timed on.
  const config::Clock& clock() const { return clock_; }
  /// The robot it drives (to watch its drives).
  robot::Navigator& navigator() { return base_; }
  /// From now on, where `poses` places a target replaces its survey for Eq. 1's guess and the aim.
  void use_map_poses(MapPoses poses) { map_poses_ = std::move(poses); }

  /// The target of the tour's `visit`-th stop (0-based, cycling through scene.visits): its scene index.
  int target_of(int visit) const;
  /// Drives to the `visit`-th stop, aims, and plans what to light there.
  Stop arrive(int visit);
  /// The next stop goes to scene target `target`'s instead of the tour's (an operator's "go to"); the
  /// tour goes on from there as listed. Throws SessionError for a target with no stop or not tracked.
  void visit_next(int target);
  /// The whole `visit`-th stop: arrive, give each lit target's tracker (`workers`, by scene index) its
  /// guess, footing and the colour of the stop's first frame, then hand the camera's frames to them until
  /// the dwell is over or `cancel` is requested (Ctrl-C, the window closed). Throws SessionError for a
  /// lit target without a worker, and what a device throws.
  Stop visit(int visit, const std::vector<alignment::PoseTracker*>& workers, const Dwell& dwell, StopObserver& observer,
             const std::stop_token& cancel);
  /// The targets besides the visited one that a robot with this believed head expects to share the
  /// view: each one's surveyed middle 0.3-5 m in front of the camera, inside the depth camera's image
  /// and the projector's. Nearest first.
  std::vector<LitTarget> neighbours(int visited, const robot::HeadPoses& believed) const;
  /// Eq. 1 and the surveyed footing of one target from a believed head.
  LitTarget plan(int target, const robot::HeadPoses& believed) const;
  /// Where the map says a target's middle stands (world frame): its MapPose's, else its survey's.
  Eigen::Vector3d surveyed_middle(int target) const;
  /// Where the map places a target: its MapPose, else its survey (`from` empty).
  MapPose map_pose(int target) const;

 private:
  const Target& find(int target) const;
  const config::Scene& scene_;
  std::vector<Target> targets_;
  robot::Navigator& base_;
  robot::PanTilt& pan_tilt_;
  config::Clock clock_;
  std::vector<int> visits_per_target_;  // by scene index
  int next_target_ = -1;                // visit_next's; -1: the tour's
  MapPoses map_poses_;                  // empty: the survey alone
};

}  // namespace projbot::live
