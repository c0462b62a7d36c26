#pragma once
// Acquisition: the target's pose from an initial guess, by ICP of its model against a captured cloud,
// with a quality gate and a global re-initialisation (FPFH + SampleConsensusPrerejective) when the
// gate fails. Not thread-safe: one Aligner per thread.

#include <Eigen/Core>
#include <chrono>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/assets/model.hpp"

namespace projbot::alignment {

/// The target model as points with normals in the model frame, metres.
struct ModelCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;  ///< unit; estimated from the points when a file has none
  /// RGB 0..1 per point, as the model's texture shows it (the projection content); empty when the model
  /// has none (a PCD / PLY cloud).
  std::vector<Eigen::Vector3f> colours;
  std::string source;  ///< the file it came from, for messages; empty when built in memory
};

/// The mean of the model's points (its centre for bounds and searches); the origin for an empty model.
Eigen::Vector3d centroid_of(const ModelCloud& model);

/// Model points: area-uniform surface samples of a mesh (glTF, OBJ, STL, a PLY with faces), or the points
/// of a cloud (PCD, a PLY without faces; normals estimated). `scale` multiplies the file's units into
/// metres (0.001 for a model in millimetres, as BOP's); the origin stays the file's.
ModelCloud load_model_cloud(const std::filesystem::path& path, std::size_t samples = 50000, double scale = 1.0);

/// Model points from a loaded (scaled, recentred) model: area-uniform surface samples, reproducible.
ModelCloud model_cloud_from(const assets::Model& model, std::size_t samples = 50000);

/// How the map says a target stands, in a camera's frame: upright on the floor or on a support, its
/// model's `up_model` axis along the floor's normal and its lowest point height_m above the floor (0 for a
/// figure on the floor). From the surveyed pose (footing_in_camera), not from Eq. 1's guess: the guess
/// carries the localisation's error, the height of a table does not.
struct Footing {
  Plane floor;
  Eigen::Vector3d up_model = Eigen::Vector3d::UnitZ();
  double height_m = 0.0;
  /// Whether up_model is known (a survey). A support found in the frame itself (support_in_frame) says
  /// only that the target rests on it: its lowest point at height_m, any way up.
  bool upright_known = true;
};

/// The footing of `model` surveyed at T_world_target, seen by a camera at T_world_camera (the floor is
/// z = 0 in the world). Throws AlignmentError for an empty model or a non-finite pose.
Footing footing_in_camera(const ModelCloud& model, const Eigen::Matrix4d& T_world_target, const Eigen::Matrix4d& T_world_camera);

/// Where there is no map: the surface the target rests on, found in the depth around the guess (a table
/// under objects, the floor under a figure), as a Footing whose height is 0 and whose upright is unknown.
/// PCL's RANSAC plane fit (SACSegmentation) on the frame's points within `reach_m` + 10 cm of the model's
/// sphere at the guess; a plane is taken only if the model's centre at the guess lies on its camera side and the
/// model's lowest point at the guess is within reach_m of it (the target rests on it: not one of its own
/// faces, nor a wall behind it), and it holds at least 300 points. Nothing when no such plane is found.
std::optional<Footing> support_in_frame(const ModelCloud& model, const DepthImage& depth, const CameraIntrinsics& k,
                                        const Eigen::Matrix4d& T_camera_guess, double reach_m);

/// Defaults suit a Kinect-class camera 0.5-3 m from a 10-50 cm object.
struct AcquisitionConfig {
  bool crop = true;  ///< keep scan points near the expected target only
  /// ICP works on the scan inside the model's bounding box under the current estimate, grown by this for
  /// the first stage (the initial guess may be off by as much) and by the correspondence distance after.
  double crop_margin_m = 0.10;
  double voxel_m = 0.004;  ///< voxel grid leaf for scan and model...
  /// ...grown for a scan until at most about this many points remain: a 1.45 m figure at 2 m is 31000
  /// points at 4 mm, and an ICP on them took 6 s here. Time then no longer grows with the target's size.
  std::size_t max_scan_points = 5000;
  int outlier_neighbours = 16;  ///< statistical outlier removal: neighbours considered
  double outlier_stddev = 2.5;  ///< ... and the distance threshold in standard deviations
  int normal_neighbours = 16;   ///< scan normals from this many nearest neighbours
  /// ICP stages, coarse to fine: correspondence distances, metres. The last one must not cut into the
  /// sensor's noise: at 3 sigma or more (Kinect v1 at 2 m: sigma 5.7 mm plus 11 mm disparity steps) it
  /// keeps the error distribution whole; a 6 mm cut left a 0.69 degree bias at 2 m, 20 mm 0.27 degrees.
  std::vector<double> icp_distances_m{0.08, 0.03, 0.02};
  int icp_iterations = 40;  ///< per stage
  /// Whether PCL's own convergence flag (its iterations ended by a small step, not by their count) must
  /// also hold. False: the result alone decides, through the quality gate (a right pose started at the
  /// truth ended with 0 iterations, refused). True: a plain PCL user's pipeline (bench baselines).
  bool icp_flag_decides = false;
  /// A coarse stage only has to bring the estimate within the next one's reach: it stops once an
  /// iteration moves the model less than this share of its correspondence distance (0.4 mm at 8 cm).
  /// The last stage runs until a step is under fine_step_m. (With every stage run to 0.01 mm, the first
  /// crept on for all its 40 iterations on the shop's duck and figure, a third of their acquisition.)
  double coarse_step_ratio = 0.005;
  /// The last stage's: at 0.01 mm, half of the shop figure's acquisitions crept on for all 40
  /// iterations (370 ms instead of 170 ms, bench acquire), for nothing the projective polish after it
  /// does not settle.
  double fine_step_m = 5e-5;
  /// ...or after this many iterations: the duck's first stage, a vase inside its 8 cm reach, went on
  /// swinging by more than that for all 40, and the finer stages then took 2-4.
  int coarse_iterations = 20;
  /// Point-to-plane against the model's normals (ours); false: point-to-point (SVD), as plain ICP does.
  bool point_to_plane = true;
  /// ICP correspondences farther apart than this many times their median are rejected (0: none): a
  /// neighbour touching the target (a banana leaning on a wood block, a box on top of it) lies within
  /// the correspondence distance and pulled the estimate 10-15 mm off on real frames; the target's own
  /// points near a close estimate are much nearer than that. On the YCB-V frames from 20 mm / 5 deg the
  /// wood block went from none to 75 % within 10 mm with it, the banana from 5 to 25 %.
  double icp_median_factor = 3.0;
  /// ICP correspondences whose scan and model normals differ by more than this are rejected (180: none).
  double max_normal_angle_deg = 60.0;
  double inlier_distance_m = 0.006;  ///< a scan point within this of the model counts as explained...
  /// ...or within inlier_sigmas of the sensor's depth noise at its range, sigma(z) = depth_sigma_coeff z^2,
  /// when that is more (the RMS limit grows by the same factor). Kinect v1: 1.425e-3 z^2 axial noise and
  /// disparity steps of z^2 / 348 m (uniform, 1/sqrt(12) of a step) make 1.65e-3 z^2: 6.6 mm at 2 m,
  /// where a fixed 6 mm explained 58-60 % of the shop's standing figure at estimates that put the light
  /// within 2.7-3.6 mm, and the gate blanked it on every visit. 0: fixed distance (a cloud of unknown frame).
  double depth_sigma_coeff = 1.65e-3;
  double inlier_sigmas = 2.0;
  /// Quality gate: share of cropped scan points explained. Correct poses of an uncluttered target
  /// score 0.8-1.0 on Kinect-class data; a duck turned 30 degrees wrong still scored 0.53.
  double min_inlier_ratio = 0.7;
  double max_rmse_mm = 4.0;  ///< quality gate: RMS distance of the inliers
  /// The scan was seen from its frame's origin (a depth camera's cloud): a scan point the model does not
  /// explain is left out of the inlier ratio where it says nothing about the pose: in front of the model
  /// along its ray (an occluder: a neighbour leaning on the target, a box on top of it), or where its ray
  /// misses the model and it lies farther than the model beside it (what stands behind the outline).
  /// Seen through the model, or beside it at its depth, it counts against. On the real YCB-V frames
  /// the wood block, half hidden by a banana and a box, scored 0.62-0.68 at its ground truth (refused
  /// at every pose), the banana leaning on it 0.53. False: a cloud of unknown frame, every point judged.
  bool scan_from_origin = true;
  /// ...but at most this share of the cropped points may be neutral: a model pushed behind a surface it
  /// cannot be seen through would otherwise be judged on its few remaining points.
  double max_neutral_ratio = 0.5;
  /// When the gate fails: ICP again from the guess turned by +-this about each axis (0: never)...
  double restart_angle_deg = 25.0;
  bool reinitialise = true;            ///< ...then FPFH + SampleConsensusPrerejective over a wide region (false: never global)
  double reinit_crop_margin_m = 0.35;  ///< re-initialisation searches model radius + this around the guess
  double feature_radius_m = 0.03;      ///< FPFH support radius
  /// SearchStage::global_wide searches model radius + this around the guess: most of a room-scale view.
  double wide_crop_margin_m = 1.0;
  /// Global searches use at most this many scan points (a coarser voxel grid beyond), which bounds an
  /// attempt's time: FPFH and RANSAC grow with the points.
  std::size_t max_global_points = 6000;
  int ransac_iterations = 20000;
  /// A bounded stage (not `full`) starts no further restart or RANSAC round after this many ms; the ICP
  /// already running finishes, so an attempt ends within about this plus one ICP (about 0.5 s here).
  double attempt_budget_ms = 500.0;
  std::size_t min_points = 30;  ///< fewer valid scan points than this is an error
  /// Search with PCL's own k-d tree and outlier filter (pcl::search::KdTree, StatisticalOutlierRemoval)
  /// instead of the same searches one query at a time without OpenMP (same answers; 3-7 times faster
  /// here): for `projbot bench acquire`'s stock-PCL comparison and the test that they agree.
  bool pcl_search = false;
  /// With a Footing, an estimate passes only if the target stands as surveyed: its lowest point within
  /// this of the surveyed height, and its up axis within footing_tilt_deg of the floor's normal. A box
  /// seen face-on slid 3.3 cm up its own face, or fitted into the front edge of its table 30 cm lower,
  /// or turned 90 degrees about a horizontal axis onto another face (a cube's symmetry), explains the
  /// depth as well as the truth (bench acquire, gross guesses); none of them stands as surveyed.
  double footing_height_m = 0.02;
  double footing_tilt_deg = 5.0;
  /// With a support found in the frame (Footing::upright_known false), the target rests on it: its
  /// lowest point may lie up to footing_height_m below the plane but at most this above it. At the
  /// ground truth of the real YCB-V frames it lay 1-11 mm below the fitted plane, never above; the mug,
  /// lifted 15 mm and tilted 16 degrees by its neighbours, fitted at 0.99 inliers.
  double support_float_m = 0.006;
};

/// The benchmarks' baseline, PCL's pipeline as a PCL user runs it with Aligner::align(SearchStage::icp_only):
/// crop, voxel grid, outlier filter, normals, point-to-plane ICP, no restarts, no global search, and no
/// gate: `converged` is PCL's own flag. `pcl_search`: PCL's k-d tree and outlier filter (what a PCL user
/// gets); false: the serial searches ours uses (the same answers).
AcquisitionConfig pcl_pipeline_config(bool pcl_search);

/// One estimate with the numbers the quality gate judged it by.
struct AlignmentResult {
  Eigen::Matrix4d T_scan_model = Eigen::Matrix4d::Identity();  ///< maps model points into the scan frame
  bool converged = false;                                      ///< ICP converged and the quality gate passed
  /// Share of the cropped scan points within inlier_distance_m of the model, of those judged (the neutral
  /// ones left out: AcquisitionConfig::scan_from_origin).
  double inlier_ratio = 0.0;
  /// Share of the cropped scan points that say nothing about the pose: in front of the model (occluders),
  /// or beyond its outline and farther than it (what stands behind and beside it).
  double neutral_ratio = 0.0;
  double rmse_mm = 0.0;          ///< RMS point-to-model distance of those inliers, millimetres
  double tolerance_scale = 1.0;  ///< mean inlier tolerance at the points' ranges over inlier_distance_m (>= 1)
  int iterations = 0;            ///< ICP iterations, all stages and attempts
  double time_ms = 0.0;          ///< wall time of align()
  bool reinitialised = false;    ///< the global re-initialisation produced this result
  std::size_t scan_points = 0;   ///< scan points after cropping and filtering
  /// With a Footing: how far the estimate's lowest point is from the surveyed height (mm, signed: up is
  /// positive) and how far its up axis is tilted from the floor's normal (degrees); both 0 without one.
  double footing_height_error_mm = 0.0;
  double footing_tilt_deg = 0.0;
  bool stands = true;  ///< within the footing's tolerances (or no footing given); `converged` includes it
  /// With a colour image (TargetFollower::acquire): how far colour moved the pose along its weakest
  /// slides (mm), and the colour agreement after (NaN: colour said nothing, the pose was kept).
  double colour_shift_mm = 0.0;
  double colour_agreement = std::numeric_limits<double>::quiet_NaN();
  /// ICP's last stage held weak directions where they started (Aligner::align's hold_weak: its last
  /// step left at least one out; TargetFollower's acquisition with a colour image): colour places them.
  bool weak_held = false;
};

/// A direction of motion whose point-to-plane strength (its eigenvalue over the largest, the rotations
/// scaled by the seen surface's radius) is below this is weak: the scan hardly pins it down (a box
/// seen face-on, along its face).
inline constexpr double kWeakStrength = 0.02;

/// Which part of the acquisition align() runs. `full` is one acquisition as `projbot align` and the
/// localized tour do it; the tracker worker runs the others one at a time, each bounded, escalating.
enum class SearchStage {
  full,         ///< ICP from the guess, the local restarts, then the global search near the guess
  refine,       ///< ICP from the guess only (a track lost on this frame)
  icp_only,     ///< ICP from the guess only, not bounded: the first pass of a whole acquisition
  finish,       ///< only ICP's last (finest) stage, from an estimate that converged (on a tighter crop)
  local,        ///< ICP from the guess and from the guess turned +-restart_angle_deg about each axis
  global_near,  ///< FPFH + SampleConsensusPrerejective within model radius + reinit_crop_margin_m, then ICP
  global_wide,  ///< the same within model radius + wide_crop_margin_m
};

/// The calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), as a std::chrono clock: what an
/// acquisition's budget is counted in, so that a busy machine (a test run beside others, the renderer
/// on the same cores) slows an acquisition down without cutting it short where an idle one finishes.
struct ThreadCpuClock {
  using duration = std::chrono::nanoseconds;
  using rep = duration::rep;
  using period = duration::period;
  using time_point = std::chrono::time_point<ThreadCpuClock>;
  static constexpr bool is_steady = true;
  static time_point now() noexcept;
  /// Whether `deadline` is set and this thread's CPU time has passed it.
  static bool past(const std::optional<time_point>& deadline) { return deadline && now() > *deadline; }
};

class Aligner {
 public:
  /// Prepares the model (downsampling, search structures). Throws AlignmentError for an empty model.
  Aligner(ModelCloud model, AcquisitionConfig config = {});
  ~Aligner();
  Aligner(Aligner&&) noexcept;
  Aligner& operator=(Aligner&&) noexcept;

  /// Refines T_init (model -> scan frame) against the scan. With `footing` (in the scan's frame), only
  /// an estimate that stands as surveyed passes, and restarts go on past one that does not. Throws
  /// AlignmentError when the scan has fewer than min_points valid points (after cropping) or T_init is
  /// not finite. With `hold_weak`, ICP's last (finest) stage moves the estimate only along the directions
  /// its correspondences pin down (strong_point_to_plane_step): the weak ones stay where the coarser
  /// stages left them, for colour to place (the finest stage crept along a face-on box's face for all
  /// its iterations, 300-500 ms, to no better place).
  /// With a `deadline` (the caller's whole budget: one acquisition's, on the calling thread's CPU
  /// clock), no ICP stage after the first, restart or RANSAC round starts after it either, whatever the
  /// stage, and a global search keeps to max_global_points.
  /// With `close_guess` (T_init known to within half the model's size), the gate counts for nothing the
  /// scan points beside the model's outline more than two inlier tolerances from its seen surface: a
  /// neighbour the target touches, where a shifted estimate's own surface could not be.
  AlignmentResult align(const PointCloud& scan, const Eigen::Matrix4d& T_init, SearchStage stage = SearchStage::full,
                        const std::optional<Footing>& footing = std::nullopt, bool hold_weak = false,
                        std::optional<ThreadCpuClock::time_point> deadline = std::nullopt, bool close_guess = false) const;

  /// The quality-gate numbers of a given pose, without refining it (converged: the gate passes).
  AlignmentResult score(const PointCloud& scan, const Eigen::Matrix4d& T_scan_model,
                        const std::optional<Footing>& footing = std::nullopt, bool close_guess = false) const;

  const AcquisitionConfig& config() const;
  /// How often the model's FPFH features were computed: once per Aligner, at its first global search.
  int model_feature_computations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The baseline the tracker is measured against: PCL's IterativeClosestPoint (point-to-point, kd-tree) in
/// its best set-up for tracking: the scan's points near the guess, voxel-downsampled, as source; the
/// model (voxel-downsampled) as target, its search tree built once. Frame-to-frame use, as a tracker.
class PclIcpBaseline {
 public:
  PclIcpBaseline(const ModelCloud& model, double voxel_m = 0.004, int iterations = 30, double max_distance_m = 0.04);
  ~PclIcpBaseline();
  PclIcpBaseline(PclIcpBaseline&&) noexcept;
  PclIcpBaseline& operator=(PclIcpBaseline&&) noexcept;
  /// T_scan_model refined from T_init; the scan is cropped to the model's radius + 10 cm around T_init.
  Eigen::Matrix4d track(const PointCloud& scan, const Eigen::Matrix4d& T_init) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::alignment
