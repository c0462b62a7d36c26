// projbot calibrate photometric: the projector's response per channel and colour mixing (issue 43), in the
// twin; the colour camera's response from exposure brackets first.

#include <cmath>
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "projbot/calibrate/calibrate.hpp"
#include "projbot/calibrate/photometric.hpp"
#include "projbot/config/scene.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

void print_against_truth(const calibrate::PhotometricResult& r, const calibrate::PhotometricSim& sim) {
  const calibrate::PhotometricDifference d = calibrate::compare(r, sim);
  std::printf(
      "against the twin's truth: gamma within %.2f %% (worst channel), mixing within %.4f (worst entry), "
      "camera gamma %.3f (truth %.3f)\n",
      100.0 * d.gamma_share, d.mixing, r.camera_gamma, sim.camera_gamma);
}

int run_photometric(const cli::Args& args) {
  if (!args.flag("sim"))
    throw cli::UsageError(
        "on a real projector and camera this session is not available yet: give --sim for the twin's (the projector's "
        "gamma and black_level then come from the scene)");
  const auto scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "shop.yaml").string()));
  calibrate::PhotometricSim sim;
  sim.projector = scene.projector;
  // The scene's projector is the truth; one without crosstalk gets a DLP's, so there is mixing to find.
  if (sim.projector.photometry.mixing.isIdentity()) sim.projector.photometry.mixing = calibrate::typical_mixing();
  sim.ambient_lux = scene.room.ambient_lux;
  sim.seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  sim.noise_levels = args.get_double("noise", 2.0);
  if (!(sim.noise_levels >= 0.0 && sim.noise_levels <= 50.0)) throw cli::UsageError("--noise must be 0..50 levels");
  sim.camera_gamma = args.get_double("camera-gamma", 2.2);
  if (!(sim.camera_gamma >= 1.0 && sim.camera_gamma <= 3.0)) throw cli::UsageError("--camera-gamma must be 1..3");
  const auto rig = calibrate::make_twin_photometric_rig(sim);
  const calibrate::PhotometricResult r = calibrate::calibrate_photometric(*rig, sim.projector.photometry.black_level);
  const auto& p = r.projector;
  std::printf("%d captures: gamma R %.3f G %.3f B %.3f; camera gamma %.3f\nmixing (column j: channel j's light in R, G, B):\n",
              r.captures, p.gamma_rgb[0], p.gamma_rgb[1], p.gamma_rgb[2], r.camera_gamma);
  for (int i = 0; i < 3; ++i) std::printf("  %.4f %.4f %.4f\n", p.mixing(i, 0), p.mixing(i, 1), p.mixing(i, 2));
  print_against_truth(r, sim);
  const std::string out = *args.get("out");
  calibrate::write_photometric(r, out, "projbot calibrate photometric --sim (the twin of " + scene.source.string() + ")");
  std::cout << "wrote " << out << '\n';
  return 0;
}

}  // namespace

const Command kCalibratePhotometric{
    "calibrate photometric",
    "the projector's response per channel and colour mixing, from its colours on a surface (the twin)",
    "projbot calibrate photometric --sim --out photo.yaml [--scene FILE] [--seed K] [--noise LEVELS] [--camera-gamma G]\n\n"
    "The projector shows uniform colours on a light surface and the colour camera measures them: white at six\n"
    "exposures for the camera's own response (value against exposure), then black, white, each primary and an\n"
    "eight-step ramp per channel. From the linearised values: each channel's gamma (its ramp's share of its\n"
    "full light, log against log) and the colour mixing (each primary's light in the camera's R, G, B as a\n"
    "share of white's). Black level and the room's light cannot be told apart with the projector on: the\n"
    "scene's black_level is kept. With --sim the twin's projector (the scene's lumens, gammas, mixing (a DLP's\n"
    "few percent of crosstalk where the scene has none) and room light) and an 8-bit camera; the result is\n"
    "compared with that truth. Paste its photometry: section into a calibration file to project with it.\n"
    "The projector and camera of a site config are not driven yet.\n",
    {{"sim", "", "the twin's projector and camera"},
     {"out", "FILE", "the photometry to write (YAML, `photometry:` as a calibration file carries it)",
      cli::PathRole::output_file},
     {"scene", "FILE", "scene giving the projector and room (default: assets/scenes/shop.yaml)", cli::PathRole::input_file},
     {"seed", "K", "seed of the camera's noise (default 1)"},
     {"noise", "LEVELS", "the twin camera's noise per pixel, levels (default 2)"},
     {"camera-gamma", "G", "the twin camera's response exponent (default 2.2)"}},
    [](const cli::Args& args) {
      if (!args.get("out")) throw cli::UsageError("--out FILE is required");
      return run_photometric(args);
    }};

}  // namespace projbot::tools
