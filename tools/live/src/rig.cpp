#include "projbot/live/rig.hpp"

#include <stdexcept>

namespace projbot::live {

Rig::Rig(const config::Scene& scene, const std::vector<session::Target>& targets, hardware::Devices& devices,
         const config::Recording* replay, RigOptions options)
    : options_(std::move(options)), replay_(replay) {
  if (!options_.interrupted) options_.interrupted = [] { return false; };
  if (devices.base)
    devices_ = std::make_unique<hardware::DeviceSession>(scene, targets, devices);
  else if (replay) {
    if (!options_.replay_clock.now_s) throw std::invalid_argument("a replay's rig needs the replay's clock");
    replay_session_ = std::make_unique<session::ReplaySession>(scene, *replay, targets, options_.replay_clock);
  } else {
    twin_ = std::make_unique<twin::TwinSession>(scene, targets, options_.seed, devices.camera.get(), options_.interrupted,
                                                options_.recording, options_.depth_model);
    twin_camera_ = devices.camera == nullptr;
  }
}

Rig::~Rig() = default;

session::Session& Rig::session() {
  if (devices_) return devices_->session();
  if (replay_session_) return replay_session_->session();
  return twin_->session();
}

session::Dwell Rig::dwell(double dwell_s) {
  if (devices_) return devices_->dwell(dwell_s, options_.recording);
  if (replay_session_) return replay_session_->dwell();
  return twin_->dwell(dwell_s, options_.recording);
}

twin::Twin* Rig::twin() { return twin_ ? &twin_->twin() : nullptr; }

std::unique_ptr<twin::ReflectanceSurvey> Rig::reflectance_survey() {
  if (!twin_ || !twin_camera_) return nullptr;
  return std::make_unique<twin::ReflectanceSurvey>(twin_->twin(), twin_->renderer());
}

void Rig::projector_shows(twin::TwinCamera::UniformLight shown) {
  if (twin_ && twin_camera_) twin_->see_projector(std::move(shown));
}

int Rig::visits(int asked) const { return replay_ ? static_cast<int>(replay_->stops.size()) : asked; }

void Rig::on_scan(ScanListener listener) {
  if (devices_) devices_->navigator().on_scan(std::move(listener));
  if (twin_) twin_->twin().robot().on_scan(std::move(listener));
}

}  // namespace projbot::live
