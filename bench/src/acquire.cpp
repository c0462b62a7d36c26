#include "projbot/bench/acquire.hpp"

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/clock.hpp"

namespace projbot::bench {
namespace {

// The truth moved by `cm` and turned by `deg` about its own origin, each in a random direction.
Eigen::Matrix4d perturbed(const Eigen::Matrix4d& T, double cm, double deg, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * cm / 100.0;
  Eigen::Matrix4d out = T;
  out.topLeftCorner<3, 3>() = Eigen::AngleAxisd(config::radians(deg), axis).toRotationMatrix() * T.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() += shift;
  return out;
}

// One capture's truth: the pose, and the model points the camera sees there.
struct Truth {
  const alignment::ModelCloud& model;
  Eigen::Matrix4d T;
  std::vector<std::size_t> seen;
};

AcquireOutcome judged(const Truth& truth, const Eigen::Matrix4d& T_est, bool lit, double ms) {
  const Eigen::Matrix4d d = alignment::rigid_inverse(truth.T) * T_est;
  AcquireOutcome o{lit, 1000.0 * alignment::translation_norm_m(d), alignment::rotation_angle_deg(d), ms};
  // Where the estimate puts the content of each seen point: the model point it draws there.
  if (o.far_off()) o.looks_alike = alignment::looks_alike(truth.model, alignment::rigid_inverse(d), truth.seen);
  return o;
}

// Ours, as the tour's localized mode runs it (TargetFollower::acquire: the floor left out, the silhouette
// crop grown by `grow_m`, ICP with restarts and global re-initialisation), then the quality gate and
// the free-space check.
AcquireOutcome ours(const alignment::TargetFollower& follower, const alignment::DepthImage& depth, const assets::Image& colour,
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
AcquireOutcome pcl_pipeline(const alignment::Aligner& aligner, const twin::Twin& twin, const alignment::DepthImage& depth,
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

twin::TwinOptions twin_options(std::uint64_t seed) {
  twin::TwinOptions o;
  o.seed = seed;
  return o;
}

}  // namespace

void AcquireTally::add(const AcquireOutcome& o) {
  ++trials;
  const bool close = o.error_mm <= 3.0 && o.error_deg <= 0.5;
  success += o.lit && close ? 1 : 0;
  false_accepts += o.far_off() ? 1 : 0;
  look_alikes += o.far_off() && o.looks_alike ? 1 : 0;
  false_blanks += !o.lit && close ? 1 : 0;
  ms.push_back(o.ms);
}

AcquireBench::AcquireBench(const config::Scene& scene, const AcquireOptions& options, engine::Renderer& renderer)
    : options_(options), twin_(scene, twin_options(options.seed), renderer), rng_(static_cast<std::uint32_t>(options.seed)) {}

AcquireTarget AcquireBench::run_target(std::size_t i, const std::function<bool()>& keep_going,
                                       const std::function<void(const AcquireTarget&)>& trial_done) {
  const twin::TwinTarget& target = twin_.targets()[i];
  const twin::Arrival arrival = twin_.arrive(i, static_cast<int>(i));
  const Eigen::Matrix4d T_true = alignment::rigid_inverse(arrival.truth.T_world_camera.matrix()) * target.T_world_target_true;
  // The footing is the map's (where the target was surveyed), not the perturbed guess's.
  const alignment::Footing footing =
      alignment::footing_in_camera(target.cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
  const alignment::TargetFollower follower(target.cloud, twin_.camera());
  const double cm = options_.guess_cm, deg = options_.guess_deg;
  // The crop grows by how far each kind of guess's error (known here) can reach.
  const double grow_m[2] = {alignment::guess_reach_m(target.cloud, cm / 100.0, deg),
                            alignment::guess_reach_m(target.cloud, 0.30, 40.0)};
  const alignment::Aligner pcl[2] = {alignment::Aligner(target.cloud, alignment::pcl_pipeline_config(true)),
                                     alignment::Aligner(target.cloud, alignment::pcl_pipeline_config(false))};
  AcquireTarget out;
  out.name = target.config.name;
  for (; out.trials < options_.trials && keep_going(); ++out.trials) {
    const auto noise_seed = static_cast<std::uint32_t>(options_.seed * 7919 + i * 1000 + static_cast<std::size_t>(out.trials));
    const auto depth = twin_.capture(arrival.truth.T_world_camera.matrix(), noise_seed);
    const auto colour = twin_.capture_colour(arrival.truth.T_world_camera.matrix(), noise_seed);
    const Truth truth{target.cloud, T_true, alignment::visible_samples(target.cloud, T_true, depth, twin_.camera())};
    for (const int gross : {0, 1}) {
      const Eigen::Matrix4d guess = perturbed(T_true, gross ? 30.0 : cm, gross ? 40.0 : deg, rng_);
      out.tallies[3 * gross].add(ours(follower, depth, colour, footing, guess, grow_m[gross], truth));
      for (int j = 0; j < 2; ++j) out.tallies[3 * gross + 1 + j].add(pcl_pipeline(pcl[j], twin_, depth, guess, truth));
    }
    AcquireTarget finished = out;
    ++finished.trials;
    trial_done(finished);
  }
  return out;
}

}  // namespace projbot::bench
