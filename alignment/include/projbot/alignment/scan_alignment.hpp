#pragma once
// One acquisition of a model against a scan from a file (`projbot align`): a cloud (.pcd, .ply) aligned by
// ICP with restarts and global re-initialisation, or a depth image (16-bit .png / .tiff) acquired as the
// tour, the tracker and bench dataset acquire it, then checked for free space.

#include <Eigen/Core>
#include <filesystem>
#include <optional>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"

namespace projbot::alignment {

/// A scan as a cloud; for a depth image, the image and its camera too (for the free-space check).
struct Scan {
  PointCloud cloud;
  std::optional<DepthImage> depth;
  CameraIntrinsics k;
};

/// Reads `path`: a .pcd / .ply cloud, or a .png (`units_per_metre` depth units per metre) or .tiff depth
/// image back-projected through `k` (the Kinect v1's when none is given, which must then be 640x480).
/// Throws AlignmentError naming the file for a format it does not read, an image of another size than the
/// default intrinsics' or intrinsics whose principal point lies outside it.
Scan load_scan(const std::filesystem::path& path, double units_per_metre, const std::optional<CameraIntrinsics>& k);

/// Whether `path` names a cloud (.pcd, .ply), or a depth image (.png, .tif, .tiff), by its extension.
bool is_cloud_file(const std::filesystem::path& path);
bool is_depth_image_file(const std::filesystem::path& path);

struct ScanAlignment {
  AlignmentResult result;
  std::optional<FreeSpaceCheck> free_space;  ///< depth images only
  double max_behind_ratio = 0.0;             ///< the free-space check's limit
  bool accepted = false;                     ///< passed the gate (and the free-space check)
  std::string refused;                       ///< why a depth image had nothing to align near the guess (empty: it had)
};

/// Aligns `model` to `scan` from `T_init`. A depth image: the support under the guess left out, the depth
/// cropped to the guess's silhouette grown by how far `error` reaches, ICP, the gate, then the free-space
/// check. A cloud (its frame unknown: no range noise, no viewpoint): ICP with restarts and global
/// re-initialisation, cropped around the guess when `config.crop`.
ScanAlignment align_scan(const ModelCloud& model, const Scan& scan, const Eigen::Matrix4d& T_init, const GuessError& error,
                         AcquisitionConfig config);

}  // namespace projbot::alignment
