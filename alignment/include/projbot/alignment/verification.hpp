#pragma once
// Verification that a good fit to the wrong place cannot pass: the depth the camera would measure if
// the target stood at the estimate, compared with the depth it did measure, inside the predicted
// silhouette. Measured surface behind the predicted one means free space where the model should be:
// evidence against. Measured in front is occlusion (a visitor, a pillar): neutral. Agreement supports.

#include <Eigen/Core>
#include <cstddef>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace projbot::alignment {

/// Pixel counts inside the predicted silhouette, its rim left out (edges are where depth is least sure).
struct FreeSpaceCheck {
  std::size_t predicted = 0;  ///< interior silhouette pixels with a measurement
  std::size_t behind = 0;     ///< measured farther than the model's surface by more than the tolerance
  std::size_t in_front = 0;   ///< measured nearer: occluded, neutral
  /// Share of the predicted pixels where the camera looks through the model; 0 with nothing predicted.
  double behind_ratio() const { return predicted == 0 ? 0.0 : static_cast<double>(behind) / static_cast<double>(predicted); }
  /// Fewer predicted pixels than this and the check cannot vouch for an estimate (the model is out of
  /// view, or nearly so, there).
  static constexpr std::size_t kMinPredicted = 50;
  /// Whether the estimate passes: enough of its silhouette measured, and the camera seeing through the
  /// model in at most `max_behind_ratio` of it.
  bool passes(double max_behind_ratio) const { return predicted >= kMinPredicted && behind_ratio() <= max_behind_ratio; }
};

/// The depth inside the model's silhouette at T_camera_model, grown by grow_m (the guess's
/// uncertainty) in the image and in depth; the rest set to 0 (missing). What acquisition aligns to:
/// the wall behind a target and a neighbour beside it drop out before ICP sees them.
DepthImage crop_to_silhouette(const DepthImage& depth, const CameraIntrinsics& k, const ModelCloud& model,
                              const Eigen::Matrix4d& T_camera_model, double grow_m);

/// How far a guess off by translation_m and rotation_deg (about the model's origin) can put a model
/// point: the silhouette crop's growth.
double guess_reach_m(const ModelCloud& model, double translation_m, double rotation_deg);

/// The model's visible surface (samples whose normals face the camera, nearest per pixel) under
/// T_camera_model compared with `depth`. The tolerance grows with range like the Kinect v1's error:
/// 15 mm + 5 mm per square metre of depth (35 mm at 2 m).
FreeSpaceCheck check_free_space(const ModelCloud& model, const Eigen::Matrix4d& T_camera_model, const DepthImage& depth,
                                const CameraIntrinsics& k);

}  // namespace projbot::alignment
