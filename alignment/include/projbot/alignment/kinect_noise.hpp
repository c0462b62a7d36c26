#pragma once
// The Kinect v1 depth error model, applied to a clean (simulated) depth image.

#include <cstdint>

#include "projbot/alignment/depth.hpp"

namespace projbot::alignment {

/// Kinect v1 axial noise coefficient: sigma_z = kKinectV1SigmaZCoeff * z^2, metres.
inline constexpr double kKinectV1SigmaZCoeff = 1.425e-3;

/// Kinect v1 / PrimeSense error sources. The defaults are the published model: axial noise after
/// Khoshelham & Elberink (2012) and Nguyen et al. (2012), sigma_z = 1.425e-3 z^2 m, per pixel; disparity
/// d = b f / z measured in 1/8 px steps, so depth comes in steps that grow with z^2; no depth on either
/// side of a discontinuity nor on surfaces seen at grazing angles.
///
/// fitted() is the model fitted to a real PrimeSense sensor (`projbot bench sensor` on YCB-Video's Asus
/// Xtion frames, 0.53-1.14 m, against the ground truth). Most of its error is smooth, not per pixel (the
/// noise of neighbouring pixels correlates 0.97, 3 px apart 0.87, 8 px apart 0.67: the correlation window
/// of the structured light) and 2.5 times the published size (that includes the ground truth's own
/// error, which the frames cannot tell from the sensor's); steps finer than 1/8 px (1.8 mm per m^2); a
/// band of about 4 px beside a foreground edge where a third to two thirds of the pixels are lost (more
/// on the right: the IR projector's shadow); the foreground bleeding a pixel outward; small holes.
struct KinectNoiseConfig {
  double sigma_z_coeff = kKinectV1SigmaZCoeff;  ///< per-pixel noise: sigma = coeff * z^2, metres (0 disables)
  double smooth_sigma_z_coeff = 0.0;            ///< smooth noise: sigma = coeff * z^2, metres (0 disables)
  double smooth_scale_px = 14.0;                ///< its grid spacing, px: independent twice as far apart
  double baseline_m = 0.075;                    ///< IR projector - IR camera baseline
  double disparity_focal_px = 580.0;            ///< focal length of the IR camera used for disparity
  double disparity_step_px = 0.125;             ///< disparity quantisation (0 disables)
  double edge_jump_m = 0.02;                    ///< a depth jump is larger than this + 2% of z
  double edge_drop = 1.0;                       ///< share of the pixels on a jump's near side that are lost
  int shadow_band_px = 1;                       ///< the band beyond a foreground edge where pixels are lost...
  double shadow_left = 1.0;                     ///< ...this share of it left of the foreground,
  double shadow_right = 1.0;                    ///< right of it (the IR projector's shadow),
  double shadow_vertical = 1.0;                 ///< above or below it
  double bleed = 0.0;                           ///< share of the pixels beside a foreground edge given its depth
  double hole_ratio = 0.0;                      ///< share of surface pixels lost in small holes
  double max_incidence_deg = 75.0;              ///< drop surfaces seen more obliquely than this
  double min_range_m = 0.5;                     ///< Kinect v1 measures 0.5 - 4.5 m
  double max_range_m = 4.5;

  /// The exact depth: no noise, nothing lost.
  static KinectNoiseConfig none() {
    KinectNoiseConfig c;
    c.sigma_z_coeff = c.smooth_sigma_z_coeff = c.disparity_step_px = 0.0;
    c.edge_jump_m = 1e9;
    c.edge_drop = c.shadow_left = c.shadow_right = c.shadow_vertical = c.bleed = c.hole_ratio = 0.0;
    c.max_incidence_deg = 90.0;
    c.min_range_m = 0.0;
    c.max_range_m = 1e9;
    return c;
  }

  /// Fitted to the real PrimeSense frames (see above; `projbot bench sensor` prints both beside them).
  static KinectNoiseConfig fitted() {
    KinectNoiseConfig c;
    c.sigma_z_coeff = 0.35e-3;
    c.smooth_sigma_z_coeff = 3.8e-3;
    c.disparity_step_px = 0.079;
    c.edge_drop = 0.6;
    c.shadow_band_px = 4;
    c.shadow_left = 0.45;
    c.shadow_right = 0.7;
    c.shadow_vertical = 0.35;
    c.bleed = 0.3;
    c.hole_ratio = 0.025;
    return c;
  }
};

/// A noisy copy of `clean` (0 = no depth), reproducible for a seed.
DepthImage apply_kinect_v1_noise(const DepthImage& clean, const CameraIntrinsics& k, const KinectNoiseConfig& cfg,
                                 std::uint32_t seed);

}  // namespace projbot::alignment
