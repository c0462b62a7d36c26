#pragma once
// The Kinect v1 depth error model, applied to a clean (simulated) depth image.

#include <cstdint>

#include "projbot/alignment/depth.hpp"

namespace projbot::alignment {

/// Kinect v1 axial noise coefficient: sigma_z = kKinectV1SigmaZCoeff * z^2, metres.
inline constexpr double kKinectV1SigmaZCoeff = 1.425e-3;

/// Kinect v1 / PrimeSense error sources. Axial noise after Khoshelham & Elberink (2012) and Nguyen et al.
/// (2012): sigma_z = 1.425e-3 z^2 m. The sensor measures disparity d = b f / z in 1/8 pixel steps, so depth
/// comes in steps that grow with z^2. It returns no depth near discontinuities (the projector's shadow)
/// nor on surfaces seen at grazing angles.
struct KinectNoiseConfig {
  double sigma_z_coeff = kKinectV1SigmaZCoeff;  ///< sigma_z = coeff * z^2, metres (0 disables)
  double baseline_m = 0.075;                    ///< IR projector - IR camera baseline
  double disparity_focal_px = 580.0;            ///< focal length of the IR camera used for disparity
  double disparity_step_px = 0.125;             ///< disparity quantisation (0 disables)
  double edge_jump_m = 0.02;                    ///< drop pixels next to a depth jump larger than this + 2% of z
  double max_incidence_deg = 75.0;              ///< drop surfaces seen more obliquely than this
  double min_range_m = 0.5;                     ///< Kinect v1 measures 0.5 - 4.5 m
  double max_range_m = 4.5;

  static KinectNoiseConfig none() { return {0.0, 0.075, 580.0, 0.0, 1e9, 90.0, 0.0, 1e9}; }
};

/// A noisy copy of `clean` (0 = no depth), reproducible for a seed.
DepthImage apply_kinect_v1_noise(const DepthImage& clean, const CameraIntrinsics& k, const KinectNoiseConfig& cfg,
                                 std::uint32_t seed);

}  // namespace projbot::alignment
