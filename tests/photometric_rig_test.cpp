// `calibrate photometric`'s rig on a projector and colour camera (issue 43): the renderer draws each
// colour over the projector's image (offscreen here, the projector's window on a site), and a camera
// behind the RgbdCamera boundary sees a wall lit by what was drawn (the projector's response, mixing and
// the room's light: the truth), its frames stamped on the host's clock, every other one an old frame of
// the colour before. The fit recovers the truth within the goals; a camera that does not see the
// light, one that saturates and a rig without exposure control given no camera gamma are refused by name.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "projbot/calibrate/calibrate.hpp"
#include "projbot/calibrate/pattern_screen.hpp"
#include "projbot/calibrate/photometric.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/renderer.hpp"

namespace {

using projbot::calibrate::CalibrationError;

// A 160 x 120 colour camera looking at a wall: its middle 80 x 60 lit by the projector (the colour
// `shown` holds at its centre pixel, through `truth`), all of it by the room; an 8-bit response
// x^(1 / gamma) with Gaussian noise. `lit` false: the projector's light falls outside its view.
class WallCamera final : public projbot::alignment::RgbdCamera {
 public:
  WallCamera(projbot::engine::RenderTarget& shown, const projbot::config::Photometry& truth, double white_lux, double ambient_lux)
      : shown_(shown), truth_(truth), white_lux_(white_lux), ambient_lux_(ambient_lux) {}
  bool lit = true;
  double gain = 0.9 / (0.8 * 320.0);  // white fills 90 % of the range
  int stale_frames = 0;               // old frames delivered (and to be dropped)

  projbot::alignment::RgbdFrame next() override {
    projbot::alignment::RgbdFrame f;
    f.depth.width = kW, f.depth.height = kH;
    f.depth.depth_m.assign(kW * kH, 1.5F);
    const bool stale = (++calls_ % 2) == 1;  // taken before the newest colour was shown: all white
    f.depth.capture_time_s = projbot::config::steady_now_s() - (stale ? 1.0 : 0.0);
    stale_frames += stale ? 1 : 0;
    const projbot::assets::Image drawn = shown_.read_back();
    const std::uint8_t* c = drawn.pixel(drawn.width / 2, drawn.height / 2);
    const Eigen::Vector3d input(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    const Eigen::Vector3d projected =
        lit ? Eigen::Vector3d(white_lux_ * projbot::engine::light(truth_, input)) : Eigen::Vector3d::Zero();
    f.colour.width = kW, f.colour.height = kH;
    f.colour.rgba.assign(kW * kH * 4, 255);
    std::normal_distribution<double> noise(0.0, 1.5);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const bool patch = x >= 40 && x < 120 && y >= 30 && y < 90;
        for (int ch = 0; ch < 3; ++ch) {
          const double lux = ambient_lux_ + (patch ? projected[ch] : 0.0);
          const double v = 255.0 * std::pow(std::min(gain * 0.8 * lux, 1.0), 1.0 / 2.2) + noise(rng_);
          f.colour.pixel(x, y)[ch] = stale ? 255 : static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L));
        }
      }
    return f;
  }

 private:
  static constexpr int kW = 160, kH = 120;
  projbot::engine::RenderTarget& shown_;
  projbot::config::Photometry truth_;
  double white_lux_, ambient_lux_;
  int calls_ = 0;
  std::mt19937_64 rng_{5};
};

struct Bench {
  Bench() {
    projector.width_px = 64, projector.height_px = 40;
    projector.fx_px = projector.fy_px = 70.0;
    projector.cx_px = 31.5, projector.cy_px = 19.5;
    truth.gamma_rgb = {2.0, 2.3, 2.5};
    truth.mixing = projbot::calibrate::typical_mixing();
    truth.black_level = 0.002;
  }
  projbot::config::ProjectorConfig projector;
  projbot::config::Photometry truth;
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
};

}  // namespace

TEST(PhotometricRig, RecoversTheProjectorsResponseFromWhatTheRendererDrew) {
  Bench b;
  auto window = b.renderer.make_offscreen(b.projector.width_px, b.projector.height_px);
  WallCamera camera(*window, b.truth, 300.0, 20.0);
  projbot::calibrate::ColourScreen screen(b.renderer, b.projector);
  const auto rig = projbot::calibrate::make_device_photometric_rig(screen, b.renderer, *window, camera, 0.0, 0.0);
  EXPECT_FALSE(rig->brackets());
  try {
    projbot::calibrate::calibrate_photometric(*rig, b.truth.black_level);
    ADD_FAILURE() << "a camera without exposure control was fitted without its response";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot set its exposure"), std::string::npos) << e.what();
  }
  const auto r = projbot::calibrate::calibrate_photometric(*rig, b.truth.black_level, {.gamma = 2.2});
  for (std::size_t j = 0; j < 3; ++j)
    EXPECT_NEAR(r.projector.gamma_rgb[j], b.truth.gamma_rgb[j], 0.02 * b.truth.gamma_rgb[j]) << j;
  EXPECT_LT((r.projector.mixing - b.truth.mixing).cwiseAbs().maxCoeff(), 0.02) << r.projector.mixing;
  EXPECT_EQ(r.camera_response, projbot::calibrate::CameraResponse::given);
  EXPECT_EQ(r.captures, 2 + 3 * 8);
  EXPECT_GE(camera.stale_frames, r.captures);  // each capture met an old frame first, and dropped it
  // Its response measured from the same session instead: the colours adding up (a grey ramp more).
  const auto m = projbot::calibrate::calibrate_photometric(*rig, b.truth.black_level, {.from_colours = true});
  EXPECT_EQ(m.camera_response, projbot::calibrate::CameraResponse::colours_adding_up);
  EXPECT_NEAR(m.camera_gamma, 2.2, 0.02 * 2.2);
  for (std::size_t j = 0; j < 3; ++j)
    EXPECT_NEAR(m.projector.gamma_rgb[j], b.truth.gamma_rgb[j], 0.02 * b.truth.gamma_rgb[j]) << j;
  EXPECT_LT((m.projector.mixing - b.truth.mixing).cwiseAbs().maxCoeff(), 0.02) << m.projector.mixing;
  EXPECT_EQ(m.captures, 2 + 3 * 8 + 7);
}

TEST(PhotometricRig, RefusesACameraThatDoesNotSeeTheLightOrSaturates) {
  Bench b;
  auto window = b.renderer.make_offscreen(b.projector.width_px, b.projector.height_px);
  projbot::calibrate::ColourScreen screen(b.renderer, b.projector);
  const auto expect_refused = [&](WallCamera& camera, const std::string& why) {
    const auto rig = projbot::calibrate::make_device_photometric_rig(screen, b.renderer, *window, camera, 0.0, 0.0);
    try {
      projbot::calibrate::calibrate_photometric(*rig, b.truth.black_level, {.gamma = 2.2});
      ADD_FAILURE() << "fitted: " << why;
    } catch (const CalibrationError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  WallCamera dark(*window, b.truth, 300.0, 20.0);
  dark.lit = false;
  expect_refused(dark, "the projector's light is not in the camera's view: under its white 0 pixels");
  WallCamera bright(*window, b.truth, 300.0, 20.0);
  bright.gain *= 3.0;
  expect_refused(bright, "the camera saturates under input 255 255 255");
}

// Ctrl-C during a session (stop() true from the fifth capture on): SessionStopped, before the next image is
// taken, and no result.
TEST(PhotometricRig, StopsAtTheNextCaptureWhenAsked) {
  Bench b;
  auto window = b.renderer.make_offscreen(b.projector.width_px, b.projector.height_px);
  WallCamera camera(*window, b.truth, 300.0, 20.0);
  projbot::calibrate::ColourScreen screen(b.renderer, b.projector);
  int asked = 0;
  const auto rig = projbot::calibrate::make_device_photometric_rig(screen, b.renderer, *window, camera, 120.0, 0.0,
                                                                   [&asked] { return ++asked > 8; });
  try {
    projbot::calibrate::calibrate_photometric(*rig, b.truth.black_level, {.gamma = 2.2});
    ADD_FAILURE() << "a stopped session was fitted";
  } catch (const projbot::calibrate::SessionStopped& e) {
    EXPECT_NE(std::string(e.what()).find("while measuring the projector's colours"), std::string::npos) << e.what();
  }
  EXPECT_GE(asked, 9);
  EXPECT_LE(camera.stale_frames, 12);  // a few captures' frames taken, not the session's 26
}
