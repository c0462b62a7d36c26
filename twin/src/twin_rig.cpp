#include "projbot/twin/twin_rig.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "projbot/live/device_rig.hpp"
#include "projbot/live/replay.hpp"
#include "projbot/twin/appearance.hpp"
#include "projbot/twin/display_error.hpp"

namespace projbot::twin {
namespace {

// The twin's truth at a stop (StopMeter), asked by scene index.
class TwinStopTruth final : public live::StopTruth {
 public:
  TwinStopTruth(Twin& twin, const config::Scene& scene)
      : meter_(twin, ProjectorModels{scene.projector, scene.projector, scene.pan_tilt.T_projector_camera},
               twin.true_head().T_world_projector.matrix()) {
    for (const config::TargetConfig& t : scene.targets) twin_index_.push_back(twin.target_index(t.name));
  }
  double error_mm(int target, int target_visit, const Eigen::Matrix4d& T_camera_target, double t_s) const override {
    if (target < 0 || static_cast<std::size_t>(target) >= twin_index_.size()) return std::nan("");
    return meter_.measure(twin_index_[static_cast<std::size_t>(target)], target_visit, T_camera_target, t_s).mean_mm;
  }

 private:
  StopMeter meter_;
  std::vector<std::size_t> twin_index_;  // by scene index
};

}  // namespace

TwinRig::TwinRig(const config::Scene& scene, const std::vector<live::Target>& targets, std::uint64_t seed,
                 alignment::RgbdCamera* configured, std::function<bool()> stop_requested, bool recording,
                 const alignment::KinectNoiseConfig& depth_model)
    : renderer_(engine::RendererOptions{}),
      twin_(
          scene,
          [&] {
            TwinOptions o;
            o.seed = seed;
            o.depth_model = depth_model;
            o.stop_requested = std::move(stop_requested);  // SIGTERM while the twin is built
            return o;
          }(),
          renderer_),
      twin_camera_(twin_, seed, recording),
      configured_(configured),
      lockstep_(recording),
      session_(scene, targets, twin_.robot(), twin_.pan_tilt()) {}

live::Dwell TwinRig::dwell(double dwell_s) {
  live::Dwell d;
  d.camera = [this](const live::Stop& stop, double since_s) -> alignment::RgbdCamera& {
    const std::size_t i = twin_.target_index(twin_.scene().targets[static_cast<std::size_t>(stop.target)].name);
    twin_camera_.at_stop(i, stop.target_visit, stop.visit, since_s);
    return configured_ ? *configured_ : twin_camera_;
  };
  d.over = [dwell_s](const live::Stop&, int, double elapsed_s) { return elapsed_s >= dwell_s; };
  d.lockstep = lockstep_;
  return d;
}

std::shared_ptr<const live::StopTruth> TwinRig::truth(const live::Stop& /*stop*/) {
  return std::make_shared<const TwinStopTruth>(twin_, twin_.scene());
}

void TwinRig::left(const live::Stop& stop) {
  twin_.end_visit(twin_.target_index(twin_.scene().targets[static_cast<std::size_t>(stop.target)].name), stop.target_visit);
}

std::unique_ptr<live::SurfaceSurvey> TwinRig::reflectance_survey() {
  if (configured_) return nullptr;
  return std::make_unique<ReflectanceSurvey>(twin_, renderer_);
}

void TwinRig::projector_shows(live::UniformLight shown) {
  if (!configured_) twin_camera_.see_projector(renderer_, std::move(shown));
}

live::OpenRig rig_opener(TwinRigOptions twin) {
  return [twin](const config::Scene& scene, const std::vector<live::Target>& targets, live::Devices& devices,
                const live::RigOptions& o) -> std::unique_ptr<live::Rig> {
    if (devices.base) return std::make_unique<live::DeviceRig>(scene, targets, devices, o.recording);
    if (o.replay) {
      if (!o.replay_clock.now_s) throw std::invalid_argument("a replay's rig needs the replay's clock");
      return std::make_unique<live::ReplayRig>(scene, *o.replay, targets, o.replay_clock);
    }
    const std::function<bool()> interrupted = o.interrupted ? o.interrupted : [] { return false; };
    return std::make_unique<TwinRig>(scene, targets, twin.seed, devices.camera.get(), interrupted, o.recording, twin.depth_model);
  };
}

}  // namespace projbot::twin
