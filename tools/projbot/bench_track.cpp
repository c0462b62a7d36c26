// projbot bench track: the projective tracker against PCL's IterativeClosestPoint on the same synthetic
// Kinect v1 frames of a moving target.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numeric>
#include <utility>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker.hpp"
#include "projbot/bench/track.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

void print_row(const char* name, const bench::TrackStats& stats) {
  const auto& ms = stats.ms;
  double mean = 0, mean_mm = 0, max_mm = 0, max_deg = 0;
  for (std::size_t i = 0; i < ms.size(); ++i) {
    mean += ms[i] / static_cast<double>(ms.size());
    mean_mm += stats.err_mm[i] / static_cast<double>(ms.size());
    max_mm = std::max(max_mm, stats.err_mm[i]);
    max_deg = std::max(max_deg, stats.err_deg[i]);
  }
  std::printf("%-26s %7.1f %8.2f %8.2f %8.2f %8.2f %9.3f %9.3f %9.3f", name, 1000.0 / mean, mean, engine::percentile(ms, 0.5),
              engine::percentile(ms, 0.95), *std::max_element(ms.begin(), ms.end()), mean_mm, max_mm, max_deg);
  if (stats.iterations_per_frame > 0.0)
    std::printf(" %6.1f\n", stats.iterations_per_frame);
  else
    std::printf(" %6s\n", "-");
}

}  // namespace

const Command kBenchTrack{
    "bench track",
    "benchmark frame-to-frame tracking against PCL's IterativeClosestPoint",
    "projbot bench track [--frames N] [--distance M]\n\n"
    "Renders N synthetic 640x480 Kinect v1 depth frames (the engine's depth camera plus the Kinect noise model)\n"
    "of the Duck (32 cm) moving up to 1 cm and 2 degrees per frame, then tracks it frame to frame with the\n"
    "projective tracker and with PCL's IterativeClosestPoint (kd-tree, point-to-point) from the same starts.\n"
    "Times include each method's preprocessing (pyramid; cloud from depth and crop). The model is 50k points.\n"
    "iters: the projective tracker's Gauss-Newton iterations per frame, all pyramid levels together.\n",
    {{"frames", "N", "frames in the sequence (default 300)"},
     {"distance", "M", "camera to target distance in metres (default 1.2)"},
     {"device", "N", "Vulkan physical device index for the depth rendering"}},
    [](const cli::Args& args) {
      const int frames = args.get_int("frames", 300, 10, 100000);
      const double distance = args.get_double("distance", 1.2);
      if (!(distance >= 0.5 && distance <= 4.0)) throw cli::UsageError("--distance must be 0.5..4 metres");
      engine::RendererOptions ro;
      ro.device_index = args.get_int("device", -1, -1, 64);
      engine::Renderer renderer(ro);
      auto duck = assets::load_gltf(asset_dir() / "models" / "Duck" / "Duck.glb");
      assets::scale_and_recenter(duck, 0.2, true);
      const std::size_t id = renderer.add_model(duck);
      const alignment::ModelCloud model = alignment::model_cloud_from(duck, 50000);
      const alignment::CameraIntrinsics k = alignment::CameraIntrinsics::kinect_v1();

      std::printf("rendering %d frames at %.1f m...\n", frames, distance);
      std::fflush(stdout);
      const auto stopped = [&](const std::string& what, int frame) {
        return benchmark_interrupted("while " + what + " (frame " + std::to_string(frame) + " of " + std::to_string(frames) +
                                     ")");
      };
      catch_interrupts();  // Ctrl-C: the methods measured are printed whole, the one under way is dropped; exit 130
      const auto keep_going = [] { return !interrupted(); };
      const bench::TrackSequence sequence = bench::render_track_sequence(renderer, id, k, frames, distance, keep_going);
      if (interrupted()) return stopped("rendering the depth sequence", static_cast<int>(sequence.truth.size()));
      const auto& depth = sequence.depth;
      std::printf("%-26s %7s %8s %8s %8s %8s %9s %9s %9s %6s\n", "method", "fps", "mean_ms", "p50_ms", "p95_ms", "max_ms",
                  "mean_mm", "max_mm", "max_deg", "iters");
      const alignment::ProjectiveTracker tracker(model, k);
      double iterations = 0.0;
      const auto tracked = [&](const alignment::ProjectiveTracker& t, int f, const Eigen::Matrix4d& prev) {
        const alignment::TrackResult r = t.track(depth[static_cast<std::size_t>(f)], prev);
        iterations += r.iterations;
        return r.T_camera_target;
      };
      bench::TrackStats ours = bench::measure_tracking(
          sequence, [&](int f, const Eigen::Matrix4d& prev) { return tracked(tracker, f, prev); }, keep_going);
      ours.iterations_per_frame = std::exchange(iterations, 0.0) / static_cast<double>(ours.ms.size());
      if (interrupted()) return stopped("measuring", static_cast<int>(ours.ms.size()) + 1);
      print_row("projective (20k of 50k)", ours);
      alignment::TrackerConfig all_points;
      all_points.model_points = {5000, 15000, 50000};
      const alignment::ProjectiveTracker tracker_all(model, k, all_points);
      bench::TrackStats ours_all = bench::measure_tracking(
          sequence, [&](int f, const Eigen::Matrix4d& prev) { return tracked(tracker_all, f, prev); }, keep_going);
      ours_all.iterations_per_frame = iterations / static_cast<double>(ours_all.ms.size());
      if (interrupted()) return stopped("measuring", static_cast<int>(ours_all.ms.size()) + 1);
      print_row("projective (all 50k)", ours_all);
      const alignment::PclIcpBaseline pcl_icp(model);
      const bench::TrackStats base = bench::measure_tracking(
          sequence,
          [&](int f, const Eigen::Matrix4d& prev) {
            return pcl_icp.track(alignment::depth_to_cloud(depth[static_cast<std::size_t>(f)], k), prev);
          },
          keep_going);
      if (interrupted()) return stopped("measuring", static_cast<int>(base.ms.size()) + 1);
      print_row("pcl IterativeClosestPoint", base);
      const auto mean = [](const std::vector<double>& v) {
        return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
      };
      std::printf("speed-up over PCL (mean time): %.1fx (20k points), %.1fx (all 50k)\n", mean(base.ms) / mean(ours.ms),
                  mean(base.ms) / mean(ours_all.ms));
      return 0;
    }};

}  // namespace projbot::tools
