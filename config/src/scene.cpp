#include "projbot/config/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>

namespace projbot::config {
namespace {

// A YAML mapping being read: knows its key path for errors and rejects keys nobody asked for.
class MapReader {
 public:
  MapReader(YAML::Node node, std::string path, const std::string& file) : node_(node), path_(std::move(path)), file_(file) {
    if (!node_.IsMap()) fail(node_, path_, "expected a mapping");
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key_path, const std::string& why) const {
    const YAML::Mark mark = at.Mark();
    std::ostringstream msg;
    msg << file_;
    if (mark.line >= 0) msg << ':' << mark.line + 1;
    msg << ": " << (key_path.empty() ? "<root>" : key_path) << ": " << why;
    throw ConfigError(msg.str());
  }

  std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  bool has(const std::string& key) const { return static_cast<bool>(node_[key]); }

  YAML::Node child(const std::string& key, bool required) {
    used_.insert(key);
    YAML::Node n = node_[key];
    if (!n && required) fail(node_, key_path(key), "missing required key");
    return n;
  }

  template <typename T>
  T get(const std::string& key, const T& fallback, bool required = false) {
    YAML::Node n = child(key, required);
    if (!n) return fallback;
    if (!n.IsScalar()) fail(n, key_path(key), "expected a " + type_name<T>());
    try {
      T value = n.as<T>();
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(value)) fail(n, key_path(key), "must be finite");
      }
      return value;
    } catch (const YAML::Exception&) {
      fail(n, key_path(key), "expected a " + type_name<T>() + ", got '" + n.Scalar() + "'");
    }
  }

  std::vector<double> numbers(const YAML::Node& n, const std::string& key_path, std::size_t count) const {
    if (!n.IsSequence() || n.size() != count) fail(n, key_path, "expected a list of " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (const auto& item : n) {
      double v = 0.0;
      if (!item.IsScalar() || !YAML::convert<double>::decode(item, v) || !std::isfinite(v))
        fail(item, key_path, "'" + (item.IsScalar() ? item.Scalar() : std::string("<non-scalar>")) + "' is not a finite number");
      out.push_back(v);
    }
    return out;
  }

  // Call once every known key was read: any other key is a typo the user must hear about.
  void reject_unknown() const {
    for (const auto& kv : node_) {
      const auto key = kv.first.as<std::string>();
      if (!used_.contains(key)) fail(kv.first, key_path(key), "unknown key");
    }
  }

  const std::string& file() const { return file_; }

 private:
  template <typename T>
  static std::string type_name() {
    if constexpr (std::is_same_v<T, bool>)
      return "boolean";
    else if constexpr (std::is_integral_v<T>)
      return "integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "number";
    else
      return "string";
  }

  YAML::Node node_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> used_;
};

ProjectorConfig read_projector(MapReader& root) {
  YAML::Node node = root.child("projector", true);
  MapReader r(node, "projector", root.file());
  ProjectorConfig p;
  p.width_px = r.get<int>("width", 0, true);
  p.height_px = r.get<int>("height", 0, true);
  p.fx_px = r.get<double>("fx", 0.0, true);
  p.fy_px = r.get<double>("fy", 0.0, true);
  p.cx_px = r.get<double>("cx", 0.0, true);
  p.cy_px = r.get<double>("cy", 0.0, true);
  p.near_m = r.get<double>("near", p.near_m);
  p.far_m = r.get<double>("far", p.far_m);
  r.reject_unknown();
  try {
    validate_projector(p, "projector");
  } catch (const ConfigError& e) {
    r.fail(node, "", e.what());
  }
  return p;
}

Eigen::Matrix4d read_pose(MapReader& target, const std::string& path, const std::string& key = "pose",
                          const Eigen::Matrix4d& fallback = Eigen::Matrix4d::Identity()) {
  YAML::Node node = target.child(key, false);
  if (!node) return fallback;
  MapReader r(node, path, target.file());
  Eigen::Matrix4d T;
  if (r.has("matrix")) {
    if (r.has("translation") || r.has("rpy_deg"))
      r.fail(node, path, "give either 'matrix' or 'translation' + 'rpy_deg', not both");
    const auto m = r.numbers(r.child("matrix", true), r.key_path("matrix"), 16);
    for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = m[static_cast<std::size_t>(i)];
  } else {
    const auto t = r.numbers(r.child("translation", true), r.key_path("translation"), 3);
    YAML::Node rpy_node = r.child("rpy_deg", false);
    std::vector<double> rpy{0.0, 0.0, 0.0};
    if (rpy_node) rpy = r.numbers(rpy_node, r.key_path("rpy_deg"), 3);
    T = pose_from_xyz_rpy({t[0], t[1], t[2]}, {rpy[0], rpy[1], rpy[2]});
  }
  r.reject_unknown();
  try {
    validate_rigid(T, path);
  } catch (const ConfigError& e) {
    r.fail(node, "", e.what());
  }
  return T;
}

// The optional robot section: the pan-tilt rig's calibration, each key defaulting to the simulated rig.
PanTiltConfig read_robot(MapReader& root) {
  PanTiltConfig c = default_pan_tilt();
  YAML::Node node = root.child("robot", false);
  if (!node) return c;
  MapReader r(node, "robot", root.file());
  YAML::Node pt = r.child("pan_tilt", true);
  MapReader p(pt, "robot.pan_tilt", root.file());
  c.T_base_mount = read_pose(p, "robot.pan_tilt.mount", "mount", c.T_base_mount);
  c.T_head_camera = read_pose(p, "robot.pan_tilt.camera", "camera", c.T_head_camera);
  c.T_projector_camera = read_pose(p, "robot.pan_tilt.projector_from_camera", "projector_from_camera", c.T_projector_camera);
  if (YAML::Node n = p.child("tilt_axis_offset", false)) {
    const auto v = p.numbers(n, "robot.pan_tilt.tilt_axis_offset", 3);
    c.tilt_axis_offset_m = {v[0], v[1], v[2]};
  }
  const auto limits = [&](const char* key, double& lo, double& hi) {
    YAML::Node n = p.child(key, false);
    if (!n) return;
    const std::string path = std::string("robot.pan_tilt.") + key;
    const auto v = p.numbers(n, path, 2);
    if (!(v[0] < v[1]) || v[0] < -180.0 || v[1] > 180.0) p.fail(n, path, "need min < max within -180..180 degrees");
    lo = v[0] * std::numbers::pi / 180.0;
    hi = v[1] * std::numbers::pi / 180.0;
  };
  limits("pan_limits_deg", c.pan_min_rad, c.pan_max_rad);
  limits("tilt_limits_deg", c.tilt_min_rad, c.tilt_max_rad);
  p.reject_unknown();
  r.reject_unknown();
  return c;
}

}  // namespace

void validate_projector(const ProjectorConfig& p, std::string_view where) {
  const auto fail = [&](const std::string& why) { throw ConfigError(std::string(where) + ": " + why); };
  if (p.width_px <= 0 || p.height_px <= 0 || p.width_px > 16384 || p.height_px > 16384)
    fail("size " + std::to_string(p.width_px) + "x" + std::to_string(p.height_px) + " must be 1..16384 pixels each way");
  if (!(p.fx_px > 0.0) || !(p.fy_px > 0.0) || !std::isfinite(p.fx_px) || !std::isfinite(p.fy_px))
    fail("fx and fy must be finite and > 0");
  if (!std::isfinite(p.cx_px) || !std::isfinite(p.cy_px)) fail("cx and cy must be finite");
  if (!(p.near_m > 0.0) || !std::isfinite(p.far_m) || !(p.near_m < p.far_m))
    fail("need 0 < near < far (near " + std::to_string(p.near_m) + ", far " + std::to_string(p.far_m) + ")");
}

Scene parse_scene(std::string_view yaml_text, const std::filesystem::path& source) {
  const std::string file = source.empty() ? std::string("<scene>") : source.string();
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::ParserException& e) {
    throw ConfigError(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
  if (!root || root.IsNull()) throw ConfigError(file + ": the scene file is empty");

  Scene scene;
  scene.source = source;
  MapReader r(root, "", file);
  scene.projector = read_projector(r);
  scene.pan_tilt = read_robot(r);

  YAML::Node targets = r.child("targets", true);
  if (!targets.IsSequence()) r.fail(targets, "targets", "expected a list of targets");
  const std::filesystem::path base = source.empty() ? std::filesystem::path() : source.parent_path();
  std::set<std::string> names;
  for (std::size_t i = 0; i < targets.size(); ++i) {
    const std::string path = "targets[" + std::to_string(i) + "]";
    MapReader t(targets[i], path, file);
    TargetConfig target;
    target.name = t.get<std::string>("name", "", true);
    if (target.name.empty()) t.fail(targets[i], path + ".name", "must not be empty");
    if (!names.insert(target.name).second) t.fail(targets[i], path + ".name", "duplicate target name '" + target.name + "'");
    const auto model = t.get<std::string>("model", "", true);
    if (model.empty()) t.fail(targets[i], path + ".model", "must not be empty");
    target.model = std::filesystem::path(model).is_absolute() ? std::filesystem::path(model) : base / model;
    target.scale = t.get<double>("scale", 1.0);
    if (!(target.scale > 0.0)) t.fail(targets[i]["scale"], path + ".scale", "must be > 0");
    target.recenter = t.get<bool>("recenter", false);
    target.T_projector_target = read_pose(t, path + ".pose");
    t.reject_unknown();
    scene.targets.push_back(std::move(target));
  }
  r.reject_unknown();
  return scene;
}

Scene load_scene(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path.string() + ": cannot open scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path);
}

}  // namespace projbot::config
