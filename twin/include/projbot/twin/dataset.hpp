#pragma once
// Datasets the twin renders (`projbot twin-dataset`, issue 68): BOP-format scenes of several objects on a
// table, touching and hiding each other, a wall or a shelf behind, seen by a slowly moving camera 0.6 to
// 1.5 m away looking down 20 to 60 degrees, its depth under the Kinect model fitted to real PrimeSense
// frames. `bench dataset` and `bench sensor` read them as they read real ones: breadth to measure pose
// estimation on, with exact ground truth, beyond the shapes the real frames hold.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::twin {

/// The YCB-Video camera (Asus Xtion, depth registered to colour): what the fitted sensor model was fitted on.
alignment::CameraIntrinsics ycbv_camera();

struct DatasetOptions {
  /// BOP models folders (models_info.json beside obj_IIIIII.ply, millimetres): their objects go in, ids kept.
  std::vector<std::filesystem::path> model_folders;
  bool procedural = true;  ///< and the procedural shapes (shapes.hpp), ids from 101
  int scenes = 10;
  int images = 10;  ///< per scene: a video of a slowly moving camera
  std::uint32_t seed = 1;
  alignment::KinectNoiseConfig sensor = alignment::KinectNoiseConfig::fitted();
  alignment::CameraIntrinsics camera = ycbv_camera();
  std::function<bool()> stop_requested;      ///< asked between images: true ends the dataset there
  std::function<void(int done)> image_done;  ///< images written so far
};

struct DatasetSummary {
  int objects = 0, scenes = 0, images = 0, instances = 0;
  bool interrupted = false;  ///< stop_requested ended it: the last scene holds the images written before
};

/// Writes the dataset into `out` (an empty or new folder): models/ (each object's PLY and
/// models_info.json) and test/SCENE/ (depth/, rgb/, mask_visib/, scene_camera.json, scene_gt.json,
/// scene_gt_info.json). Each scene is written beside its place and renamed into it when done, so an
/// error never leaves half a scene; a stop ends the last scene after the images written. Throws config::OutputError,
/// assets::AssetError or alignment::AlignmentError naming the file; a repeated object id across `model_folders` is an error.
DatasetSummary write_twin_dataset(const std::filesystem::path& out, const DatasetOptions& options, engine::Renderer& renderer);

}  // namespace projbot::twin
