#pragma once
// Where a gross guess's target may be: poses near the guess scored against the depth before any ICP
// runs, so that ICP starts inside its basin. ICP from 50 mm / 15 degrees on real frames settles on the
// table or a neighbour about half the time; from 20 mm / 5 degrees it settles right nine times in ten.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace projbot::alignment {

/// The search around a guess: a grid of moves of the model (camera frame) within reach_m, spaced
/// step_m, for the guess's orientation and for turns of turn_deg either way about each camera axis
/// through the model's centre.
struct CoarseSearch {
  double reach_m = 0.05;         ///< the farthest move tried, metres (a sphere of moves)
  double step_m = 0.01;          ///< the grid's spacing, metres (> 0), widened to keep within max_moves
  double turn_deg = 12.0;        ///< the turns tried besides the guess's orientation; 0: none
  std::size_t samples = 400;     ///< model points scored per pose (spread over the model)
  std::size_t count = 3;         ///< candidates returned at most
  double separation_m = 0.02;    ///< kept candidates' centres lie at least this far apart
  std::size_t max_moves = 4000;  ///< at most about this many moves (a 30 cm reach: a 3.5 cm grid)

  /// The spacing used: step_m, or wider where reach_m would take more than max_moves of it.
  double grid_step_m() const {
    const double cells = static_cast<double>(std::max<std::size_t>(max_moves, 1)) * 3.0 / (4.0 * M_PI);
    return std::max(step_m, reach_m / std::cbrt(cells));
  }
};

/// A pose the search found, with its score: the share of the model's camera-facing samples whose
/// measured depth agrees with them, less twice the share the camera sees through (-2..1).
struct CoarseCandidate {
  Eigen::Matrix4d T_camera_model = Eigen::Matrix4d::Identity();
  double score = 0.0;
};

/// The best-scoring poses around T_guess, best first, at most search.count, their model centres
/// search.separation_m apart. A sample agrees where the measured depth at its pixel lies within step_m
/// plus the Kinect's noise (2.5 mm per square metre of range) of it; measured nearer is an occluder
/// (neutral: the table in front of a sunk pose, a neighbour); measured farther is free space where the
/// model would be. Empty when the depth does not match the intrinsics, the guess is not finite or no
/// pose scores above 0.
std::vector<CoarseCandidate> coarse_candidates(const ModelCloud& model, const Eigen::Matrix4d& T_guess, const DepthImage& depth,
                                               const CameraIntrinsics& k, const CoarseSearch& search = {});

}  // namespace projbot::alignment
