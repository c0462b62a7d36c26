#include "projbot/alignment/scan_alignment.hpp"

#include <string>

#include "file_kind.hpp"

namespace projbot::alignment {
namespace {

using detail::lower_extension;

// The camera of a depth image: `k` (its size the image's), or the Kinect v1's for a 640x480 one.
CameraIntrinsics camera_of(const std::filesystem::path& path, const DepthImage& depth, const std::optional<CameraIntrinsics>& k) {
  // Intrinsics belong to one image size: a depth image of another size would back-project to a wrong,
  // plausible-looking cloud.
  const std::string size = std::to_string(depth.width) + "x" + std::to_string(depth.height);
  if (!k && (depth.width != 640 || depth.height != 480))
    throw AlignmentError(path.string() + ": the depth image is " + size +
                         " pixels, the Kinect v1 default intrinsics are for 640x480: give --intrinsics "
                         "fx,fy,cx,cy of the camera that took it");
  CameraIntrinsics out = k ? *k : CameraIntrinsics::kinect_v1();
  if (!(out.cx_px > 0 && out.cx_px < depth.width && out.cy_px > 0 && out.cy_px < depth.height))
    throw AlignmentError(path.string() + ": the depth image is " + size +
                         " pixels, but --intrinsics put its principal point outside it (cx, cy = " + std::to_string(out.cx_px) +
                         ", " + std::to_string(out.cy_px) + ")");
  out.width_px = depth.width;
  out.height_px = depth.height;
  return out;
}

}  // namespace

bool is_cloud_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".pcd" || ext == ".ply";
}

bool is_depth_image_file(const std::filesystem::path& path) {
  const std::string ext = lower_extension(path);
  return ext == ".png" || ext == ".tif" || ext == ".tiff";
}

Scan load_scan(const std::filesystem::path& path, double units_per_metre, const std::optional<CameraIntrinsics>& k) {
  if (is_cloud_file(path)) return {read_cloud(path), std::nullopt, {}};
  if (!is_depth_image_file(path))
    throw AlignmentError("--scan must be a .pcd or .ply cloud or a 16-bit .png / .tiff depth image, got '" + path.string() + "'");
  const DepthImage depth =
      lower_extension(path) == ".png" ? read_depth_png(path, units_per_metre) : read_depth_tiff(path, 1.0 / units_per_metre);
  const CameraIntrinsics camera = camera_of(path, depth, k);
  return {depth_to_cloud(depth, camera), depth, camera};
}

ScanAlignment align_scan(const ModelCloud& model, const Scan& scan, const Eigen::Matrix4d& T_init, const GuessError& error,
                         AcquisitionConfig config) {
  ScanAlignment out;
  out.max_behind_ratio = WorkerConfig{}.max_behind_ratio;
  if (scan.depth) {
    WorkerConfig worker;
    worker.acquisition = config;
    const TargetFollower follower(model, scan.k, worker);
    try {
      out.result = follower.acquire(*scan.depth, T_init, error);
    } catch (const AlignmentError& e) {  // too little depth near the guess: nothing to align, refused
      out.refused = e.what();
      out.result.T_scan_model = T_init;
    }
    // Where the camera looks through the model at the estimate, it is in the wrong place, however well it fits.
    out.free_space = follower.verify(*scan.depth, out.result.T_scan_model);
  } else {
    config.depth_sigma_coeff = 0.0;   // a cloud's z is no range: the depth camera's noise there says nothing
    config.scan_from_origin = false;  // nor is its origin where it was seen from
    out.result = Aligner(model, config).align(scan.cloud, T_init);
  }
  out.accepted = out.result.converged && (!out.free_space || out.free_space->passes(out.max_behind_ratio));
  return out;
}

}  // namespace projbot::alignment
