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
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/alignment/tracker.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

struct Stats {
  std::vector<double> ms, err_mm, err_deg;
  double iterations = 0.0;  // Gauss-Newton iterations per frame, all levels (the projective tracker's)
  void print(const char* name) const {
    double mean = 0, mean_mm = 0, max_mm = 0, max_deg = 0;
    for (std::size_t i = 0; i < ms.size(); ++i) {
      mean += ms[i] / static_cast<double>(ms.size());
      mean_mm += err_mm[i] / static_cast<double>(ms.size());
      max_mm = std::max(max_mm, err_mm[i]);
      max_deg = std::max(max_deg, err_deg[i]);
    }
    std::printf("%-26s %7.1f %8.2f %8.2f %8.2f %8.2f %9.3f %9.3f %9.3f", name, 1000.0 / mean, mean, engine::percentile(ms, 0.5),
                engine::percentile(ms, 0.95), *std::max_element(ms.begin(), ms.end()), mean_mm, max_mm, max_deg);
    if (iterations > 0.0)
      std::printf(" %6.1f\n", iterations / static_cast<double>(ms.size()));
    else
      std::printf(" %6s\n", "-");
  }
};

// The benchmark's frames: the Duck on a smooth path (up to 1 cm and 2 degrees per frame at 30 Hz) in
// rendered Kinect v1 depth, and its true poses. Stops early (fewer frames) when interrupted.
struct Sequence {
  std::vector<Eigen::Matrix4d> truth;
  std::vector<alignment::DepthImage> depth;
};
Sequence render_sequence(engine::Renderer& renderer, std::size_t model, const alignment::CameraIntrinsics& k, int frames,
                         double distance) {
  const config::ProjectorConfig pinhole(k, 0.1, 10.0);
  auto camera = renderer.make_depth_camera(k.width_px, k.height_px);
  Sequence s;
  for (int f = 0; f < frames && !interrupted(); ++f) {
    const double t = f / 30.0;
    const Eigen::Matrix4d T =
        config::pose_from_xyz_rpy({0.12 * std::sin(2.0 * t), 0.06 * std::sin(1.3 * t), distance + 0.1 * std::sin(0.9 * t)},
                                  {180.0 + 15.0 * std::sin(1.1 * t), 20.0 * std::sin(0.8 * t), 40.0 * std::sin(1.5 * t)});
    const std::vector<engine::DrawItem> items{{model, T}};
    renderer.draw_frame(*camera, pinhole, items);
    const engine::DepthMap map = camera->read_back_depth();
    s.depth.push_back(
        alignment::apply_kinect_v1_noise({map.width, map.height, map.z_m, t}, k, {}, static_cast<std::uint32_t>(f)));
    s.truth.push_back(T);
  }
  return s;
}

// One method tracked frame to frame from the truth of frame 0: each step's time and error.
Stats measure(const Sequence& sequence, const std::function<Eigen::Matrix4d(int, const Eigen::Matrix4d&)>& step) {
  Stats s;
  Eigen::Matrix4d estimate = sequence.truth[0];
  for (std::size_t f = 1; f < sequence.truth.size() && !interrupted(); ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    estimate = step(static_cast<int>(f), estimate);
    s.ms.push_back(config::ms_since(t0));
    const Eigen::Matrix4d err = alignment::rigid_inverse(sequence.truth[f]) * estimate;
    s.err_mm.push_back(alignment::translation_norm_m(err) * 1000.0);
    s.err_deg.push_back(alignment::rotation_angle_deg(err));
  }
  return s;
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
      const Sequence sequence = render_sequence(renderer, id, k, frames, distance);
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
      Stats ours = measure(sequence, [&](int f, const Eigen::Matrix4d& prev) { return tracked(tracker, f, prev); });
      ours.iterations = std::exchange(iterations, 0.0);
      if (interrupted()) return stopped("measuring", static_cast<int>(ours.ms.size()) + 1);
      ours.print("projective (20k of 50k)");
      alignment::TrackerConfig all_points;
      all_points.model_points = {5000, 15000, 50000};
      const alignment::ProjectiveTracker tracker_all(model, k, all_points);
      Stats ours_all = measure(sequence, [&](int f, const Eigen::Matrix4d& prev) { return tracked(tracker_all, f, prev); });
      ours_all.iterations = iterations;
      if (interrupted()) return stopped("measuring", static_cast<int>(ours_all.ms.size()) + 1);
      ours_all.print("projective (all 50k)");
      const alignment::PclIcpBaseline pcl_icp(model);
      const Stats base = measure(sequence, [&](int f, const Eigen::Matrix4d& prev) {
        return pcl_icp.track(alignment::depth_to_cloud(depth[static_cast<std::size_t>(f)], k), prev);
      });
      if (interrupted()) return stopped("measuring", static_cast<int>(base.ms.size()) + 1);
      base.print("pcl IterativeClosestPoint");
      const auto mean = [](const std::vector<double>& v) {
        return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
      };
      std::printf("speed-up over PCL (mean time): %.1fx (20k points), %.1fx (all 50k)\n", mean(base.ms) / mean(ours.ms),
                  mean(base.ms) / mean(ours_all.ms));
      return 0;
    }};

}  // namespace projbot::tools
