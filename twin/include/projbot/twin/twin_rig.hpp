#pragma once
// The twin serving a projection session (`run --sim`, `record` in the twin): its robot and pan-tilt, and
// its camera unless a configured one replaces it; the truth every stop's light is measured against. And
// the one place that chooses what serves a session (rig_opener): the configured robot, a recording, or
// the twin.

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

/// The twin serving the session's robot (and camera, unless `configured`). Renders on the thread that
/// builds it, which must be the one that drives it.
class TwinRig final : public live::Rig {
 public:
  /// `stop_requested`, asked while the twin is built (its map survey), ends that with
  /// robot::SetupInterrupted. `recording`: every frame tracked in lockstep and given colour (record).
  /// `depth_model`: the twin's depth camera (TwinOptions::depth_model).
  TwinRig(const config::Scene& scene, const std::vector<live::Target>& targets, std::uint64_t seed,
          alignment::RgbdCamera* configured, std::function<bool()> stop_requested, bool recording = false,
          const alignment::KinectNoiseConfig& depth_model = alignment::KinectNoiseConfig::fitted());
  live::StopSequence& session() override { return session_; }
  /// `dwell_s` at each stop, the camera the configured one or the twin's.
  live::Dwell dwell(double dwell_s) override;
  void on_scan(live::ScanListener listener) override { twin_.robot().on_scan(std::move(listener)); }
  /// The twin as the stop begins: where each target truly is while the robot dwells.
  std::shared_ptr<const live::StopTruth> truth(const live::Stop& stop) override;
  bool knows_truth() const override { return true; }
  void left(const live::Stop& stop) override;
  /// When the twin's camera serves the session (it sees the twin's projector light); null otherwise.
  std::unique_ptr<live::SurfaceSurvey> reflectance_survey() override;
  /// The twin's camera sees the projector's light when it shows one colour (TwinCamera::see_projector).
  void projector_shows(live::UniformLight shown) override;
  /// The twin's camera renders colour with a frame while `wanted` says so (TwinCamera::colour_wanted).
  void colour_wanted(std::function<bool()> wanted) override { twin_camera_.colour_wanted(std::move(wanted)); }
  Twin& twin() { return twin_; }

 private:
  engine::Renderer renderer_;
  Twin twin_;
  TwinCamera twin_camera_;
  alignment::RgbdCamera* configured_;
  bool lockstep_;
  live::StopSequence session_;
};

/// What the twin serves with when it does: its noise's seed and its depth camera's model.
struct TwinRigOptions {
  std::uint64_t seed = 1;
  alignment::KinectNoiseConfig depth_model = alignment::KinectNoiseConfig::fitted();
};

/// What serves a session: the configured robot when the devices hold a base (open_session_devices has
/// checked it has the pan-tilt and camera too; live::DeviceRig), else the recording when options name one
/// (live::ReplayRig), else the twin (with the devices' camera in its own's place when one is open).
/// Throws std::invalid_argument for a replay without a replay clock.
live::OpenRig rig_opener(TwinRigOptions twin);

}  // namespace projbot::twin
