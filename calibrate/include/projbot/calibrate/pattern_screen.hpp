#pragma once
// `calibrate capture`'s rigs on the engine: the patterns drawn by the renderer (offscreen for the twin,
// full screen on the projector for the real devices) and the configured colour camera.

#include <array>
#include <cstdint>
#include <functional>
#include <istream>
#include <map>
#include <memory>
#include <ostream>

#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/calibrate/capture.hpp"
#include "projbot/calibrate/photometric.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::calibrate {

/// The Gray-code patterns uploaded once, each a quad that fills the projector's image texel for pixel
/// (nearest sampling, no lens: a pattern's pixels are the panel's own).
class PatternScreen {
 public:
  PatternScreen(engine::Renderer& renderer, const config::ProjectorConfig& projector);
  /// Draws pattern `index` into `target` (the projector window, or an offscreen image of its size).
  void draw(engine::RenderTarget& target, std::size_t index);
  /// Draws it offscreen and reads it back as 8-bit grey: the projector's output as the engine makes it.
  cv::Mat render(std::size_t index);
  /// The white pattern's index (gray_code_images(): the codes, then white, then black).
  std::size_t white_index() const { return models_.size() - 2; }

 private:
  engine::Renderer& renderer_;
  config::ProjectorConfig pinhole_;
  std::vector<std::size_t> models_;
  std::unique_ptr<engine::RenderTarget> offscreen_;
};

/// What the twin's rig is lit by (make_twin_rig's `display`): each pattern as `screen` draws it,
/// checked pixel for pixel against the pattern (a CalibrationError naming the pattern where they differ).
PatternDisplay engine_display(PatternScreen& screen);

/// The real rig: `screen` drawn into `window` (the projector, full screen), `camera`'s colour images
/// taken `settle_ms` plus the projector's input lag after each pattern is presented; ready() asks the
/// person at `prompt` to hold the board and press Enter on `answers` (q: finish).
std::unique_ptr<CaptureRig> make_device_rig(PatternScreen& screen, engine::Renderer& renderer, engine::RenderTarget& window,
                                            alignment::RgbdCamera& camera, double settle_ms, double input_lag_ms,
                                            std::istream& answers, std::ostream& prompt);

/// One colour over the projector's whole image (`calibrate photometric`): a quad as PatternScreen's, its
/// texture one texel of that colour, made the first time the colour is shown.
class ColourScreen {
 public:
  ColourScreen(engine::Renderer& renderer, const config::ProjectorConfig& projector);
  /// Draws `rgb` (8-bit levels) over the whole image into `target`.
  void draw(engine::RenderTarget& target, const std::array<std::uint8_t, 3>& rgb);

 private:
  engine::Renderer& renderer_;
  config::ProjectorConfig pinhole_;
  std::map<std::array<std::uint8_t, 3>, std::size_t> models_;
};

/// The real photometric rig: `screen` drawn into `window` (the projector, full screen), `camera`'s colour
/// images taken `settle_ms` plus the projector's input lag after each colour is presented, and averaged
/// over the patch the projector lights: the first measurement takes the camera under black and white and
/// keeps the pixels whose light rose by at least half as much as the most lit ones' (a CalibrationError
/// when fewer than 100 did: the projector's light is not in the camera's view). The camera's exposure is
/// not set (brackets() is false): its response is given. When `stop()` says so (Ctrl-C), the next capture
/// throws SessionStopped instead (within 50 ms of a settling wait).
std::unique_ptr<PhotometricRig> make_device_photometric_rig(ColourScreen& screen, engine::Renderer& renderer,
                                                            engine::RenderTarget& window, alignment::RgbdCamera& camera,
                                                            double settle_ms, double input_lag_ms,
                                                            std::function<bool()> stop = {});

}  // namespace projbot::calibrate
