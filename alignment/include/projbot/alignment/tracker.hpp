#pragma once
// Frame-to-frame tracking at camera rate: the previous pose refined against each new depth frame by
// projective data association (model points projected into the depth image; no search tree),
// point-to-plane Gauss-Newton with a robust weight, coarse to fine over an image pyramid. Eigen only.
// Not thread-safe: one tracker per worker thread.

#include <Eigen/Core>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace projbot::alignment {

struct TrackerConfig {
  int pyramid_levels = 3;                                    ///< 640x480, 320x240, 160x120
  std::vector<int> iterations{6, 5, 4};                      ///< Gauss-Newton iterations per level, coarsest first
  std::vector<std::size_t> model_points{3000, 8000, 20000};  ///< model points used per level, coarsest first
  double max_distance_m = 0.04;                              ///< correspondences farther apart are ignored
  /// The same on the coarsest level (at least max_distance_m): there the start is pulled into the basin
  /// of a target that jumped (1 m/s from rest: 3.3 cm between 30 Hz frames that the still prediction
  /// does not know of, most of max_distance_m); the finer levels then work with max_distance_m. With
  /// 0.04 on every level, motion.yaml's box starting at 1 m/s settled part-way (63 % inliers), and the
  /// worker's second, wider pass (TargetFollower, reach_m) made that frame 12.5 ms instead of 6.6.
  double coarse_max_distance_m = 0.10;
  double huber_sigmas = 2.0;         ///< Huber threshold in sensor sigmas (1.425e-3 z^2, at least 1 mm)
  double occlusion_margin_m = 0.03;  ///< scan depth this much nearer than the model: occluded, not counted
  double inlier_distance_m = 0.01;   ///< for the quality numbers
  /// The silhouette's edges, on the finest level: a model point near the model's outline (its normal
  /// within edge_max_cos of square to the viewing ray) is moved along the outline's normal until the
  /// model's outline meets the step in the depth image from the target to what lies behind. Weight of
  /// one such point against one point-to-plane point, its pixels counted as metres at its depth; 0, the
  /// default, leaves them out (TargetFollower's acquisition uses them: WorkerConfig::polish_edge_weight).
  double edge_weight = 0.0;
  double edge_max_cos = 0.2;
  /// Only outlines that face sideways in the image (|x| of their normal there at least this): with the
  /// top of the head, the undersides of the arms and the soles too, the shop figure was held 1 mm low
  /// (bench acquire, seed 2: 0.97 mm mean, noise-free 0.9 mm; the duck's were even), a bias not traced.
  /// Sideways is the direction that depth left free.
  double edge_min_across = 0.7;
  int edge_search_px = 8;         ///< how far along the outline's normal the step is looked for, each way (1..32)
  double min_inlier_ratio = 0.6;  ///< quality gate
  double max_rmse_mm = 6.0;
  std::size_t min_correspondences = 200;
  /// A level's iterations stop once a step moves the model less than this (its origin's move plus its
  /// turn times its RMS radius): the tracked pose's own noise (bench track: 0.13 mm mean error, the
  /// same with or without this; 12.9 instead of 15 iterations per frame there, fewer on slow motion).
  double converged_step_m = 1e-4;
  /// Pull towards the start pose, relative to the depth's mean information per axis: holds the
  /// directions the depth leaves free (a box seen face-on) at the start (the motion prediction).
  double start_prior = 0.01;
  /// The same pull towards a held pose (track's T_hold), stronger: the depth of the shop's face-on box
  /// pulls 2 mm along its face (at 0.01 the held pose slid 1.6-2.0 mm away, at 0.1 0.1-0.2 mm).
  double hold_prior = 0.1;
  /// A descent whose last step still moved the surface along its normals by more than this (RMS over the
  /// correspondences) had not arrived: the twin's cube, started 7 cm and 16 degrees off after dropped
  /// frames, stopped 22 mm off along its grazing face, gate passed (last steps there 0.44-0.49 mm; on
  /// the real YCB-V frames 90 % of tracks end under 0.08 mm). It goes on from there, up to
  /// extra_descents more times, the start prior moved with it.
  double settled_shift_m = 1e-4;
  int extra_descents = 1;
};

/// One tracked frame.
struct TrackResult {
  Eigen::Matrix4d T_camera_target = Eigen::Matrix4d::Identity();
  bool accepted = false;      ///< passed the quality gate
  double inlier_ratio = 0.0;  ///< of model points that are visible, in the image and not occluded
  double rmse_mm = 0.0;       ///< point-to-plane RMS of the inliers
  std::size_t correspondences = 0;
  std::size_t edge_points = 0;  ///< model points on the outline that found the silhouette's step (last pass)
  int iterations = 0;
  double last_shift_m = 0.0;  ///< RMS move of the surface along its normals in the last step (see settled_shift_m)
  double time_ms = 0.0;       ///< including the pyramid
};

class ProjectiveTracker {
 public:
  /// Throws AlignmentError for an empty model or bad intrinsics.
  ProjectiveTracker(ModelCloud model, CameraIntrinsics intrinsics, TrackerConfig config = {});

  /// Refines T_prev (target -> camera) against `depth` (metres, 0 = missing). With T_hold, hold_prior
  /// pulls towards it instead of start_prior towards T_prev: a pose that colour placed along the directions the
  /// depth leaves free (a box seen face-on) stays there instead of sliding back to the depth's optimum.
  TrackResult track(const DepthImage& depth, const Eigen::Matrix4d& T_prev, const Eigen::Matrix4d* T_hold = nullptr) const;

  const TrackerConfig& config() const { return cfg_; }

 private:
  struct Level {
    CameraIntrinsics k;
    const float* z = nullptr;  // metres; missing where !has_depth
    std::vector<float> own;    // a coarse level's depths (the finest is the frame's own)
  };
  std::vector<Level> pyramid(const DepthImage& depth) const;
  /// The model's own depth under T per pixel, each front-facing point of the first n covering its pixel
  /// and the 8 around it (closing the gaps between samples): where the model's outline is.
  std::vector<float> outline_grid(const Eigen::Matrix4d& T, std::size_t n) const;
  /// The silhouette's pull on camera-frame model point x (normal nrm) on the finest level `lv`, added to
  /// the normal equations; false when x is not on the model's outline or no step is found near it.
  /// x0: the same point under the pose the outline was drawn at.
  bool add_edge(const Level& lv, const std::vector<float>& outline, const Eigen::Vector3d& x, const Eigen::Vector3d& x0,
                const Eigen::Vector3d& nrm, Eigen::Matrix<double, 6, 6>& H, Eigen::Matrix<double, 6, 1>& g) const;
  /// One pass over a level's first `count` model points under T: the normal equations, and the quality numbers.
  struct Pass {
    Eigen::Matrix<double, 6, 6> H = Eigen::Matrix<double, 6, 6>::Zero();  // upper triangle
    Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
    std::size_t used = 0, candidates = 0, inliers = 0, edges = 0;
    double inlier_sq = 0.0;
  };
  /// The model's outline under the start pose T, for the finest level's edges (TrackerConfig::edge_weight).
  struct Outline {
    std::vector<float> grid;
    Eigen::Matrix4d T;
  };
  /// `outline` is given on the finest level when edges are used, else null.
  Pass pass(const Level& lv, std::size_t count, const Eigen::Matrix4d& T, double reach, const Outline* outline) const;
  /// Coarse to fine from T (moved in place), pulled towards `anchor` with weight `prior`; counts its
  /// iterations into `iterations` and returns the last step's RMS move along the normals (settled_shift_m).
  double descend(const std::vector<Level>& levels, const Outline* outline, const Eigen::Matrix4d& anchor, double prior,
                 Eigen::Matrix4d& T, int& iterations) const;

  ModelCloud model_;  // shuffled once, so any prefix is a uniform subsample
  CameraIntrinsics k_;
  TrackerConfig cfg_;
  double model_radius_m_ = 0.1;  // RMS distance of the model's points from its origin
};

}  // namespace projbot::alignment
