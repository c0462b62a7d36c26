// projbot bench acquire: acquisition from perturbed initial guesses in the twin (issue 11): success rate,
// false accepts, false blanks and time, ours beside PCL's own pipeline on the same captures.

#include <cstdio>
#include <mutex>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/bench/acquire.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

void print_row(const bench::AcquireTally& t, const std::string& target, const char* guesses, const char* method) {
  std::printf("| %s | %s | %s | %d | %.1f %% | %d (%d) | %d | %.0f / %.0f / %.0f |\n", target.c_str(), guesses, method, t.trials,
              t.trials > 0 ? 100.0 * t.success / t.trials : 0.0, t.false_accepts, t.look_alikes, t.false_blanks,
              engine::percentile(t.ms, 0.5), engine::percentile(t.ms, 0.95), engine::percentile(t.ms, 1.0));
}

}  // namespace

const Command kBenchAcquire{
    "bench acquire",
    "benchmark acquisition from perturbed guesses in the twin, ours beside PCL's pipeline",
    "projbot bench acquire [--scene S.yaml] [--trials N] [--guess-error CM,DEG] [--seed K]\n\n"
    "For every target of the scene the robot drives to its stop and aims (the twin), then N depth captures\n"
    "(Kinect v1 noise, a seed each) are acquired from the true pose moved by CM and turned by DEG in random\n"
    "directions, and N more from a gross guess (30 cm, 40 degrees), where the target must be re-found or\n"
    "blanked. Ours: the floor left out, the scan cropped to the guess's silhouette grown by how far its\n"
    "error reaches, projective ICP (the tracker's association, wide reach) then ICP's finest stage on the\n"
    "scan cropped again at its estimate (3 cm); when that fails the gate, ICP coarse to fine and the same\n"
    "refine, then restarts and global re-initialisation; three projective passes on the whole frame (a model\n"
    "without colours held sideways by the silhouette's left and right edges); the quality gate, the footing (upright at the "
    "surveyed height,\n"
    "from the map, not from the guess), the pose moved along its weakest slides to where the colour image\n"
    "agrees with the model's colours, turned to the look-alike pose nearest the guess where the seen faces\n"
    "show the same either way (a textured box turned 180 degrees), and the free-space check; no search\n"
    "step starts after 1.5 s of the acquiring thread's CPU time, and what is not confirmed by then is\n"
    "blanked. PCL's pipeline: crop around the guess, normals, point-to-plane ICP, lit whenever it\n"
    "converges, with PCL's own k-d tree (pcl::search::KdTree) and outlier filter; \"PCL, serial search\" is\n"
    "the same with the searches ours uses (the same answers, one query at a time without OpenMP).\n"
    "Success: lit within 3 mm and 0.5 degrees of the truth; false accept: lit more than 10 mm or 2 degrees\n"
    "off; false blank: blanked within 3 mm and 0.5 degrees. In brackets, the false accepts that look alike:\n"
    "the content they put on the surfaces the camera sees is the truth's (shape and colour: a textured box\n"
    "turned onto a face with the same texture, which neither depth nor colour can tell apart).\n"
    "Without --scene, assets/scenes/shop.yaml runs. Ctrl-C prints the rows finished.\n",
    {{"scene", "FILE", "scene with a tour (default: assets/scenes/shop.yaml)", cli::PathRole::input_file},
     {"trials", "N", "acquisitions per target and kind of guess (default 20)"},
     {"guess-error", "CM,DEG", "the guess's error (default 5,10)"},
     {"seed", "K", "seed of the guesses and the depth noise (default 1)"}},
    [](const cli::Args& args) {
      const int trials = args.get_int("trials", 20, 1, 10000);
      const auto [cm, deg] = cli::parse_distance_angle(args.get_or("guess-error", "5,10"), "guess-error", "cm", 100);
      const auto seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
      const auto scene = config::load_scene(args.get_or("scene", (asset_dir() / "scenes" / "shop.yaml").string()));
      check_scene_outputs(args, scene);
      catch_interrupts();
      engine::Renderer renderer(engine::RendererOptions{});
      bench::AcquireBench bench(scene, {trials, cm, deg, seed}, renderer);
      std::printf(
          "| target | guesses | method | trials | success | false accepts (look-alike) | false blanks | time median / p95 / max "
          "ms |\n"
          "|---|---|---|---|---|---|---|---|\n");
      std::fflush(stdout);  // the header before the first trial's seconds, also into a file or pipe
      char small[48];
      std::snprintf(small, sizeof small, "%.0f cm, %.0f deg", cm, deg);
      Progress progress("trial", static_cast<int>(bench.targets()) * trials);
      int trials_done = 0;
      const auto print_target = [&](const bench::AcquireTarget& t) {
        for (int gross : {0, 1})
          for (int j = 0; j < 3; ++j)
            print_row(t.tallies[static_cast<std::size_t>(3 * gross + j)], t.name, gross ? "30 cm, 40 deg" : small,
                      bench::kAcquireMethods[static_cast<std::size_t>(j)]);
        std::fflush(stdout);
      };
      for (std::size_t i = 0; i < bench.targets(); ++i) {
        // A trial runs PCL for seconds and cannot stop inside: it runs on a thread of its own, and a signal is
        // answered at once with the trials finished (the one under way is dropped).
        std::mutex m;
        bench::AcquireTarget finished;
        finished.name = bench.target_name(i);
        const auto t = unless_interrupted<bench::AcquireTarget>([&] {
          return bench.run_target(
              i, [] { return !interrupted(); },
              [&](const bench::AcquireTarget& so_far) {
                const std::lock_guard<std::mutex> lock(m);
                finished = so_far;
                progress.step(++trials_done);
              });
        });
        const std::lock_guard<std::mutex> lock(m);
        const bench::AcquireTarget& done = t ? *t : finished;
        if (done.trials > 0) print_target(done);  // Ctrl-C: the trials finished for this target (their count says)
        if (done.trials < trials) {
          benchmark_interrupted("at " + done.name + ", trial " + std::to_string(done.trials + 1));
          quit_now();
        }
      }
      return 0;
    }};

}  // namespace projbot::tools
