// projbot bench motion: the scene's scripted motions tracked in the twin with motion prediction off and
// on, in one run, side by side (issue 14). Errors are those of each projector frame at its display time.

#include <cmath>
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/twin/tour.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

std::string cell(double v, int decimals = 1) {
  if (std::isnan(v)) return "-";
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", decimals, v);
  return s;
}

void print_side_by_side(const twin::TourReport& off, const twin::TourReport& on) {
  std::printf(
      "\n| # | target | motion | while moving mean / p95 / worst mm, off | on | blank frames while moving, off / on | "
      "lost, lit again after s, off / on | still mean mm, off / on | lit > 10 / > 20 mm off, off / on | "
      "pose age at display p50 / p95 ms (on) |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  const auto moving = [](const twin::VisitReport& v) {
    return v.moved ? cell(v.moving_mean_mm) + " / " + cell(v.moving_p95_mm) + " / " + cell(v.max_mm_moving) : std::string("-");
  };
  const auto recovery = [](const twin::VisitReport& v) {
    return v.recovery_s == 0.0 ? std::string("-") : v.recovery_s < 0.0 ? std::string("never") : cell(v.recovery_s, 2);
  };
  const auto far = [](const twin::VisitReport& v) {
    return std::to_string(v.far_off.over_10mm) + " / " + std::to_string(v.far_off.over_20mm);
  };
  // After Ctrl-C in the first run, its finished visits are printed with the second run's cells "-".
  for (std::size_t i = 0; i < off.visits.size(); ++i) {
    const auto& a = off.visits[i];
    const bool ran = i < on.visits.size();
    const auto& b = ran ? on.visits[i] : a;
    const auto second = [ran](const std::string& text) { return ran ? text : std::string("-"); };
    std::printf("| %d | %s | %s | %s | %s | %d / %s | %s / %s | %s / %s | %s, %s | %s / %s |\n", a.visit, a.target.c_str(),
                a.moved ? "moved" : "still", moving(a).c_str(), second(moving(b)).c_str(), a.moving_blank_frames,
                second(std::to_string(b.moving_blank_frames)).c_str(), recovery(a).c_str(), second(recovery(b)).c_str(),
                cell(a.still_mean_mm, 2).c_str(), second(cell(b.still_mean_mm, 2)).c_str(), far(a).c_str(),
                second(far(b)).c_str(), second(cell(b.age_p50_ms, 0)).c_str(), second(cell(b.age_p95_ms, 0)).c_str());
  }
}

}  // namespace

const Command kBenchMotion{
    "bench motion",
    "benchmark tracking of moving targets with motion prediction off and on (the twin)",
    "projbot bench motion [--scene S.yaml] [--visits N] [--seed K] [--dwell S] [--process-noise Q]\n"
    "                     [--processing-ms MS] [--depth-model fitted|kinect]\n\n"
    "Runs the scene's tour twice in the digital twin in tracking mode, the same seed and motions each time:\n"
    "first drawing the newest measured pose, then the pose predicted for each projector frame's display time\n"
    "(a constant-velocity filter per target; the tracker also starts from it). The camera runs at 30 Hz,\n"
    "the projector at the scene's refresh_hz; a pose is ready after this machine's capture and tracking time\n"
    "(or, with --processing-ms, a fixed time after its capture: figures that do not depend on the load),\n"
    "and a frame is displayed one refresh after it starts, plus the projector's input_lag_ms. Each projector\n"
    "frame's error is measured at the markers against the target's true pose at its display time. Without\n"
    "--scene, assets/scenes/motion.yaml runs (still, 0.5 m/s with 90 deg/s, 1 m/s, accelerating starts up\n"
    "to 1 m/s with 180 deg/s, sudden stops, a target carried away). Markers the projector lights edge-on\n"
    "are not measured. Ctrl-C prints the visits finished so far.\n",
    {{"scene", "FILE", "scene with scripted motions (default: assets/scenes/motion.yaml)", cli::PathRole::input_file},
     {"visits", "N", "visits, cycling through the scene's list (default: the list once)"},
     {"seed", "K", "seed of the drift, laser and depth noise (default 1)"},
     {"dwell", "S", "simulated seconds of projection per visit (default 3)"},
     depth_model_option(),
     {"process-noise", "Q", "the motion filter's acceleration noise, m s^-1.5 (turning: 3 Q rad s^-1.5; default 0.2)"},
     processing_ms_option()},
    [](const cli::Args& args) {
      twin::TourOptions o;
      o.mode = twin::TourMode::tracking;
      const TourFamilyArgs family = tour_family_args(args, 3.0);
      o.visits = family.visits, o.seed = family.seed, o.dwell_s = family.dwell_s;
      o.fitted_depth = family.depth_model == "fitted";
      const double q = args.get_double("process-noise", alignment::MotionModelConfig{}.accel_noise);
      if (!(q > 0.0 && q <= 100.0)) throw cli::UsageError("--process-noise must be in (0, 100]");
      o.motion.accel_noise = q;
      o.motion.angular_accel_noise = 3.0 * q;
      o.processing_ms = family.processing_ms;
      const auto scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "motion.yaml").string()));
      check_scene_outputs(args, scene);
      catch_interrupts();
      o.stop_requested = [] { return interrupted(); };
      twin::TourReport runs[2];
      const int visits = o.visits > 0 ? o.visits : static_cast<int>(scene.visits.size());
      Progress progress("visit", 2 * visits);
      note_twin_on_odometry(std::cout);
      for (const bool predict : {false, true}) {
        o.predict = predict;
        std::cout << "prediction " << (predict ? "on" : "off") << ": " << std::flush;
        o.on_visit = [&](const twin::VisitReport& v) {
          std::cout << v.visit << ' ' << std::flush;
          progress.step((predict ? visits : 0) + v.visit);
        };
        runs[predict ? 1 : 0] = twin::run_tour(scene, o);
        std::cout << "visits done in " << cell(runs[predict ? 1 : 0].wall_s) << " s" << std::endl;
        if (runs[predict ? 1 : 0].interrupted) break;
      }
      print_side_by_side(runs[0], runs[1]);
      const auto& p = scene.projector;
      std::printf("\nprojector %.0f Hz, input lag %.0f ms; camera 30 Hz, %s depth model; seed %llu", p.refresh_hz, p.input_lag_ms,
                  family.depth_model.c_str(), static_cast<unsigned long long>(o.seed));
      if (o.processing_ms)
        std::printf("; a pose ready %.1f ms after its capture (fixed)\n", *o.processing_ms);
      else
        std::printf("; a pose ready after this machine's capture and tracking time\n");
      if (interrupted())
        return benchmark_interrupted(
            "during the tours (the visits above are those finished; '-' where the run with "
            "prediction did not reach them)");
      return 0;
    }};

}  // namespace projbot::tools
