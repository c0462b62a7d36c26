#pragma once
// Verification that a good fit to the wrong place cannot pass: the depth the camera would measure if
// the target stood at the estimate, compared with the depth it did measure, inside the predicted
// silhouette. Measured surface behind the predicted one means free space where the model should be:
// evidence against. Measured in front is occlusion (a visitor, a pillar): neutral. Agreement supports.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/nearest_points.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/assets/image.hpp"

namespace projbot::alignment {

/// Pixel counts inside the predicted silhouette, its rim left out (edges are where depth is least sure).
struct FreeSpaceCheck {
  std::size_t predicted = 0;  ///< interior silhouette pixels with a measurement
  std::size_t behind = 0;     ///< measured farther than the model's surface by more than the tolerance
  std::size_t in_front = 0;   ///< measured nearer: occluded, neutral
  std::size_t agree = 0;      ///< measured within the tolerance of the model's surface
  /// The silhouette's outline: what the camera measures a few pixels outside it, past the band of mixed
  /// pixels, against the model's depth at the outline.
  std::size_t outline_step = 0;     ///< farther: the model's edge is a step to what lies behind
  std::size_t outline_flush = 0;    ///< within the tolerance: the surface runs on past the outline
  std::size_t outline_front = 0;    ///< nearer: an occluder beside it (neutral)
  std::size_t outline_missing = 0;  ///< nothing measured there (the IR shadow, a step's lost pixels)
  /// Share of the outline (occluded pixels left out) where the measured surface runs on flush past it:
  /// the model's edge is no edge in the depth (a pose sunk into a larger surface); 0 with no outline.
  double flush_ratio() const {
    const std::size_t n = outline_step + outline_flush + outline_missing;
    return n == 0 ? 0.0 : static_cast<double>(outline_flush) / static_cast<double>(n);
  }
  /// Share of the predicted pixels where the camera looks through the model; 0 with nothing predicted.
  double behind_ratio() const { return predicted == 0 ? 0.0 : static_cast<double>(behind) / static_cast<double>(predicted); }
  /// Share of the predicted pixels measured nearer than the model: occluded.
  double in_front_ratio() const { return predicted == 0 ? 0.0 : static_cast<double>(in_front) / static_cast<double>(predicted); }
  /// Share of the predicted pixels where the measured surface is the model's.
  double agree_ratio() const { return predicted == 0 ? 0.0 : static_cast<double>(agree) / static_cast<double>(predicted); }
  /// Fewer predicted pixels than this and the check cannot vouch for an estimate (the model is out of
  /// view, or nearly so, there).
  static constexpr std::size_t kMinPredicted = 50;
  /// Whether the estimate passes: enough of its silhouette measured, and the camera seeing through the
  /// model in at most `max_behind_ratio` of it.
  bool passes(double max_behind_ratio) const { return predicted >= kMinPredicted && behind_ratio() <= max_behind_ratio; }
};

/// The depth inside the model's silhouette at T_camera_model, grown by grow_m (the guess's
/// uncertainty) in the image and in depth; the rest set to 0 (missing). What acquisition aligns to:
/// the wall behind a target and a neighbour beside it drop out before ICP sees them. With `cluster`,
/// also each connected surface that runs on past the crop's edge and lies mostly (three quarters)
/// outside the silhouette itself: a neighbour touching the crop. (Only for a guess known to within a
/// fraction of the model's size: from a gross guess the target's own support would go with it.)
DepthImage crop_to_silhouette(const DepthImage& depth, const CameraIntrinsics& k, const ModelCloud& model,
                              const Eigen::Matrix4d& T_camera_model, double grow_m, bool cluster = false);

/// How far a guess off by translation_m and rotation_deg (about the model's origin) can put a model
/// point: the silhouette crop's growth.
double guess_reach_m(const ModelCloud& model, double translation_m, double rotation_deg);

/// The model's visible surface (samples whose normals face the camera, nearest per pixel) under
/// T_camera_model compared with `depth`. The tolerance grows with range like the Kinect v1's error:
/// 15 mm + 5 mm per square metre of depth (35 mm at 2 m). The outline's counts (outline_*) only with
/// `outline`: they cost two passes over the silhouette that tracking, which checks every frame, does not use.
FreeSpaceCheck check_free_space(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const CameraIntrinsics& k, bool outline = false);

/// A direction of rigid motion the view hardly constrains: moving the model along it changes the
/// point-to-plane distances of its visible surface least (a box seen face-on slides along its face).
struct WeakDirection {
  /// The motion as a unit 6-vector split in two: translation (camera frame, metres) and rotation (axis
  /// times angle about the visible surface's centre, radians scaled by its radius), so that both parts
  /// move surface points by comparable amounts.
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();
  /// Its eigenvalue of the point-to-plane normal equations over the largest one (0..1).
  double strength = 0.0;
  bool is_slide() const { return translation.norm() >= rotation.norm(); }
};

/// How well the model's visible surface at T_camera_model pins each direction of motion down.
struct ViewConstraints {
  std::size_t points = 0;                            ///< visible model samples used
  std::array<double, 6> strength{};                  ///< eigenvalues over the largest, ascending
  std::vector<WeakDirection> weak;                   ///< those with strength below kWeak, weakest first
  std::vector<WeakDirection> all;                    ///< every direction, weakest first
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< the seen samples' centre (camera frame, m): the rotations' pivot
  double radius = 1e-3;                              ///< their RMS distance from it (m): the rotations' scale
  static constexpr double kWeak = kWeakStrength;
};

/// The eigen-decomposition of the point-to-plane normal equations (sum of J^T J, J = [n, (q x n) / r])
/// over the model samples the camera sees at T_camera_model (front-facing, nearest per pixel). Depends
/// on the model, the pose and the camera only: what any scan of this view can and cannot fix.
ViewConstraints view_constraints(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const CameraIntrinsics& k);

/// One point-to-plane least-squares step (scan points onto planes through model points with `normals`,
/// `distances` along them) that moves only along the directions the matches pin down: the normal
/// equations about the points' centre, rotations scaled by their radius (as view_constraints), solved in
/// the span of the eigen-directions with strength at least kWeakStrength; the weak ones are left where
/// they are. Identity with fewer than 6 matches.
struct StrongStep {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();  ///< the rigid transform to apply to the points
  int held = 0;                                     ///< weak directions left where they were
};
StrongStep strong_point_to_plane_step(const std::vector<Eigen::Vector3d>& points, const std::vector<Eigen::Vector3d>& normals,
                                      const std::vector<double>& distances);

/// How well the model's colours (the projection content) agree with a colour image registered to
/// `depth` (the same pinhole, as a Kinect v1 registers RGB to depth) at T_camera_model: the correlation
/// of their luminances over the model samples the camera sees there (front-facing, nearest per pixel,
/// and not hidden: the measured depth within 2 cm of the sample), the image sampled bilinearly. In
/// -1..1; NaN when the model has no colours, the images do not match the pinhole, fewer than
/// kMinColourSamples samples are seen or either side has no contrast (a plain target says nothing).
double colour_agreement(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                        const assets::Image& colour, const CameraIntrinsics& k);
inline constexpr std::size_t kMinColourSamples = 200;
/// Whether the model's colours vary at all (colour_agreement is NaN everywhere for one that does not:
/// one plain material).
bool has_colour_contrast(const ModelCloud& model);

/// Whether the model moved by `T_model_model` looks the same as unmoved at the model points `probes`
/// (indices into model.points; empty: 300 spread over all of them): moved, they land on the model's
/// surface (as near, on average, as a probe's nearest other sample) and carry the colour found there
/// (as near as that sample's colour). With the probes a camera sees at the truth and T_model_model =
/// estimate^-1 * truth, it says whether the content an estimate puts on the seen surfaces is the
/// truth's: a textured box turned 180 degrees onto a face that shows the same texture. False for a
/// model without colour contrast (has_colour_contrast), whose content is where its shape is.
/// `samples`: an index of model.points (built here when null; a caller that asks often keeps one).
bool looks_alike(const ModelCloud& model, const Eigen::Matrix4d& T_model_model, const std::vector<std::size_t>& probes = {},
                 const NearestPoints* samples = nullptr);

/// The turns that take the model's bounding box onto itself if it were a cube: the 23 rotations of a
/// cube (90, 180 and 270 degrees about each of its axes, 180 about the diagonals of its faces, 120 and
/// 240 about its body's diagonals), about the box's centre, each as a T_model_model. The places a
/// box-like model may look like itself; looks_alike says where it does.
std::vector<Eigen::Matrix4d> box_turns(const ModelCloud& model);

/// T, or T * turn for the one of `turns` nearest `prior` in rotation, where that one puts the same
/// content on the surfaces the camera sees at T (looks_alike on visible_samples) and lies nearer the
/// prior than T by more than margin_deg. The seen faces cannot tell such poses apart, so the prior
/// does: a textured box found turned 180 degrees onto a face with the same texture, from a guess 40
/// degrees off, is turned back. A pose within (90 + margin_deg) / 2 degrees of the prior is never moved
/// (every turn is 90 degrees or more).
inline constexpr double kLookAlikeMarginDeg = 20.0;
Eigen::Matrix4d nearest_look_alike(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const Eigen::Matrix4d& prior,
                                   const std::vector<Eigen::Matrix4d>& turns, const DepthImage& depth, const CameraIntrinsics& k,
                                   double margin_deg = kLookAlikeMarginDeg, const NearestPoints* samples = nullptr);

/// The model points a camera sees with the model at T_camera_model: in its image, facing it, and within
/// 1 cm of the depth measured there; at most `max` of them, spread over the model.
std::vector<std::size_t> visible_samples(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                         const CameraIntrinsics& k, std::size_t max = 300);

/// The axis of a weak rotation (`weak` from view_constraints, a rotation rather than a slide): through
/// the point about which the weak motion is a pure turn (the axis of a mug seen with its handle hidden),
/// camera frame.
struct TurnAxis {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit
  /// The turn by angle_rad about it, as a T_camera_camera to apply on the left.
  Eigen::Matrix4d turn(double angle_rad) const;
};
TurnAxis turn_axis(const ViewConstraints& view, const WeakDirection& weak);

/// The turn about turn_axis(view, weak) that brings T_camera_model's orientation nearest `prior`'s about
/// that axis, as a T_camera_camera to apply on the left; identity for a slide.
Eigen::Matrix4d turn_towards(const ViewConstraints& view, const WeakDirection& weak, const Eigen::Matrix4d& T_camera_model,
                             const Eigen::Matrix4d& prior);

/// T, or T turned about an axis the view cannot fix towards `prior`, where the depth cannot tell the
/// two apart: the samples seen at T, so turned, still lie on the model's surface (all but 2 %, each as
/// near as twice its own neighbour's spacing plus 2 mm), and no more of the turned model is seen through
/// (check_free_space: at most 1 % of its silhouette more). Depth alone says nothing about how far a body
/// of revolution is turned about its axis (a plain mug with its handle hidden); the prior does.
/// `samples` as for looks_alike.
Eigen::Matrix4d nearest_unseen_turn(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const Eigen::Matrix4d& prior,
                                    const DepthImage& depth, const CameraIntrinsics& k, const NearestPoints* samples = nullptr);

/// A pose moved to where colour agrees best, in the plane of its two weakest slides.
struct ColourRefinement {
  Eigen::Matrix4d T_camera_model = Eigen::Matrix4d::Identity();
  double agreement_before = 0.0;                      ///< colour_agreement at the pose given (NaN: colour says nothing)
  double agreement_after = 0.0;                       ///< ...and at the result
  Eigen::Vector3d shift_m = Eigen::Vector3d::Zero();  ///< the move of the seen surface's centre, camera frame
  double turn_deg = 0.0;                              ///< the turn about its weakest rotation, degrees
  /// The coarse grid's best still lay on its rim after it had moved there twice: a better place may lie
  /// farther along (the caller may search again from the result).
  bool out_of_reach = false;
  bool moved() const { return shift_m.norm() > 0.0 || turn_deg > 0.0; }
};
/// How far colour_refined turns a pose about its weakest rotation at most (degrees).
inline constexpr double kColourTurnReachDeg = 2.0;

/// Depth pins a box seen face-on only loosely along its face: the Kinect's edges are noisy and the
/// shop's box came out 1.7-2.9 mm off sideways. Its texture does not slide. The pose is moved within
/// +-reach_m in the plane of the two weakest slides of view_constraints (their translations, made
/// orthonormal) to where colour_agreement is highest: a grid of 2 step_m, then finer ones of step_m / 2
/// and step_m / 4 around the best; then turned about the view's weakest rotation (through the seen
/// surface's centre, within kColourTurnReachDeg) and slid once more. The pose is kept when colour says
/// nothing (NaN) or no move gains at least min_gain.
ColourRefinement colour_refined(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const assets::Image& colour, const CameraIntrinsics& k, double reach_m = 0.008,
                                double step_m = 0.001, double min_gain = 0.005);

}  // namespace projbot::alignment
