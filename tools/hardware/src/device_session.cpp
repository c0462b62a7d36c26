#include "projbot/hardware/device_session.hpp"

namespace projbot::hardware {

DeviceSession::DeviceSession(const config::Scene& scene, const std::vector<session::Target>& targets, Devices& devices)
    : map_(devices.laser && scene.devices.laser
               ? std::optional<robot::Localizer>(robot::Localizer::load(scene.devices.laser->map))
               : std::nullopt),
      navigator_(*devices.base, {scene.robot_start.x(), scene.robot_start.y(), scene.robot_start.z()}),
      camera_(*devices.camera),
      session_(scene, targets, navigator_, *devices.pan_tilt) {
  if (devices.laser) navigator_.use_laser(*devices.laser, map_ ? &*map_ : nullptr);
}

session::Dwell DeviceSession::dwell(double dwell_s, bool lockstep) {
  session::Dwell d;
  d.camera = [this](const session::Stop&, double) -> alignment::RgbdCamera& { return camera_; };
  d.over = [dwell_s](const session::Stop&, int, double elapsed_s) { return elapsed_s >= dwell_s; };
  d.lockstep = lockstep;
  return d;
}

}  // namespace projbot::hardware
