// projbot bench acquire: acquisition from perturbed initial guesses in the twin (issue 11): success rate,
// false accepts, false blanks and time, ours beside PCL's own pipeline on the same captures.

#include <Eigen/Geometry>
#include <cstdio>
#include <random>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/twin/world.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

// One acquisition: lit or blanked, how far its pose is from the truth, how long it took.
struct Outcome {
  bool lit = false;
  double error_mm = 0.0, error_deg = 0.0, ms = 0.0;
  bool looks_alike = false;  ///< lit far off, and the content it puts on the seen surfaces is the truth's
  /// Lit more than 10 mm or 2 degrees off: a false accept (a cube turned onto another face too).
  bool far_off() const { return lit && (error_mm > 10.0 || error_deg > 2.0); }
};

struct Tally {
  int trials = 0, success = 0, false_accepts = 0, false_blanks = 0, look_alikes = 0;
  std::vector<double> ms;
  void add(const Outcome& o) {
    ++trials;
    const bool close = o.error_mm <= 3.0 && o.error_deg <= 0.5;
    success += o.lit && close ? 1 : 0;
    false_accepts += o.far_off() ? 1 : 0;
    look_alikes += o.far_off() && o.looks_alike ? 1 : 0;
    false_blanks += !o.lit && close ? 1 : 0;
    ms.push_back(o.ms);
  }
  void print(const std::string& target, const char* guesses, const char* method) const {
    std::printf("| %s | %s | %s | %d | %.1f %% | %d (%d) | %d | %.0f / %.0f / %.0f |\n", target.c_str(), guesses, method, trials,
                trials > 0 ? 100.0 * success / trials : 0.0, false_accepts, look_alikes, false_blanks,
                engine::percentile(ms, 0.5), engine::percentile(ms, 0.95), engine::percentile(ms, 1.0));
  }
};

// The truth moved by `cm` and turned by `deg` about its own origin, each in a random direction.
Eigen::Matrix4d perturbed(const Eigen::Matrix4d& T, double cm, double deg, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * cm / 100.0;
  Eigen::Matrix4d out = T;
  out.topLeftCorner<3, 3>() = Eigen::AngleAxisd(deg * M_PI / 180.0, axis).toRotationMatrix() * T.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() += shift;
  return out;
}

// One capture's truth: the pose, and the model points the camera sees there.
struct Truth {
  const alignment::ModelCloud& model;
  Eigen::Matrix4d T;
  std::vector<std::size_t> seen;
};

Outcome judged(const Truth& truth, const Eigen::Matrix4d& T_est, bool lit, double ms) {
  const Eigen::Matrix4d d = alignment::rigid_inverse(truth.T) * T_est;
  Outcome o{lit, 1000.0 * alignment::translation_norm_m(d), alignment::rotation_angle_deg(d), ms};
  // Where the estimate puts the content of each seen point: the model point it draws there.
  if (o.far_off()) o.looks_alike = alignment::looks_alike(truth.model, alignment::rigid_inverse(d), truth.seen);
  return o;
}

// Ours, as the tour's localized mode runs it (TargetFollower::acquire: the floor left out, the silhouette
// crop grown by `grow_m`, ICP with restarts and global re-initialisation), then the quality gate and
// the free-space check.
Outcome ours(const alignment::TargetFollower& follower, const alignment::DepthImage& depth, const assets::Image& colour,
             const alignment::Footing& footing, const Eigen::Matrix4d& guess, double grow_m, const Truth& truth) {
  const auto t0 = std::chrono::steady_clock::now();
  alignment::AlignmentResult r;
  try {
    r = follower.acquire(depth, guess, footing, grow_m, &colour);
  } catch (const alignment::AlignmentError&) {  // too little left to align: blank
  }
  const bool lit = r.converged && follower.passes(follower.verify(depth, r.T_scan_model));
  return judged(truth, r.T_scan_model, lit, config::ms_since(t0));
}

// PCL's own pipeline: crop around the guess, normals, point-to-plane ICP; lit whenever ICP converges.
Outcome pcl_pipeline(const alignment::Aligner& aligner, const twin::Twin& twin, const alignment::DepthImage& depth,
                     const Eigen::Matrix4d& guess, const Truth& truth) {
  const auto t0 = std::chrono::steady_clock::now();
  alignment::AlignmentResult r;
  try {
    // icp_only: ICP from the guess, run to its end (refine would stop it after 500 ms, at the machine's load).
    r = aligner.align(alignment::depth_to_cloud(depth, twin.camera()), guess, alignment::SearchStage::icp_only);
  } catch (const alignment::AlignmentError&) {
  }
  return judged(truth, r.T_scan_model, r.converged, config::ms_since(t0));
}

const char* const kMethods[3] = {"ours", "PCL", "PCL, serial search"};

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
      catch_interrupts();
      engine::Renderer renderer(engine::RendererOptions{});
      twin::TwinOptions to;
      to.seed = seed;
      twin::Twin twin(scene, to, renderer);
      std::mt19937 rng(static_cast<std::uint32_t>(seed));
      std::printf(
          "| target | guesses | method | trials | success | false accepts (look-alike) | false blanks | time median / p95 / max "
          "ms |\n"
          "|---|---|---|---|---|---|---|---|\n");
      char small[48];
      std::snprintf(small, sizeof small, "%.0f cm, %.0f deg", cm, deg);
      Progress progress("trial", static_cast<int>(twin.targets().size()) * trials);
      int trials_done = 0;
      for (std::size_t i = 0; i < twin.targets().size(); ++i) {
        const twin::TwinTarget& target = twin.targets()[i];
        const twin::Arrival arrival = twin.arrive(i, static_cast<int>(i));
        const Eigen::Matrix4d T_true =
            alignment::rigid_inverse(arrival.truth.T_world_camera.matrix()) * target.T_world_target_true;
        // The footing is the map's (where the target was surveyed), not the perturbed guess's.
        const alignment::Footing footing =
            alignment::footing_in_camera(target.cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
        const alignment::TargetFollower follower(target.cloud, twin.camera());
        // The crop grows by how far each kind of guess's error (known here) can reach.
        const double grow_m[2] = {alignment::guess_reach_m(target.cloud, cm / 100.0, deg),
                                  alignment::guess_reach_m(target.cloud, 0.30, 40.0)};
        const alignment::Aligner pcl[2] = {alignment::Aligner(target.cloud, alignment::pcl_pipeline_config(true)),
                                           alignment::Aligner(target.cloud, alignment::pcl_pipeline_config(false))};
        Tally tallies[6];  // ours, PCL, PCL with our searches: small guesses; the same for gross guesses
        int k = 0;
        for (; k < trials && !interrupted(); ++k) {
          const auto noise_seed = static_cast<std::uint32_t>(seed * 7919 + i * 1000 + k);
          const auto depth = twin.capture(arrival.truth.T_world_camera.matrix(), noise_seed);
          const auto colour = twin.capture_colour(arrival.truth.T_world_camera.matrix(), noise_seed);
          const Truth truth{target.cloud, T_true, alignment::visible_samples(target.cloud, T_true, depth, twin.camera())};
          for (const int gross : {0, 1}) {
            const Eigen::Matrix4d guess = perturbed(T_true, gross ? 30.0 : cm, gross ? 40.0 : deg, rng);
            tallies[3 * gross].add(ours(follower, depth, colour, footing, guess, grow_m[gross], truth));
            for (int j = 0; j < 2; ++j) tallies[3 * gross + 1 + j].add(pcl_pipeline(pcl[j], twin, depth, guess, truth));
          }
          progress.step(++trials_done);
        }
        if (k > 0) {  // Ctrl-C: the trials finished for this target are printed too (their count says how many)
          for (int gross : {0, 1})
            for (int j = 0; j < 3; ++j)
              tallies[3 * gross + j].print(target.config.name, gross ? "30 cm, 40 deg" : small, kMethods[j]);
          std::fflush(stdout);
        }
        if (k < trials) return benchmark_interrupted("at " + target.config.name + ", trial " + std::to_string(k + 1));
      }
      return 0;
    }};

}  // namespace projbot::tools
