#pragma once
// Eq. 3 of the paper, x = A_p (R_p X_m + X_p), as the projector pass computes it, and its CPU twin.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "projbot/config/scene.hpp"

namespace projbot::engine {

/// Vulkan clip coordinates from projector-frame coordinates (OpenCV pinhole, x right, y down, z forward).
/// After the divide by w = Z and the viewport transform onto a width x height target, a point lands at
/// framebuffer coordinate (u + 0.5, v + 0.5) with u = fx X/Z + cx, v = fy Y/Z + cy: pixel (i, j) has
/// its centre at u = i, v = j. Depth maps near..far to 0..1.
Eigen::Matrix4d clip_from_projector(const config::ProjectorConfig& projector);

// The CPU side of Eq. 3 is config::Pinhole::project (ProjectorConfig is a Pinhole).

/// A projector with lens distortion is drawn in two passes: the models through a pinhole onto an
/// undistorted canvas, then each panel pixel takes the canvas at the ray its light leaves along (the lens
/// undone), so content drawn for a ray lands on that ray. The canvas is the projector's pinhole (same
/// focal lengths, no distortion) widened by margins that hold every panel pixel's ray.
struct LensCanvas {
  config::ProjectorConfig pinhole;  ///< the canvas's projector: size width + left + right margins, principal point shifted
  int left_px = 0;                  ///< margin left of and above the panel's image, projector pixels
  int top_px = 0;
};
/// The canvas for `projector` (whose lens validate_projector accepted).
LensCanvas lens_canvas(const config::ProjectorConfig& projector);
/// The lens pass's map: for each pixel of a width x height target showing the projector's panel (row
/// by row), the canvas position (0..1 each way) of the ray its light leaves along, as two floats; -1, -1
/// where the lens sends no ray. Computed once per target and lens: solving the lens per pixel in the
/// shader (8 Newton steps) took 24 ms of a 1280x800 frame on lavapipe.
std::vector<float> lens_warp(const config::ProjectorConfig& projector, const LensCanvas& canvas, int width, int height);

/// Converts a host transform to the column-major float matrix the GPU gets (the one Eigen -> GPU conversion).
std::array<float, 16> to_gpu_matrix(const Eigen::Matrix4d& m);

}  // namespace projbot::engine
