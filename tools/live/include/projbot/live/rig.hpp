#pragma once
// What serves a session (`run`, `record`): the configured robot (a base, pan-tilt and camera together; no
// twin), a recording (`run --replay`: no device, no twin) or the digital twin (with a configured camera in
// place of its own, when one is open).

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/hardware/device_session.hpp"
#include "projbot/hardware/devices.hpp"
#include "projbot/session/replay.hpp"
#include "projbot/session/session.hpp"
#include "projbot/twin/appearance.hpp"
#include "projbot/twin/twin_session.hpp"

namespace projbot::live {

struct RigOptions {
  std::uint64_t seed = 1;  ///< the twin's drive and noise
  /// The twin's depth camera: the real sensor's fitted model (the default), or KinectNoiseConfig{} the published one.
  alignment::KinectNoiseConfig depth_model = alignment::KinectNoiseConfig::fitted();
  /// `record`: every frame tracked before the next is read, and the twin's camera gives colour with every
  /// frame (a fakenect dump holds both). A replay is always tracked in lockstep.
  bool recording = false;
  std::function<bool()> interrupted;  ///< the twin's set-up (its map survey) gives up when it says so
  config::Clock replay_clock;         ///< a replay's robot keeps time on it (ReplayClock::robot()); required with one
};

/// A robot's laser scans with the wheel odometry at each.
using ScanListener = std::function<void(const robot::LaserScan&, const robot::Pose2D& odometry)>;

class Rig {
 public:
  /// The configured robot when `devices` holds a base (open_session_devices has checked it has the pan-tilt
  /// and camera too), else `replay` when given, else the twin (with `devices.camera` when one is open).
  /// They must outlive the rig. Built on the thread that drives it (the twin renders on it). Throws
  /// std::invalid_argument for a replay without options.replay_clock.
  Rig(const config::Scene& scene, const std::vector<session::Target>& targets, hardware::Devices& devices,
      const config::Recording* replay, RigOptions options);
  ~Rig();
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  session::Session& session();
  /// Each stop's camera and how long it lasts: `dwell_s` seconds (a recording: its stop's frames).
  session::Dwell dwell(double dwell_s);
  /// The twin when it serves the session (its truth measures the display error); null otherwise.
  twin::Twin* twin();
  /// A survey of the targets' reflectance when the twin serves the camera too (its colour camera sees the
  /// twin's projector light); null otherwise: a configured camera's session drives no projector here.
  std::unique_ptr<twin::ReflectanceSurvey> reflectance_survey();
  /// When the twin serves the camera, it sees the projector's light while `shown` says it shows one colour
  /// (a reflectance measured at a stop); a configured camera sees the real projector's.
  void projector_shows(twin::TwinCamera::UniformLight shown);
  /// The visits a tour of `asked` makes: a recording plays its own stops.
  int visits(int asked) const;
  /// Each laser scan while driving and settling: the twin's, or the configured laser's; a recording has none.
  void on_scan(ScanListener listener);

 private:
  RigOptions options_;
  const config::Recording* replay_ = nullptr;
  std::unique_ptr<hardware::DeviceSession> devices_;
  std::unique_ptr<session::ReplaySession> replay_session_;
  std::unique_ptr<twin::TwinSession> twin_;
  bool twin_camera_ = false;  // the twin serves the camera too
};

}  // namespace projbot::live
