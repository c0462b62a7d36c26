#include "projbot/bench/track.hpp"

#include <chrono>
#include <cmath>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::bench {

TrackSequence render_track_sequence(engine::Renderer& renderer, std::size_t model, const alignment::CameraIntrinsics& k,
                                    int frames, double distance, const std::function<bool()>& keep_going) {
  const config::Camera pinhole(k, 0.1, 10.0);
  auto camera = renderer.make_depth_camera(k.width_px, k.height_px);
  TrackSequence s;
  for (int f = 0; f < frames && keep_going(); ++f) {
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

TrackStats measure_tracking(const TrackSequence& sequence, const TrackStep& step, const std::function<bool()>& keep_going) {
  TrackStats s;
  Eigen::Matrix4d estimate = sequence.truth[0];
  for (std::size_t f = 1; f < sequence.truth.size() && keep_going(); ++f) {
    const auto t0 = std::chrono::steady_clock::now();
    estimate = step(static_cast<int>(f), estimate);
    s.ms.push_back(config::ms_since(t0));
    const Eigen::Matrix4d err = alignment::rigid_inverse(sequence.truth[f]) * estimate;
    s.err_mm.push_back(alignment::translation_norm_m(err) * 1000.0);
    s.err_deg.push_back(alignment::rotation_angle_deg(err));
  }
  return s;
}

}  // namespace projbot::bench
