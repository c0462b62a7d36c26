// projbot calibrate photometric: the projector's response per channel and colour mixing (issue 43), on a
// site's projector and colour camera or in the twin (there the camera's response from exposure brackets
// first, unless measured from the colours adding up).

#include <cmath>
#include <cstdio>
#include <iostream>

#include "calibrate_devices.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/calibrate/calibrate.hpp"
#include "projbot/calibrate/pattern_screen.hpp"
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

void print_result(const calibrate::PhotometricResult& r) {
  const auto& p = r.projector;
  std::printf(
      "%d captures: gamma R %.3f G %.3f B %.3f; camera gamma %.3f (%s)\nmixing (column j: channel j's light in R, G, B):\n",
      r.captures, p.gamma_rgb[0], p.gamma_rgb[1], p.gamma_rgb[2], r.camera_gamma, calibrate::to_string(r.camera_response));
  for (int i = 0; i < 3; ++i) std::printf("  %.4f %.4f %.4f\n", p.mixing(i, 0), p.mixing(i, 1), p.mixing(i, 2));
  std::printf("ramps against their fitted curves: %.2f %% of full light RMS (worst channel)\n", 100.0 * r.ramp_residual);
}

// --camera-response colours; nothing else is a way this command has.
bool from_colours(const cli::Args& args) {
  const auto response = args.get("camera-response");
  if (response && *response != "colours")
    throw cli::UsageError("--camera-response can only be 'colours' (from the projector's colours adding up), not '" + *response +
                          "'");
  return response.has_value();
}

double camera_gamma_option(const cli::Args& args) {
  const double g = args.get_double("camera-gamma", 2.2);
  if (!(g >= 1.0 && g <= 3.0)) throw cli::UsageError("--camera-gamma must be 1..3");
  return g;
}

int photometric_in_twin(const cli::Args& args, const std::string& out) {
  const auto scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "shop.yaml").string()));
  check_scene_outputs(args, scene);
  calibrate::PhotometricSim sim;
  sim.projector = scene.projector;
  // The scene's projector is the truth; one without crosstalk gets a DLP's, so there is mixing to find.
  if (sim.projector.photometry.mixing.isIdentity()) sim.projector.photometry.mixing = calibrate::typical_mixing();
  sim.ambient_lux = scene.room.ambient_lux;
  sim.seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  sim.noise_levels = args.get_double("noise", 2.0);
  if (!(sim.noise_levels >= 0.0 && sim.noise_levels <= 50.0)) throw cli::UsageError("--noise must be 0..50 levels");
  sim.camera_gamma = camera_gamma_option(args);
  const auto rig = calibrate::make_twin_photometric_rig(sim);
  const calibrate::PhotometricResult r =
      calibrate::calibrate_photometric(*rig, sim.projector.photometry.black_level, {.from_colours = from_colours(args)});
  print_result(r);
  print_against_truth(r, sim);
  calibrate::write_photometric(r, out, "projbot calibrate photometric --sim (the twin of " + scene.source.string() + ")");
  std::cout << "wrote " << out << '\n';
  return 0;
}

// The session on the config's projector (its window) and colour camera.
int photometric_on_devices(const cli::Args& args, const std::string& out) {
  const std::string path = *args.get("config");
  const config::Scene scene = config::load_scene(path);
  check_scene_outputs(args, scene);
  if (!scene.devices.camera)
    throw cli::UsageError(path +
                          " configures no camera (devices.camera): the session needs the projector and a colour camera; "
                          "--sim runs it in the twin");
  const bool measured = from_colours(args);
  const double camera_gamma = measured ? 0.0 : camera_gamma_option(args), settle_ms = settle_ms_option(args);
  CalibrationDevices d = open_calibration_devices(args, scene, "projbot calibrate photometric");
  const alignment::ExposureHold hold = d.devices.camera->hold_colour_exposure();
  if (hold.held)
    std::cout << "camera: " << hold.detail << '\n';
  else
    std::cout << "camera: its exposure is not held (" << hold.detail
              << "): switch its automatic exposure and white balance off yourself, or the values follow them\n";
  calibrate::ColourScreen screen(*d.renderer, scene.projector);
  catch_interrupts();  // Ctrl-C: stops at the next capture; nothing is written (the fit needs them all)
  const auto rig = calibrate::make_device_photometric_rig(screen, *d.renderer, *d.window, *d.devices.camera, settle_ms,
                                                          scene.projector.input_lag_ms, interrupted);
  if (measured)
    std::printf(
        "the projector shows black, white, its primaries, their ramps and a grey ramp, %.0f ms each; the camera's response "
        "is measured from the colours adding up\n",
        settle_ms + scene.projector.input_lag_ms);
  else
    std::printf(
        "the projector shows black, white, its primaries and their ramps, %.0f ms each; the camera's response is taken as "
        "gamma %.2f (--camera-gamma: its exposure time cannot be bracketed to measure it)\n",
        settle_ms + scene.projector.input_lag_ms, camera_gamma);
  std::fflush(stdout);
  calibrate::PhotometricResult r;
  try {
    r = calibrate::calibrate_photometric(*rig, scene.projector.photometry.black_level,
                                         {.gamma = camera_gamma, .from_colours = measured});
  } catch (const calibrate::SessionStopped& e) {
    return nothing_written(e.what());
  }
  print_result(r);
  calibrate::write_photometric(r, out, "projbot calibrate photometric on the camera and projector of " + path);
  std::cout << "wrote " << out << " (paste its photometry: section into the calibration file the scene names)\n";
  return 0;
}

int run_photometric(const cli::Args& args) {
  const auto out = args.get("out");
  if (!out) throw cli::UsageError("--out FILE is required");
  const bool sim = args.flag("sim");
  if (sim && args.get("config")) throw cli::UsageError("--sim and --config: give one (the twin's devices, or the config's)");
  if (!sim && !args.get("config"))
    throw cli::UsageError("give --config site.yaml (its devices.camera and devices.projector) or --sim for the twin's");
  if (!sim && from_colours(args) && args.get("camera-gamma"))
    throw cli::UsageError("--camera-gamma and --camera-response colours: give the camera's gamma or have it measured, not both");
  for (const char* twin_only : {"scene", "seed", "noise"})
    if (!sim && args.flag(twin_only))
      throw cli::UsageError(std::string("--") + twin_only + " is the twin's (--sim); a site's devices come with --config");
  for (const char* site_only : {"settle-ms", "fullscreen", "monitor", "present-mode"})
    if (sim && args.flag(site_only))
      throw cli::UsageError(std::string("--") + site_only + " is for the projector window of --config, not --sim");
  return sim ? photometric_in_twin(args, *out) : photometric_on_devices(args, *out);
}

}  // namespace

const Command kCalibratePhotometric{
    "calibrate photometric",
    "the projector's response per channel and colour mixing, from its colours on a surface",
    "projbot calibrate photometric --config site.yaml --out photo.yaml [--camera-gamma G | --camera-response colours]\n"
    "                              [--settle-ms MS]\n"
    "       projbot calibrate photometric --sim --out photo.yaml [--scene FILE] [--seed K] [--noise LEVELS]\n"
    "                              [--camera-gamma G] [--camera-response colours]\n\n"
    "The projector shows uniform colours on a light surface and the colour camera measures them: black, white,\n"
    "each primary and an eight-step ramp per channel (each step the nearest 8-bit level). From the linearised\n"
    "values: each channel's gamma (its ramp's share of its full light, log against log) and the colour mixing\n"
    "(each primary's light in the camera's R, G, B as a share of white's). Black level and the room's light\n"
    "cannot be told apart with the projector on: the scene's black_level is kept.\n\n"
    "With --config, the config's devices.projector (a window, full screen with --fullscreen or its\n"
    "`fullscreen: true`) and devices.camera: aim the projector at a light, matt, even surface (a white wall)\n"
    "that fills part of the camera's view and keep the room's light steady. The camera's automatic exposure\n"
    "and white balance are switched off where its driver lets projbot (it says which); otherwise switch them\n"
    "off yourself. Each colour is shown for --settle-ms plus the projector's input lag before the camera's\n"
    "image is taken; the values are averaged over the pixels the projector's white lights. projbot cannot set\n"
    "the cameras' exposure time to bracket it, so the camera's response is taken as --camera-gamma (2.2, an\n"
    "sRGB camera's, unless told), or with --camera-response colours measured from the same session: a grey\n"
    "ramp is shown too, and the camera's gamma is the one under which grey's light is the sum of the\n"
    "primaries' at the same input. That holds for a projector whose light adds up (LCD, LCoS, three-chip DLP,\n"
    "a colour wheel without a white segment: often a DLP's sRGB mode); a white segment adding a few percent\n"
    "to white passes unseen and biases the camera's gamma (in the twin 2 % of white: 8 %, 10 %: 28 %), 30 %\n"
    "is refused, as is a projector whose primaries the camera sees each in one channel only.\n"
    "Ctrl-C stops at the next capture and writes nothing (exit 130).\n\n"
    "With --sim, the twin's projector (the scene's lumens, gammas, mixing (a DLP's few percent of crosstalk\n"
    "where the scene has none) and room light) and an 8-bit camera whose response (--camera-gamma, its truth)\n"
    "is measured first, from white at six exposures, or with --camera-response colours as above; the result\n"
    "is compared with that truth.\n\n"
    "Paste the written photometry: section into the calibration file a scene names (`calibration:`) to\n"
    "project with it.\n",
    {{"config", "FILE", "site config with devices.camera and devices.projector", cli::PathRole::input_file},
     {"sim", "", "the twin's projector and camera"},
     {"out", "FILE", "the photometry to write (YAML, `photometry:` as a calibration file carries it)",
      cli::PathRole::output_file},
     {"camera-gamma", "G", "the camera's response exponent: --config, taken as given; --sim, the twin's truth (default 2.2)"},
     {"camera-response", "colours",
      "measure the camera's response from the projector's colours adding up (a projector whose light adds up: see above)"},
     {"settle-ms", "MS",
      "--config: wait after a colour is presented before taking the image (default 150; plus projector.input_lag_ms)"},
     {"fullscreen", "", "--config: full screen on the projector (the config's devices.projector says so too)"},
     {"monitor", "N", "--config: the projector's monitor index (default: devices.projector.monitor)"},
     {"present-mode", "MODE", "--config: fifo (default), mailbox or immediate"},
     {"scene", "FILE", "--sim: scene giving the projector and room (default: assets/scenes/shop.yaml)",
      cli::PathRole::input_file},
     {"seed", "K", "--sim: seed of the camera's noise (default 1)"},
     {"noise", "LEVELS", "--sim: the twin camera's noise per pixel, levels (default 2)"}},
    run_photometric};

}  // namespace projbot::tools
