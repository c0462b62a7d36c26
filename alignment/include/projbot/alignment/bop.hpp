#pragma once
// BOP datasets (the Benchmark for 6D Object Pose Estimation's format, which LM, LM-O, YCB-V, T-LESS, HB
// ... ship in): models in millimetres with models_info.json, and per scene depth/ rgb/ mask_visib/
// images with scene_camera.json, scene_gt.json and scene_gt_info.json. Read and checked once; every
// problem is an AlignmentError naming the file and what is wrong. Poses come out in metres.

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace projbot::alignment {

/// The largest image or object id: BOP names their files with six digits (000001.png, obj_000001.ply), so a
/// larger one would name a file no reader looks for. Readers refuse one; writers keep within it.
constexpr int kMaxBopId = 999999;

/// One object of the dataset (models_info.json).
struct BopObject {
  int id = 0;
  std::filesystem::path model;  ///< models/obj_IIIIII.ply, millimetres
  double diameter_m = 0.0;
  /// Scored with ADD-S: models_info.json gives symmetries, or (none given anywhere) a YCB-V dataset's
  /// known symmetric shapes.
  bool symmetric = false;
};

/// One annotated instance in one image (scene_gt.json with scene_gt_info.json).
struct BopInstance {
  int gt_index = 0;  ///< position in that image's scene_gt.json list (mask_visib/IMAGE_GTINDEX.png)
  int obj_id = 0;
  Eigen::Matrix4d T_camera_model = Eigen::Matrix4d::Identity();  ///< metres, rotation re-orthonormalised
  int visible_px = -1;                                           ///< px_count_visib; -1 where not given
};

/// One image of a scene.
struct BopImage {
  int id = 0;
  CameraIntrinsics k;                        ///< cam_K, with the depth image's size
  double depth_units_per_m = 1000.0;         ///< 1000 / depth_scale (depth_scale: mm per stored unit)
  std::filesystem::path depth;               ///< depth/IIIIII.png
  std::optional<std::filesystem::path> rgb;  ///< rgb/IIIIII.png or .jpg, where the dataset has it
  std::vector<BopInstance> instances;
};

struct BopScene {
  std::string name;  ///< the scene folder's name, e.g. "000001"
  std::filesystem::path folder;
  std::vector<BopImage> images;  ///< in image id order
};

struct BopDataset {
  std::filesystem::path root;
  std::vector<BopObject> objects;  ///< by id
  std::vector<BopScene> scenes;    ///< by name
  /// Rotations (ground truth, and cameras' cam_R_w2c) rounded beyond float32's precision (1e-4) but within
  /// 0.01 of orthonormal, as published datasets round them: made orthonormal (SVD) and used. The worst error.
  int rotations_orthonormalised = 0;
  double worst_orthonormality_error = 0.0;
  const BopObject* object(int id) const;
};

/// The one line saying how many rotations were made orthonormal, or "" where none was.
std::string rounded_rotations_note(const BopDataset& data);

/// The ids YCB-V's own evaluation scores as symmetric (cans, bowl, wood block, marker, clamps, foam brick).
inline const std::vector<int> kYcbvSymmetricIds{1, 4, 6, 13, 16, 18, 19, 20, 21};

/// The objects of a BOP models folder (`models_info.json` and obj_IIIIII.ply beside it), checked as
/// read_bop_dataset checks them; a folder of YCB-V (its own or its parent's name says so) without
/// symmetry entries gets kYcbvSymmetricIds. Throws AlignmentError naming the file.
std::vector<BopObject> read_bop_models(const std::filesystem::path& models);

/// Reads the dataset at `root` (holding models/ and `split`/), only the scenes named in `scenes` when it
/// is not empty. Checks every JSON file, that each image's depth image exists, that scene_gt_info.json
/// lists as many instances as scene_gt.json, that every obj_id has a model, and that poses are rigid
/// (a rotation within 0.01 of orthonormal is made orthonormal; beyond, an error naming image and instance),
/// in front of the camera and within 100 m, and depth scales within 0.001..1000 mm per unit.
/// Images are not decoded here: read_bop_depth does that.
BopDataset read_bop_dataset(const std::filesystem::path& root, const std::vector<std::string>& scenes = {},
                            const std::string& split = "test");

/// One object's model as the benchmark estimates and scores it, in metres (`scale`: model units to
/// metres) and not recentred (BOP's poses are of the model's own frame).
struct BopModel {
  const BopObject* info = nullptr;
  ModelCloud cloud;                                  ///< surface samples, for estimation
  std::vector<Eigen::Vector3f> vertices;             ///< the mesh's vertices for ADD / ADD-S (at most 30000, evenly)
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< bounding-box centre, model frame
};

/// Loads `object`'s model file; throws assets::AssetError naming it when it cannot be read.
BopModel load_bop_model(const BopObject& object, double scale);

/// The image's depth in metres, at its own size (a reader of several images checks they agree:
/// check_same_size).
DepthImage read_bop_depth(const BopImage& image);
/// Throws AlignmentError naming `image`'s depth file and both sizes when `depth` (read from it) is not
/// the size of `first` (a scene's first image's depth, read from `first_file`).
void check_same_size(const BopImage& image, const DepthImage& depth, const std::filesystem::path& first_file,
                     const DepthImage& first);

/// mask_visib/IMAGE_GTINDEX.png of one instance as a per-pixel flag (row-major), which must be the size of
/// its image's depth (`depth`, as read_bop_depth gave it): otherwise an AlignmentError naming the mask, the
/// depth image and both sizes.
std::vector<std::uint8_t> read_bop_mask(const BopScene& scene, const BopImage& image, const BopInstance& instance,
                                        const DepthImage& depth);

}  // namespace projbot::alignment
