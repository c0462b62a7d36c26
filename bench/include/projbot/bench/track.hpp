#pragma once
// Frame-to-frame tracking (`projbot bench track`): the Duck on a smooth path in rendered Kinect v1 depth,
// tracked from the truth of its first frame by the projective tracker and by PCL's IterativeClosestPoint.

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::bench {

/// One method over a sequence: per frame its time (ms, preprocessing included) and its error against the
/// truth (mm, degrees); the projective tracker's Gauss-Newton iterations per frame, all levels (0: none).
struct TrackStats {
  std::vector<double> ms, err_mm, err_deg;
  double iterations_per_frame = 0.0;
};

/// The benchmark's frames: model `model` (uploaded) on a smooth path up to 1 cm and 2 degrees per frame at
/// 30 Hz, about `distance` metres away, in rendered Kinect v1 depth (seeded per frame), and its true poses.
struct TrackSequence {
  std::vector<Eigen::Matrix4d> truth;
  std::vector<alignment::DepthImage> depth;
};
/// Fewer frames when `keep_going` says no.
TrackSequence render_track_sequence(engine::Renderer& renderer, std::size_t model, const alignment::CameraIntrinsics& k,
                                    int frames, double distance, const std::function<bool()>& keep_going);

/// A method's step: frame `f`'s estimate from the previous one.
using TrackStep = std::function<Eigen::Matrix4d(int f, const Eigen::Matrix4d& previous)>;
/// Runs `step` over the sequence from the truth of frame 0 (stopping where `keep_going` says no).
TrackStats measure_tracking(const TrackSequence& sequence, const TrackStep& step, const std::function<bool()>& keep_going);

}  // namespace projbot::bench
