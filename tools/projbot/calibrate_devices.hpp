#pragma once
// The configured projector and colour camera of a calibration session (`calibrate capture` and
// `calibrate photometric` on a site config).

#include <memory>
#include <string>

#include "cli.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/devices.hpp"

namespace projbot::tools {

/// The scene's devices.camera opened and read once (an absent one: an error naming it, before anything is
/// shown), and the projector's window (full screen with --fullscreen or devices.projector.fullscreen, on
/// --monitor or devices.projector.monitor), titled `title`. Members are destroyed window first.
struct CalibrationDevices {
  live::Devices devices;
  std::unique_ptr<engine::Renderer> renderer;
  std::unique_ptr<engine::RenderTarget> window;
};
CalibrationDevices open_calibration_devices(const cli::Args& args, const config::Scene& scene, const std::string& title);

/// --settle-ms (default 150, 0..5000): the wait after a pattern is presented before its image is taken.
double settle_ms_option(const cli::Args& args);

}  // namespace projbot::tools
