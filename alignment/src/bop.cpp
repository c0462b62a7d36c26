// BOP dataset reader: models_info.json and each scene's scene_camera / scene_gt / scene_gt_info JSON, checked
// once. nlohmann::json parses; every value read from it is checked for kind and range here.

#include "projbot/alignment/bop.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "projbot/assets/image.hpp"
#include "projbot/config/json_message.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/rigid.hpp"

namespace projbot::alignment {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr std::uintmax_t kMaxJsonBytes = 256ULL << 20;
// Published ground truth is rounded (LM-O's rotations to 0.0019 of orthonormal): within this it is a
// rotation and is made exactly one (SVD); beyond it, it is something else (a scale, a mistake).
constexpr double kRoundedRotation = 0.01;
constexpr double kFloat32Rotation = 1e-4;       // what float32 storage alone leaves: not counted as rounded
constexpr double kMaxTranslationMm = 100000.0;  // 100 m: no camera sees an object farther

// The rotations read that were rounded past float32's precision, and the worst of them.
struct Rounding {
  int count = 0;
  double worst = 0.0;
};

double orthonormality_error(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
}

// `R` (row-major, 9 numbers) and `t_m` as a rigid transform whose rotation is made orthonormal.
Eigen::Matrix4d read_rotation(const fs::path& file, const std::vector<double>& R, const Eigen::Vector3d& t_m,
                              const std::string& where, Rounding& rounding) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int i = 0; i < 9; ++i) T(i / 3, i % 3) = R[static_cast<std::size_t>(i)];
  T.topRightCorner<3, 1>() = t_m;
  const double error = orthonormality_error(T.topLeftCorner<3, 3>());
  try {
    T = config::orthonormalised_rigid(T, file.string() + ": " + where, kRoundedRotation);
  } catch (const std::exception& e) {
    throw AlignmentError(e.what());
  }
  if (error > kFloat32Rotation) ++rounding.count, rounding.worst = std::max(rounding.worst, error);
  return T;
}

[[noreturn]] void fail(const fs::path& file, const std::string& why) { throw AlignmentError(file.string() + ": " + why); }

json read_json(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) fail(file, "missing (a BOP dataset needs it)");
  if (!fs::is_regular_file(file, ec)) fail(file, "not a regular file");
  if (fs::file_size(file, ec) > kMaxJsonBytes) fail(file, "larger than 256 MB, not a BOP annotation file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot be opened");
  try {
    json j = json::parse(in);
    if (!j.is_object()) fail(file, "must hold a JSON object");
    return j;
  } catch (const json::exception& e) {
    fail(file, "malformed JSON (" + config::without_json_tag(e.what()) + ")");
  }
}

int parse_id(const fs::path& file, const std::string& key) {
  int id = -1;
  std::istringstream in(key);
  in >> id;
  if (!in || !in.eof() || id < 0 || id > kMaxBopId)
    fail(file, "key '" + key + "' is not an id (a whole number 0.." + std::to_string(kMaxBopId) + ")");
  return id;
}

std::vector<double> numbers(const fs::path& file, const json& value, std::size_t count, const std::string& what) {
  if (!value.is_array() || value.size() != count) fail(file, what + " must be a list of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (const json& v : value) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) fail(file, what + " holds a value that is not a finite number");
    out.push_back(v.get<double>());
  }
  return out;
}

const json& member(const fs::path& file, const json& object, const char* key, const std::string& where) {
  if (!object.is_object() || !object.contains(key)) fail(file, where + " has no '" + key + "'");
  return object.at(key);
}

std::string image_name(int id, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d%s", id, ext);
  return name;
}

// Whether an object's entry names a symmetry: a non-empty list of them. Anything else under those keys
// is an error naming the object (an empty list, or a string, made it symmetric before: scored by ADD-S).
bool has_symmetries(const fs::path& file, const std::string& key, const json& info) {
  bool any = false;
  for (const char* k : {"symmetries_discrete", "symmetries_continuous"}) {
    if (!info.is_object() || !info.contains(k)) continue;
    const json& list = info.at(k);
    if (!list.is_array()) fail(file, "object " + key + ": " + k + " must be a list of symmetries");
    for (const json& s : list)
      if (!s.is_array() && !s.is_object()) fail(file, "object " + key + ": " + k + " holds an entry that is not a symmetry");
    any = any || !list.empty();
  }
  return any;
}

// One key per id: "1" and "01" name the same image (or object), which would be counted twice.
void check_unique_ids(const fs::path& file, const json& object, const std::string& what) {
  std::map<int, std::string> seen;
  for (const auto& [key, value] : object.items()) {
    const int id = parse_id(file, key);
    if (const auto [at, added] = seen.emplace(id, key); !added)
      fail(file, what + " " + std::to_string(id) + " is listed twice ('" + at->second + "' and '" + key + "')");
  }
}

}  // namespace

std::vector<BopObject> read_bop_models(const fs::path& models) {
  const fs::path file = models / "models_info.json", root = models.parent_path();
  const json info = read_json(file);
  check_unique_ids(file, info, "object");
  bool any_symmetry = false;
  for (const auto& [key, value] : info.items()) any_symmetry = has_symmetries(file, key, value) || any_symmetry;
  // BOP's YCB-V ships symmetries; a dataset that names none anywhere (converted elsewhere) but is YCB-V
  // gets YCB-V's list, so its cans and clamps are not scored as if their turn could be seen.
  const bool ycbv = root.filename().string().find("ycbv") != std::string::npos ||
                    root.parent_path().filename().string().find("ycbv") != std::string::npos;
  std::vector<BopObject> objects;
  for (const auto& [key, value] : info.items()) {
    BopObject o;
    o.id = parse_id(file, key);
    const json& d = member(file, value, "diameter", "object " + key);
    if (!d.is_number() || !(d.get<double>() > 0.0) || !std::isfinite(d.get<double>()))
      fail(file, "object " + key + ": diameter must be a finite number > 0 (mm)");
    o.diameter_m = d.get<double>() / 1000.0;
    o.model = models / ("obj_" + image_name(o.id, ".ply"));
    o.symmetric = any_symmetry ? has_symmetries(file, key, value)
                               : ycbv && std::count(kYcbvSymmetricIds.begin(), kYcbvSymmetricIds.end(), o.id) > 0;
    objects.push_back(o);
  }
  if (objects.empty()) fail(file, "lists no objects");
  std::sort(objects.begin(), objects.end(), [](const BopObject& a, const BopObject& b) { return a.id < b.id; });
  return objects;
}

namespace {

BopImage read_camera(const fs::path& file, const fs::path& folder, int id, const json& cam, Rounding& rounding) {
  const std::string where = "image " + std::to_string(id);
  BopImage image;
  image.id = id;
  const auto K = numbers(file, member(file, cam, "cam_K", where), 9, where + ": cam_K");
  // A pinhole camera's K: focal lengths of a real camera's (1 to 100000 px), no skew, last row 0 0 1.
  if (!(K[0] >= 1.0 && K[0] <= 1e5) || !(K[4] >= 1.0 && K[4] <= 1e5))
    fail(file, where + ": cam_K's focal lengths must be 1 to 100000 px");
  if (K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0)
    fail(file, where + ": cam_K must be [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew, last row 0 0 1)");
  image.k.fx_px = K[0], image.k.fy_px = K[4], image.k.cx_px = K[2], image.k.cy_px = K[5];
  const json& scale = member(file, cam, "depth_scale", where);
  if (!scale.is_number() || !(scale.get<double>() >= 1e-3 && scale.get<double>() <= 1e3))
    fail(file, where + ": depth_scale must be a number within 0.001..1000 (mm per stored unit)");
  if (cam.contains("cam_R_w2c"))  // checked like the ground truth's rotations; the reader uses no world frame
    read_rotation(file, numbers(file, cam.at("cam_R_w2c"), 9, where + ": cam_R_w2c"), Eigen::Vector3d::Zero(),
                  where + ": cam_R_w2c", rounding);
  image.depth_units_per_m = 1000.0 / scale.get<double>();
  image.depth = folder / "depth" / image_name(id, ".png");
  std::error_code ec;
  if (!fs::is_regular_file(image.depth, ec))
    fail(image.depth, "missing: " + file.string() + " lists image " + std::to_string(id));
  for (const char* ext : {".png", ".jpg"})
    if (fs::is_regular_file(folder / "rgb" / image_name(id, ext), ec)) image.rgb = folder / "rgb" / image_name(id, ext);
  return image;
}

BopInstance read_instance(const fs::path& file, const json& gt, const std::string& where, Rounding& rounding) {
  BopInstance inst;
  const json& obj = member(file, gt, "obj_id", where);
  if (!obj.is_number_integer() || obj.get<long long>() < 0 || obj.get<long long>() > kMaxBopId)
    fail(file, where + ": obj_id must be a whole number 0.." + std::to_string(kMaxBopId));
  inst.obj_id = obj.get<int>();
  const auto R = numbers(file, member(file, gt, "cam_R_m2c", where), 9, where + ": cam_R_m2c");
  const auto t = numbers(file, member(file, gt, "cam_t_m2c", where), 3, where + ": cam_t_m2c");
  const Eigen::Vector3d t_mm(t[0], t[1], t[2]);
  if (!(t_mm.z() > 0.0))
    fail(file, where + ": cam_t_m2c puts the object behind the camera (z " + std::to_string(t_mm.z()) + " mm, must be > 0)");
  if (!(t_mm.norm() <= kMaxTranslationMm))
    fail(file, where + ": cam_t_m2c puts the object " + std::to_string(t_mm.norm() / 1000.0) + " m away (at most 100 m)");
  inst.T_camera_model = read_rotation(file, R, t_mm / 1000.0, where, rounding);
  return inst;
}

void read_instances(const fs::path& folder, std::map<int, BopImage>& images, Rounding& rounding) {
  const fs::path gt_file = folder / "scene_gt.json", info_file = folder / "scene_gt_info.json";
  const json gt = read_json(gt_file);
  check_unique_ids(gt_file, gt, "image");
  std::error_code ec;
  const std::optional<json> info = fs::exists(info_file, ec) ? std::optional<json>(read_json(info_file)) : std::nullopt;
  for (const auto& [key, list] : gt.items()) {
    const int id = parse_id(gt_file, key);
    const auto image = images.find(id);
    if (image == images.end()) fail(gt_file, "image " + key + " is not in scene_camera.json");
    if (!list.is_array()) fail(gt_file, "image " + key + " must hold a list of instances");
    const json* visib = nullptr;
    if (info) {
      if (!info->contains(key)) fail(info_file, "image " + key + " is missing (scene_gt.json lists it)");
      visib = &info->at(key);
      if (!visib->is_array() || visib->size() != list.size())
        fail(info_file, "image " + key + " lists " + std::to_string(visib->is_array() ? visib->size() : 0) +
                            " instances, scene_gt.json " + std::to_string(list.size()));
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string where = "image " + key + ", instance " + std::to_string(i);
      BopInstance inst = read_instance(gt_file, list[i], where, rounding);
      inst.gt_index = static_cast<int>(i);
      if (visib) {
        const json& px = member(info_file, (*visib)[i], "px_count_visib", where);
        if (!px.is_number_integer() || px.get<long long>() < 0 || px.get<long long>() > 100000000)
          fail(info_file, where + ": px_count_visib must be a whole number >= 0");
        inst.visible_px = px.get<int>();
      }
      image->second.instances.push_back(inst);
    }
  }
}

BopScene read_scene(const fs::path& folder, Rounding& rounding) {
  BopScene scene;
  scene.name = folder.filename().string();
  scene.folder = folder;
  const fs::path cam_file = folder / "scene_camera.json";
  const json cams = read_json(cam_file);
  check_unique_ids(cam_file, cams, "image");
  std::map<int, BopImage> images;
  for (const auto& [key, cam] : cams.items()) {
    const int id = parse_id(cam_file, key);
    images.emplace(id, read_camera(cam_file, folder, id, cam, rounding));
  }
  if (images.empty()) fail(cam_file, "lists no images");
  read_instances(folder, images, rounding);
  for (auto& [id, image] : images) scene.images.push_back(std::move(image));
  return scene;
}

}  // namespace

const BopObject* BopDataset::object(int id) const {
  for (const BopObject& o : objects)
    if (o.id == id) return &o;
  return nullptr;
}

BopDataset read_bop_dataset(const fs::path& root, const std::vector<std::string>& scenes, const std::string& split) {
  std::error_code ec;
  if (const std::string why = config::input_folder_problem(root); !why.empty())
    fail(root, why + " (a BOP dataset: models/ and " + split + "/)");
  BopDataset out;
  out.root = root;
  out.objects = read_bop_models(root / "models");
  const fs::path split_dir = root / split;
  if (const std::string why = config::input_folder_problem(split_dir); !why.empty())
    fail(split_dir, why + " (the dataset's " + split + " split)");
  std::vector<fs::path> folders;
  // A hidden folder is no scene: twin-dataset writes `.SCENE.partial` and renames it when whole, so one left
  // by a writer that was killed is work in progress, not a broken dataset.
  for (const auto& entry : fs::directory_iterator(split_dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.front() != '.' && (scenes.empty() || std::count(scenes.begin(), scenes.end(), name)))
      folders.push_back(entry.path());
  }
  for (const std::string& s : scenes) {
    if (fs::path(s).filename() != s || s == "." || s == "..")
      fail(split_dir, "scene '" + s + "' is a path; name a scene folder of it (e.g. 000000)");
    if (!fs::is_directory(split_dir / s, ec)) fail(split_dir / s, "no such scene");
  }
  if (folders.empty()) fail(split_dir, "holds no scene folders");
  std::sort(folders.begin(), folders.end());
  Rounding rounding;
  for (const fs::path& f : folders) out.scenes.push_back(read_scene(f, rounding));
  out.rotations_orthonormalised = rounding.count;
  out.worst_orthonormality_error = rounding.worst;
  // Every object an instance names is in models_info.json and has its model file (each looked up once).
  std::set<int> checked;
  for (const BopScene& s : out.scenes)
    for (const BopImage& im : s.images)
      for (const BopInstance& inst : im.instances) {
        if (!checked.insert(inst.obj_id).second) continue;
        const BopObject* o = out.object(inst.obj_id);
        if (!o) fail(s.folder / "scene_gt.json", "obj_id " + std::to_string(inst.obj_id) + " is not in models_info.json");
        if (!fs::is_regular_file(o->model, ec))
          fail(o->model, "missing (object " + std::to_string(inst.obj_id) + " has instances)");
      }
  return out;
}

std::string rounded_rotations_note(const BopDataset& data) {
  if (data.rotations_orthonormalised == 0) return "";
  char worst[32];
  std::snprintf(worst, sizeof worst, "%.2g", data.worst_orthonormality_error);
  const int n = data.rotations_orthonormalised;
  return data.root.string() + ": " + std::to_string(n) + (n == 1 ? " rotation" : " rotations") +
         " rounded off orthonormal (worst " + worst + ", within 0.01) made orthonormal (SVD)";
}

DepthImage read_bop_depth(const BopImage& image) {
  DepthImage d = read_depth_png(image.depth, image.depth_units_per_m);
  if (!(image.k.cx_px > 0.0 && image.k.cx_px < d.width && image.k.cy_px > 0.0 && image.k.cy_px < d.height))
    fail(image.depth,
         "cam_K's principal point lies outside the " + std::to_string(d.width) + "x" + std::to_string(d.height) + " image");
  return d;
}

void check_same_size(const BopImage& image, const DepthImage& depth, const fs::path& first_file, const DepthImage& first) {
  if (depth.width != first.width || depth.height != first.height)
    fail(image.depth, "is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) + ", but " + first_file.string() +
                          " of the same scene is " + std::to_string(first.width) + "x" + std::to_string(first.height) +
                          ": one camera, one size");
}

std::vector<std::uint8_t> read_bop_mask(const BopScene& scene, const BopImage& image, const BopInstance& instance,
                                        const DepthImage& depth) {
  char name[48];
  std::snprintf(name, sizeof name, "%06d_%06d.png", image.id, instance.gt_index);
  const fs::path file = scene.folder / "mask_visib" / name;
  assets::Image mask;
  try {
    mask = assets::read_image(file);
  } catch (const assets::AssetError& e) {
    throw AlignmentError(e.what());
  }
  if (mask.width != depth.width || mask.height != depth.height)
    fail(file, "is " + std::to_string(mask.width) + "x" + std::to_string(mask.height) + ", but its image's depth " +
                   image.depth.string() + " is " + std::to_string(depth.width) + "x" + std::to_string(depth.height));
  std::vector<std::uint8_t> out(static_cast<std::size_t>(mask.width) * mask.height);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = mask.rgba[4 * i] > 127 ? 1 : 0;
  return out;
}

}  // namespace projbot::alignment
