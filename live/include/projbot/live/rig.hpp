#pragma once
// What serves a session (`run`, `record`): a robot (base, pan-tilt and camera) with the stop sequence over
// it, and what else it offers the live engine. One interface, three implementations, each beside its
// devices: the configured robot (DeviceRig, device_rig.hpp), a recording (ReplayRig, replay.hpp) and the
// digital twin (twin::TwinRig). The live engine never knows which; `twin::rig_opener` chooses.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "projbot/assets/image.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/live/devices.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/robot/laser.hpp"

namespace projbot::live {

/// Where a target drawn at a stop truly is, when what serves the session knows (the twin): how far off
/// the light of a pose lands.
class StopTruth {
 public:
  virtual ~StopTruth() = default;
  /// The mean marker error (mm) of scene target `target` drawn at T_camera_target (the believed camera's
  /// frame), `t_s` after the stop began, on its `target_visit`-th visit (its motion script; 0: still).
  /// NaN where no marker can be measured.
  virtual double error_mm(int target, int target_visit, const Eigen::Matrix4d& T_camera_target, double t_s) const = 0;
};

/// Each target's reflectance measured under the projector's light at its estimated pose (record's survey).
class SurfaceSurvey {
 public:
  virtual ~SurfaceSurvey() = default;
  /// Measures scene target `name` at T_camera_target: the points read (0: none seen under the light).
  virtual std::size_t measure(const std::string& name, const Eigen::Matrix4d& T_camera_target) = 0;
  /// What was learnt of a target: its median reflectance (linear, 0..1 per channel) and, for a model with
  /// texture coordinates, its map (sRGB, repeating over the UVs).
  struct Learnt {
    Eigen::Vector3d albedo = Eigen::Vector3d::Zero();
    std::optional<assets::Image> map;
  };
  /// Each measured target's, by name; a target with too few points is left out.
  virtual std::map<std::string, Learnt> learnt() const = 0;
};

/// A robot's laser scans with the wheel odometry at each.
using ScanListener = std::function<void(const robot::LaserScan&, const robot::Pose2D& odometry)>;
/// One colour (8-bit levels) the projector shows over its whole image, read when asked; nullopt: the targets.
using UniformLight = std::function<std::optional<std::array<std::uint8_t, 3>>()>;

class Rig {
 public:
  virtual ~Rig() = default;
  /// The stop sequence over this robot.
  virtual StopSequence& session() = 0;
  /// Each stop's camera and how long it lasts: `dwell_s` seconds (a recording: its stop's frames).
  virtual Dwell dwell(double dwell_s) = 0;
  /// The visits a tour of `asked` makes: a recording plays its own stops.
  virtual int visits(int asked) const { return asked; }
  /// Each laser scan while driving and settling; a robot without a laser (or a recording) has none.
  virtual void on_scan(ScanListener /*listener*/) {}
  /// The truth at a stop just lit (null: none known): each frame's light is measured against it.
  virtual std::shared_ptr<const StopTruth> truth(const Stop& /*stop*/) { return nullptr; }
  /// Whether truth() answers: the display errors are then measured.
  virtual bool knows_truth() const { return false; }
  /// The dwell at a stop is over (the twin puts a moved target back home, or leaves it where it was moved).
  virtual void left(const Stop& /*stop*/) {}
  /// A survey of the targets' reflectance when this rig's camera sees its own projector's light; null otherwise.
  virtual std::unique_ptr<SurfaceSurvey> reflectance_survey() { return nullptr; }
  /// The projector shows `shown`'s colour while it says so (a reflectance measured at a stop): a
  /// simulated camera is told; a real one sees the real projector's light.
  virtual void projector_shows(UniformLight /*shown*/) {}
  /// A frame's colour is wanted while `wanted` says so (the operator's page): a simulated camera that gives
  /// colour with a stop's first frame only renders it then too; a real one gives it with every frame.
  virtual void colour_wanted(std::function<bool()> /*wanted*/) {}
};

/// How a rig runs its session.
struct RigOptions {
  /// `record`: every frame tracked before the next is read, and a simulated camera gives colour with every
  /// frame (a fakenect dump holds both). A replay is always tracked in lockstep.
  bool recording = false;
  std::function<bool()> interrupted;          ///< a long set-up (the twin's map survey) gives up when it says so
  const config::Recording* replay = nullptr;  ///< a recording serves every device (run --replay)
  config::Clock replay_clock;                 ///< a replay's robot keeps time on it (ReplayClock::robot()); required with one
};

/// Opens the rig that serves a session of `scene` over `targets` with the opened `devices` (none: no robot
/// configured). Called on the thread that drives the rig. They must outlive the rig.
using OpenRig = std::function<std::unique_ptr<Rig>(const config::Scene& scene, const std::vector<Target>& targets,
                                                   Devices& devices, const RigOptions& options)>;

}  // namespace projbot::live
