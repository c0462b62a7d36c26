#include "projbot/live/device_rig.hpp"

namespace projbot::live {

DeviceRig::DeviceRig(const config::Scene& scene, const std::vector<Target>& targets, Devices& devices, bool lockstep)
    : map_(devices.laser && scene.devices.laser
               ? std::optional<robot::Localizer>(robot::Localizer::load(scene.devices.laser->map))
               : std::nullopt),
      navigator_(*devices.base, {scene.robot_start.x(), scene.robot_start.y(), scene.robot_start.z()}),
      camera_(*devices.camera),
      lockstep_(lockstep),
      session_(scene, targets, navigator_, *devices.pan_tilt) {
  if (devices.laser) navigator_.use_laser(*devices.laser, map_ ? &*map_ : nullptr);
}

Dwell DeviceRig::dwell(double dwell_s) {
  Dwell d;
  d.camera = [this](const Stop&, double) -> alignment::RgbdCamera& { return camera_; };
  d.over = [dwell_s](const Stop&, int, double elapsed_s) { return elapsed_s >= dwell_s; };
  d.lockstep = lockstep_;
  return d;
}

}  // namespace projbot::live
