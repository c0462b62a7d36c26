// projbot bench appearance: what a visitor sees of each target, compensation off and on (issue 43). The
// scene's tour in the twin, tracking; at each arrival, and through a scripted motion (0.1 s apart), the
// visited target's frame is drawn both ways and the spectator's picture scored against the content under
// the reference light, scaled by the target's gain.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/twin/tour.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

void print_table(const twin::TourReport& report) {
  std::printf(
      "\n| # | target | moving | k | compensation | PSNR dB | SSIM | dE2000 median / p95 | clipped %% | unreachable %% | "
      "projector saturated %% | ms per frame | PSNR still there dB |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& v : report.visits)
    for (const auto& a : v.appearance) {
      const auto& s = a.score;
      if (s.pixels == 0) {
        std::printf("| %d | %s | %s | %.2f | %s | no lit pixel of the target in view | | | | | | %.1f | |\n", v.visit,
                    v.target.c_str(), a.moving ? "yes" : "no", a.gain, a.compensation ? "on" : "off", a.ms_per_frame);
        continue;
      }
      char still[32] = "", moving[64] = "no", saturated[32] = "";
      if (std::isfinite(a.still_psnr_db)) std::snprintf(still, sizeof still, "%.1f", a.still_psnr_db);
      if (std::isfinite(a.projector_saturated_share))
        std::snprintf(saturated, sizeof saturated, "%.1f", 100.0 * a.projector_saturated_share);
      if (a.moving)
        std::snprintf(moving, sizeof moving, "%s, %d frames, worst %.1f dB", a.starting ? "starting" : "yes", a.frames,
                      a.worst_psnr_db);
      std::printf("| %d | %s | %s | %.2f | %s | %.1f | %.3f | %.1f / %.1f | %.1f | %.1f | %s | %.1f | %s |\n", v.visit,
                  v.target.c_str(), moving, a.gain, a.compensation ? "on" : "off", s.psnr_db, s.ssim, s.de2000_median,
                  s.de2000_p95, 100.0 * s.clipped_share, 100.0 * s.unreachable_share, saturated, a.ms_per_frame, still);
    }
}

// --reflectance measured or mapped: each visit's measurement (its median, for a map) beside the scene's
// surface (the twin's truth).
void print_albedo(const twin::TourReport& report, const config::Scene& scene, bool mapped) {
  for (const auto& v : report.visits) {
    if (!v.measured_albedo) continue;
    const config::TargetSurface& surface = scene.targets[static_cast<std::size_t>(scene.target_index(v.target))].surface;
    const Eigen::Vector3d &truth = surface.albedo, &m = *v.measured_albedo;
    if (mapped || !surface.texture.empty()) {  // one colour is not the print; a map is not one colour
      std::printf("visit %d %s: reflectance measured %s, median %.3f %.3f %.3f%s\n", v.visit, v.target.c_str(),
                  mapped ? "over its texture coordinates" : "as one colour", m.x(), m.y(), m.z(),
                  surface.texture.empty()
                      ? ""
                      : (" (the scene's surface: " + surface.texture.filename().string() + (mapped ? ")" : ", kept)")).c_str());
      continue;
    }
    std::printf("visit %d %s: reflectance measured %.3f %.3f %.3f, the scene's %.3f %.3f %.3f (worst channel %+.1f %%)\n",
                v.visit, v.target.c_str(), m.x(), m.y(), m.z(), truth.x(), truth.y(), truth.z(),
                100.0 * (m.cwiseQuotient(truth) - Eigen::Vector3d::Ones()).cwiseAbs().maxCoeff());
  }
}

void write_report(const std::filesystem::path& file, const twin::TourReport& report) {
  nlohmann::json out = {{"visits", nlohmann::json::array()}, {"interrupted", report.interrupted}};
  for (const auto& v : report.visits)
    for (const auto& a : v.appearance) {
      const auto& s = a.score;
      const auto number = [&](double x) {
        return s.pixels > 0 && std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
      };
      out["visits"].push_back(
          {{"visit", v.visit},
           {"target", v.target},
           {"compensation", a.compensation ? "on" : "off"},
           {"moving", a.moving},
           {"starting", a.starting},
           {"frames", a.frames},
           {"gain", a.gain},
           {"pixels", s.pixels},
           {"psnr_db", number(s.psnr_db)},
           {"ssim", number(s.ssim)},
           {"de2000_median", number(s.de2000_median)},
           {"de2000_p95", number(s.de2000_p95)},
           {"clipped_share", number(s.clipped_share)},
           {"unreachable_share", number(s.unreachable_share)},
           {"ms_per_frame", a.ms_per_frame},
           {"still_psnr_db", number(a.still_psnr_db)},
           {"worst_psnr_db", number(a.worst_psnr_db)},
           {"projector_saturated_share", number(a.projector_saturated_share)},
           {"albedo_measured", v.measured_albedo
                                   ? nlohmann::json({v.measured_albedo->x(), v.measured_albedo->y(), v.measured_albedo->z()})
                                   : nlohmann::json(nullptr)}});
    }
  config::write_file_atomically(file, out.dump(1) + "\n");
}

}  // namespace

const Command kBenchAppearance{
    "bench appearance",
    "benchmark what a visitor sees of each target, radiometric compensation off and on (the twin)",
    "projbot bench appearance [--scene S.yaml] [--visits N] [--seed K] [--dwell S] [--frames DIR]\n"
    "                         [--reflectance scene|measured|mapped] [--report FILE.json] [--depth-model fitted|kinect]\n"
    "                         [--processing-ms MS]\n\n"
    "Runs the scene's tour in the digital twin, tracking. At each arrival, and through a scripted motion\n"
    "(from its start to its end, a frame every 0.1 s), the visited target's projector frame is drawn with\n"
    "compensation off (the content as stored) and on (what makes the target's surface show it: the content\n"
    "x k / the surface's reflectance, less the room's light, through the projector's inverse response, for\n"
    "this frame's distance and incidence), and a visitor's picture of it (the twin's light: the surfaces'\n"
    "`surface:` reflectance, room.ambient_lux, the projector's brightness_lm, gammas, mixing and\n"
    "black_level) is scored over the target's lit pixels against the content under the reference light\n"
    "(1000 lux), scaled by the target's gain k (chosen at arrival so that about 2 % of the projector's\n"
    "pixels on it would need more than full white, at most 1, and followed as the target moves): PSNR and\n"
    "SSIM over all of them, CIEDE2000 over those the projector can reach (where even the best input stays\n"
    "more than 2 off, a pixel counts as unreachable; clipped: it needs more than full white). Projector\n"
    "saturated: of the target's pixels in its compensated frame (drawn alone) those at full in some channel,\n"
    "what the gain holds to about 2 %; a visitor off the projector's axis may see faces lit edge-on, so more\n"
    "of their pixels clip. ms per frame: drawing the projector's frame and reading it back on this machine.\n"
    "A moving row is the mean over the motion's frames (how many, and the worst frame's PSNR, in its moving\n"
    "column): 'starting' its first 0.2 s (the camera's frames reach the projector 50-67 ms after they are\n"
    "taken, and the prediction needs two to see the new speed), 'yes' the rest. Its last column: the same\n"
    "frames drawn at the target's true pose (tracked exactly: what they show standing still there, with the\n"
    "same k): the motion's cost is the difference; the arrival's row differs in the pose as well. Without\n"
    "--scene, assets/scenes/shop.yaml runs. With --frames, DIR/visitNN_TARGET_spectator_off.png and\n"
    "_spectator_on.png at each arrival, and for a motion the visitor's picture of its worst compensated frame\n"
    "in each part: _spectator_starting_worst.png and _spectator_moving_worst.png.\n"
    "With --reflectance measured, each target's reflectance is measured at its stop (the colour camera under\n"
    "the projector's black and mid grey, read at the estimated pose) instead of taken from the scene, and\n"
    "printed beside the scene's (the twin's truth). With --reflectance mapped, it is measured into the\n"
    "model's texture space (128 x 128 texels over its UVs, each the median of the points seen in it, refined over\n"
    "the target's visits, grown into the texels none fell in) and compensated for as a printed surface.\n"
    "Ctrl-C prints and reports the visits finished so far.\n",
    {{"scene", "FILE", "scene with a tour (default: assets/scenes/shop.yaml)", cli::PathRole::input_file},
     {"visits", "N", "visits, cycling through the scene's list (default: the list once)"},
     {"seed", "K", "seed of the drift, laser and depth noise (default 1)"},
     {"dwell", "S", "simulated seconds of projection per visit (default 3)"},
     depth_model_option(),
     processing_ms_option(),
     {"frames", "DIR", "write each visit's pictures here", cli::PathRole::output_folder},
     {"reflectance", "scene|measured|mapped",
      "each target's reflectance: the scene's surface (default), measured at its stop as one colour, or measured over "
      "its texture coordinates"},
     {"report", "FILE", "JSON report, one row per visit and compensation", cli::PathRole::output_file}},
    [](const cli::Args& args) {
      twin::TourOptions o;
      o.mode = twin::TourMode::tracking;
      o.appearance = true;
      const TourFamilyArgs family = tour_family_args(args, 3.0);
      o.visits = family.visits, o.seed = family.seed, o.dwell_s = family.dwell_s;
      o.fitted_depth = family.depth_model == "fitted";
      o.processing_ms = family.processing_ms;
      if (const auto frames = args.get("frames")) o.frames_dir = *frames;
      const std::string reflectance = args.get_or("reflectance", "scene");
      if (reflectance != "scene" && reflectance != "measured" && reflectance != "mapped")
        throw cli::UsageError("--reflectance must be scene, measured or mapped, not '" + reflectance + "'");
      o.measure_reflectance = reflectance != "scene";
      o.reflectance_map = reflectance == "mapped";
      const auto scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "shop.yaml").string()));
      check_scene_outputs(args, scene);
      catch_interrupts();
      o.stop_requested = [] { return interrupted(); };
      const int visits = o.visits > 0 ? o.visits : static_cast<int>(scene.visits.size());
      Progress progress("visit", visits);
      o.on_visit = [&](const twin::VisitReport& v) { progress.step(v.visit); };
      note_twin_on_odometry(std::cout);
      const twin::TourReport report = twin::run_tour(scene, o);
      print_table(report);
      print_albedo(report, scene, o.reflectance_map);
      std::printf("\nroom %.0f lux; projector %.0f lm, gamma %.2f, black %.4f; tour in %.1f s\n", scene.room.ambient_lux,
                  scene.projector.photometry.brightness_lm, scene.projector.photometry.gamma,
                  scene.projector.photometry.black_level, report.wall_s);
      if (const auto file = args.get("report")) write_report(*file, report);
      if (interrupted()) return benchmark_interrupted("during the tour (the visits above are those finished)");
      return 0;
    }};

}  // namespace projbot::tools
