#include "projbot/config/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "devices_reader.hpp"
#include "map_reader.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/yaml_keys.hpp"
#include "target_reader.hpp"

namespace projbot::config {
namespace {

// `distortion: [k1, k2, p1, p2, k3]` (OpenCV's order; fewer is the rest zero). A calibration file may
// list OpenCV's rational terms k4..k6 too, as long as they are zero: the renderer draws the 5-term lens.
Distortion read_distortion(const MapReader& r, const YAML::Node& d, const std::string& path) {
  if (!d.IsSequence() || d.size() == 0 || d.size() > 8)
    r.fail(d, path, "expected a list of up to 5 coefficients k1, k2, p1, p2, k3");
  const std::vector<double> v = r.numbers(d, path, d.size());
  Distortion k{};
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) r.fail(d, path, "coefficients must be finite");
    if (i < k.size())
      k[i] = v[i];
    else if (v[i] != 0.0)
      r.fail(d, path, "only OpenCV's 5-term lens (k1, k2, p1, p2, k3) is drawn; the rational terms k4..k6 must be zero");
  }
  return k;
}

// The projector's brightness and response (`brightness_lm`, `gamma`, `black_level`, `gamma_rgb`,
// `mixing`), each optional.
void read_photometry(MapReader& r, const YAML::Node& node, Photometry& p) {
  p.brightness_lm = r.get<double>("brightness_lm", p.brightness_lm);
  p.gamma = r.get<double>("gamma", p.gamma);
  p.black_level = r.get<double>("black_level", p.black_level);
  if (!(p.brightness_lm >= 1.0 && p.brightness_lm <= 1e5))
    r.fail(node["brightness_lm"], r.key_path("brightness_lm"), "must be 1..100000 lumens");
  if (!(p.gamma >= 1.0 && p.gamma <= 4.0)) r.fail(node["gamma"], r.key_path("gamma"), "must be 1..4");
  if (!(p.black_level >= 0.0 && p.black_level <= 0.2))
    r.fail(node["black_level"], r.key_path("black_level"), "must be 0..0.2 (black's light, of full white's)");
  p.gamma_rgb = {p.gamma, p.gamma, p.gamma};
  if (YAML::Node g = r.child("gamma_rgb", false)) {
    const std::vector<double> v = r.numbers(g, r.key_path("gamma_rgb"), 3);
    for (std::size_t i = 0; i < 3; ++i) {
      if (!(v[i] >= 1.0 && v[i] <= 4.0)) r.fail(g, r.key_path("gamma_rgb"), "each must be 1..4");
      p.gamma_rgb[i] = v[i];
    }
  }
  if (YAML::Node x = r.child("mixing", false)) {
    const std::vector<double> v = r.numbers(x, r.key_path("mixing"), 9);
    for (std::size_t i = 0; i < 9; ++i) {
      if (!(v[i] >= -0.5 && v[i] <= 1.5))
        r.fail(x, r.key_path("mixing"), "entries must be -0.5..1.5 (shares of each channel's light)");
      p.mixing(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) = v[i];
    }
    if (!(std::abs(p.mixing.determinant()) >= 0.1))
      r.fail(x, r.key_path("mixing"), "is (nearly) singular: the channels' colours must be independent");
  }
}

// A pinhole section (`projector:`, `camera:`): every intrinsic required unless defaults are given.
ProjectorConfig read_pinhole(MapReader& root, const std::string& key, const std::optional<ProjectorConfig>& defaults) {
  YAML::Node node = root.child(key, !defaults);
  ProjectorConfig p = defaults.value_or(ProjectorConfig{Pinhole{0, 0, 0.0, 0.0, 0.0, 0.0}, 0.1, 20.0});
  if (!node) return p;
  MapReader r(node, key, root.file());
  const bool required = !defaults;
  p.width_px = r.get<int>("width", p.width_px, required);
  p.height_px = r.get<int>("height", p.height_px, required);
  p.fx_px = r.get<double>("fx", p.fx_px, required);
  p.fy_px = r.get<double>("fy", p.fy_px, required);
  p.cx_px = r.get<double>("cx", p.cx_px, required);
  p.cy_px = r.get<double>("cy", p.cy_px, required);
  p.near_m = r.get<double>("near", p.near_m);  // the aggregate above keeps near and far's defaults
  p.far_m = r.get<double>("far", p.far_m);
  if (key == "projector") {
    p.refresh_hz = r.get<double>("refresh_hz", p.refresh_hz);
    p.input_lag_ms = r.get<double>("input_lag_ms", p.input_lag_ms);
    if (!(p.refresh_hz >= 1.0 && p.refresh_hz <= 1000.0))
      r.fail(node["refresh_hz"], r.key_path("refresh_hz"), "must be 1..1000 Hz");
    if (!(p.input_lag_ms >= 0.0 && p.input_lag_ms <= 1000.0))
      r.fail(node["input_lag_ms"], r.key_path("input_lag_ms"), "must be 0..1000 ms");
    if (YAML::Node d = r.child("distortion", false)) p.distortion = read_distortion(r, d, r.key_path("distortion"));
    read_photometry(r, node, p.photometry);
  }
  r.reject_unknown();
  try {
    validate_projector(p, key);
  } catch (const ConfigError& e) {
    r.fail(node, "", e.what());
  }
  return p;
}

// Where the robot can stand: inside the room and outside every obstacle. Empty when it can.
std::string metres(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string place_problem(const Room& room, double x, double y) {
  if (!(x > 0.0 && x < room.width_m && y > 0.0 && y < room.depth_m))
    return "lies outside the room (0.." + metres(room.width_m) + " x 0.." + metres(room.depth_m) + " m)";
  for (std::size_t i = 0; i < room.obstacles.size(); ++i) {
    const auto& o = room.obstacles[i];
    if (x >= o.min_x_m && x <= o.max_x_m && y >= o.min_y_m && y <= o.max_y_m)
      return "lies inside room.obstacles[" + std::to_string(i) + "]";
  }
  return {};
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
    const Eigen::Vector3d t = r.vector3(r.child("translation", true), r.key_path("translation"));
    YAML::Node rpy_node = r.child("rpy_deg", false);
    const Eigen::Vector3d rpy = rpy_node ? r.vector3(rpy_node, r.key_path("rpy_deg")) : Eigen::Vector3d::Zero();
    T = pose_from_xyz_rpy(t, rpy);
  }
  r.reject_unknown();
  try {
    validate_rigid(T, path);
  } catch (const ConfigError& e) {
    r.fail(node, "", e.what());
  }
  return T;
}

// A glTF reference, for targets and props alike: `model` (resolved against the scene's folder), `scale`
// and `recenter`.
void read_model_ref(MapReader& m, const YAML::Node& node, const std::string& path, const std::filesystem::path& base,
                    std::filesystem::path& model, double& scale, bool& recenter) {
  const auto file = m.get<std::string>("model", "", true);
  if (file.empty()) m.fail(node, path + ".model", "must not be empty");
  model = beside_scene(file, base);
  scale = m.get<double>("scale", 1.0);
  if (!(scale >= 1e-4 && scale <= 1e4))
    m.fail(node["scale"], path + ".scale", "must be 0.0001..10000 (a uniform factor on the model's metres)");
  recenter = m.get<bool>("recenter", false);
}

TargetSupport read_support(MapReader& t, const std::string& path) {
  TargetSupport support;
  YAML::Node node = t.child("support", false);
  if (!node) return support;
  if (node.IsScalar()) {
    if (node.Scalar() != "floor") t.fail(node, path, "expected 'floor' or {width: W, depth: D}, not '" + node.Scalar() + "'");
    support.floor = true;
    return support;
  }
  MapReader m(node, path, t.file());
  support.width_m = m.get<double>("width", 0.0, true);
  support.depth_m = m.get<double>("depth", 0.0, true);
  if (!(support.width_m >= 0.01 && support.width_m <= 20.0) || !(support.depth_m >= 0.01 && support.depth_m <= 20.0))
    m.fail(node, path, "width and depth must be 0.01..20 m");
  m.reject_unknown();
  return support;
}

PropConfig read_prop(const YAML::Node& node, const std::string& path, const std::string& file,
                     const std::filesystem::path& base) {
  MapReader p(node, path, file);
  PropConfig prop;
  prop.name = p.get<std::string>("name", "", true);
  if (prop.name.empty()) p.fail(node, path + ".name", "must not be empty");
  if (p.has("box") == p.has("model")) p.fail(node, path, "give either a 'model' (glTF) or a 'box: {min, max}', not both");
  if (p.has("model")) {
    read_model_ref(p, node, path, base, prop.model, prop.scale, prop.recenter);
    if (!p.has("world_pose")) p.fail(node, path, "a model prop needs a world_pose");
    prop.T_world_prop = read_pose(p, path + ".world_pose", "world_pose");
  } else {
    MapReader b(p.child("box", true), path + ".box", file);
    prop.box_min_m = b.vector3(b.child("min", true), path + ".box.min");
    prop.box_max_m = b.vector3(b.child("max", true), path + ".box.max");
    if (!(prop.box_min_m.array() < prop.box_max_m.array()).all())
      p.fail(node["box"], path + ".box", "need min < max on every axis");
    b.reject_unknown();
    if (YAML::Node c = p.child("colour", false)) {
      const Eigen::Vector3d rgb = p.vector3(c, path + ".colour");
      if (!((rgb.array() >= 0.0).all() && (rgb.array() <= 1.0).all()))
        p.fail(c, path + ".colour", "each of r, g, b must be 0..1");
      prop.colour = {static_cast<float>(rgb.x()), static_cast<float>(rgb.y()), static_cast<float>(rgb.z())};
    }
  }
  p.reject_unknown();
  return prop;
}

// The optional robot section: the pan-tilt rig's calibration, each key defaulting to the simulated rig.
PanTiltConfig read_robot(MapReader& root, Scene& scene) {
  PanTiltConfig c = default_pan_tilt();
  YAML::Node node = root.child("robot", false);
  if (!node) return c;
  MapReader r(node, "robot", root.file());
  if (YAML::Node st = r.child("start", false)) {
    scene.robot_start = r.vector3(st, "robot.start");
    scene.robot_start.z() = radians(scene.robot_start.z());
  }
  if (YAML::Node dn = r.child("drift", false)) {
    MapReader d(dn, "robot.drift", root.file());
    OdometryDrift& s = scene.drift;
    // Fractions of the distance or turn travelled: beyond 0.5 no base drives (slip_scale 1e308 once gave an
    // infinite base error and a report of 0.0 mm over 0 lit frames).
    const auto bounded = [&](const char* key, double& value, double lo) {
      value = d.get<double>(key, value);
      if (!(value >= lo && value <= 0.5)) d.fail(dn[key], d.key_path(key), lo < 0.0 ? "must be -0.5..0.5" : "must be 0..0.5");
    };
    bounded("wheel_scale_sigma", s.wheel_scale_sigma, 0.0);
    bounded("slip_scale", s.slip_scale, 0.0);
    bounded("heading_bias_rad_per_m", s.heading_bias_rad_per_m, -0.5);
    bounded("heading_bias_rad_per_rad", s.heading_bias_rad_per_rad, -0.5);
    bounded("random_translation_sigma", s.random_translation_sigma, 0.0);
    bounded("random_rotation_sigma", s.random_rotation_sigma, 0.0);
    d.reject_unknown();
  }
  YAML::Node pt = r.child("pan_tilt", false);
  if (!pt) {
    r.reject_unknown();
    return c;
  }
  MapReader p(pt, "robot.pan_tilt", root.file());
  c.T_base_mount = read_pose(p, "robot.pan_tilt.mount", "mount", c.T_base_mount);
  c.T_head_camera = read_pose(p, "robot.pan_tilt.camera", "camera", c.T_head_camera);
  c.T_projector_camera = read_pose(p, "robot.pan_tilt.projector_from_camera", "projector_from_camera", c.T_projector_camera);
  if (YAML::Node n = p.child("tilt_axis_offset", false)) c.tilt_axis_offset_m = p.vector3(n, "robot.pan_tilt.tilt_axis_offset");
  const auto limits = [&](const char* key, double& lo, double& hi) {
    YAML::Node n = p.child(key, false);
    if (!n) return;
    const std::string path = std::string("robot.pan_tilt.") + key;
    const auto v = p.numbers(n, path, 2);
    if (!(v[0] < v[1]) || v[0] < -180.0 || v[1] > 180.0) p.fail(n, path, "need min < max within -180..180 degrees");
    lo = config::radians(v[0]);
    hi = config::radians(v[1]);
  };
  limits("pan_limits_deg", c.pan_min_rad, c.pan_max_rad);
  limits("tilt_limits_deg", c.tilt_min_rad, c.tilt_max_rad);
  p.reject_unknown();
  r.reject_unknown();
  return c;
}

// A calibration's `photometry:` (projbot calibrate photometric): the keys a scene's projector gives them by.
Photometry read_calibrated_photometry(const MapReader& r, const YAML::Node& node) {
  MapReader m(node, "photometry", r.file());
  Photometry p;
  read_photometry(m, node, p);
  const double camera_gamma = m.get<double>("camera_gamma", 2.2);  // how it was measured: informational
  if (!(camera_gamma >= 0.5 && camera_gamma <= 5.0)) m.fail(node["camera_gamma"], "photometry.camera_gamma", "must be 0.5..5");
  m.reject_unknown();
  return p;
}

// `fleet: {name: NAME, domain: D}`: this robot on the fleet's DDS bus (issue 69; the name is checked where
// the fleet starts).
void read_fleet(MapReader& root, Scene& scene) {
  if (YAML::Node n = root.child("fleet", false)) {
    MapReader m(n, "fleet", root.file());
    FleetSite f;
    f.name = m.get<std::string>("name", "", true);
    if (f.name.empty()) m.fail(n["name"], "fleet.name", "expected the robot's name in the fleet");
    f.domain = m.get<int>("domain", 0);
    if (f.domain < 0 || f.domain > 232) m.fail(n["domain"], "fleet.domain", "must be 0..232 (a DDS domain)");
    m.reject_unknown();
    scene.fleet = f;
  }
}

// `console: {listen: [ADDR:]PORT, token_file: FILE}` and `osc: {port: N, allow: [HOST...], send: HOST:PORT}`:
// how the operator's controls start at this site (issue 70). The listen address is checked where the
// console starts (its parser is the console's); the token file is an input, beside the scene.
void read_operator(MapReader& root, const std::filesystem::path& base, Scene& scene) {
  if (YAML::Node n = root.child("console", false)) {
    MapReader m(n, "console", root.file());
    ConsoleSite c;
    c.listen = m.get<std::string>("listen", "", true);
    if (c.listen.empty()) m.fail(n["listen"], "console.listen", "expected [ADDR:]PORT");
    if (YAML::Node t = m.child("token_file", false)) {
      if (!t.IsScalar() || t.Scalar().empty()) m.fail(t, "console.token_file", "expected the path of a token file");
      c.token_file = beside_scene(t.Scalar(), base);
    }
    m.reject_unknown();
    scene.console = c;
  }
  if (YAML::Node n = root.child("content_folder", false)) {
    if (!n.IsScalar() || n.Scalar().empty()) root.fail(n, "content_folder", "expected the path of a folder of videos");
    scene.content_folder = beside_scene(n.Scalar(), base);
    std::error_code ec;
    if (!std::filesystem::is_directory(scene.content_folder, ec))
      root.fail(n, "content_folder", scene.content_folder.string() + " is not a folder");
  }
  if (YAML::Node n = root.child("osc", false)) {
    MapReader m(n, "osc", root.file());
    OscSite o;
    o.port = m.get<int>("port", 0, true);
    if (o.port < 1 || o.port > 65535) m.fail(n["port"], "osc.port", "must be 1..65535");
    if (YAML::Node a = m.child("allow", false)) {
      if (!a.IsSequence()) m.fail(a, "osc.allow", "expected a list of hosts");
      for (const auto& h : a) {
        if (!h.IsScalar() || h.Scalar().empty()) m.fail(h, "osc.allow", "expected a host name or address");
        o.allow.push_back(h.Scalar());
      }
    }
    o.send = m.get<std::string>("send", "");
    m.reject_unknown();
    scene.osc = o;
  }
}

// `calibration: calib.yaml` (issue 13's output): the projector's intrinsics A_p and the camera-to-projector
// extrinsics R_cp, T_cp as a calibration measured them; they replace the scene's own.
void apply_calibration(MapReader& root, Scene& scene, const std::filesystem::path& base) {
  YAML::Node node = root.child("calibration", false);
  if (!node) return;
  if (!node.IsScalar() || node.Scalar().empty()) root.fail(node, "calibration", "expected the path of a calibration file");
  // One source for each value: the calibration's are not also given in the scene.
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"})
    if (root.has("projector") && root.child("projector", false)[key])
      root.fail(node, "calibration", std::string("projector.") + key + " is the calibration's; leave it out of the scene");
  if (YAML::Node robot = root.child("robot", false);
      robot && robot.IsMap() && robot["pan_tilt"] && robot["pan_tilt"].IsMap() && robot["pan_tilt"]["projector_from_camera"])
    root.fail(node, "calibration", "robot.pan_tilt.projector_from_camera is the calibration's; leave it out of the scene");
  const std::filesystem::path path = beside_scene(node.Scalar(), base);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    root.fail(node, "calibration", "cannot open '" + path.string() + "': not a file");
  if (std::filesystem::file_size(path, ec) > (1U << 20))
    root.fail(node, "calibration", "'" + path.string() + "' is larger than 1 MB: not a calibration file");
  std::ifstream probe(path, std::ios::binary);
  if (!probe) root.fail(node, "calibration", "cannot open '" + path.string() + "'");
  const ProjectorCalibration c = load_calibration(path);
  scene.calibration = path;
  if (c.photometry)
    for (const char* key : {"gamma", "gamma_rgb", "mixing", "black_level", "brightness_lm"})
      if (root.has("projector") && root.child("projector", false)[key])
        root.fail(node, "calibration",
                  std::string("projector.") + key + " is the calibration's photometry; leave it out of the scene");
  static_cast<Pinhole&>(scene.projector) = c.projector;
  scene.projector.distortion = c.projector.distortion;
  if (c.photometry) {
    const double lumens = scene.projector.photometry.brightness_lm;
    scene.projector.photometry = *c.photometry;
    if (!c.photometry_brightness) scene.projector.photometry.brightness_lm = lumens;
  }
  scene.pan_tilt.T_projector_camera = c.T_projector_camera;
}

}  // namespace

ProjectorCalibration load_calibration(const std::filesystem::path& path) {
  const std::string file = path.string();
  const YAML::Node c = load_yaml_file(path, 1U << 20, "a calibration file");
  if (!c || c.IsNull()) throw ConfigError(file + ": the calibration file is empty");
  MapReader r(c, "", file);
  MapReader p(r.child("projector", true), "projector", file);
  ProjectorCalibration out;
  ProjectorConfig k;
  k.width_px = p.get<int>("width", 0, true);
  k.height_px = p.get<int>("height", 0, true);
  k.fx_px = p.get<double>("fx", 0.0, true);
  k.fy_px = p.get<double>("fy", 0.0, true);
  k.cx_px = p.get<double>("cx", 0.0, true);
  k.cy_px = p.get<double>("cy", 0.0, true);
  if (YAML::Node d = p.child("distortion", false)) k.distortion = read_distortion(p, d, "projector.distortion");
  p.reject_unknown();
  try {
    validate_projector(k, "projector");
  } catch (const ConfigError& e) {
    r.fail(c["projector"], "", e.what());
  }
  out.projector = k;
  out.T_projector_camera = read_pose(r, "projector_from_camera", "projector_from_camera");
  if (!c["projector_from_camera"]) r.fail(c, "projector_from_camera", "missing required key");
  if (YAML::Node rms = r.child("reprojection_rms_px", false)) {  // what the calibration measured: informational here
    MapReader m(rms, "reprojection_rms_px", file);
    m.get<double>("camera", 0.0);
    m.get<double>("projector", 0.0);
    m.reject_unknown();
  }
  if (YAML::Node ph = r.child("photometry", false)) {
    out.photometry = read_calibrated_photometry(r, ph);
    out.photometry_brightness = static_cast<bool>(ph["brightness_lm"]);
  }
  // What `projbot calibrate solve` also reports: the colour camera's own lens (the depth camera is the
  // scene's `camera:`), the projector area covered, the views and warnings. Informational here.
  for (const char* key : {"camera", "projector_coverage", "views", "warnings", "board_poses"}) r.child(key, false);
  r.reject_unknown();
  return out;
}

namespace {

// `room:`: its size, wall height and obstacles.
void read_room(MapReader& r, const std::string& file, Scene& scene) {
  YAML::Node room = r.child("room", false);
  if (!room) return;
  MapReader m(room, "room", file);
  scene.room.width_m = m.get<double>("width", 0.0, true);
  scene.room.depth_m = m.get<double>("depth", 0.0, true);
  if (!(scene.room.width_m > 0.5) || !(scene.room.depth_m > 0.5) || scene.room.width_m > 200 || scene.room.depth_m > 200)
    m.fail(room, "room", "width and depth must be 0.5..200 m");
  scene.room.wall_height_m = m.get<double>("wall_height", scene.room.wall_height_m);
  if (!(scene.room.wall_height_m >= 0.1 && scene.room.wall_height_m <= 50.0))
    m.fail(room["wall_height"], "room.wall_height", "must be 0.1..50 m");
  scene.room.ambient_lux = m.get<double>("ambient_lux", scene.room.ambient_lux);
  if (!(scene.room.ambient_lux >= 0.0 && scene.room.ambient_lux <= 1e5))
    m.fail(room["ambient_lux"], "room.ambient_lux", "must be 0..100000 lux");
  if (YAML::Node obs = m.child("obstacles", false)) {
    if (!obs.IsSequence()) m.fail(obs, "room.obstacles", "expected a list of [x0, y0, x1, y1]");
    for (std::size_t i = 0; i < obs.size(); ++i) {
      const auto v = m.numbers(obs[i], "room.obstacles[" + std::to_string(i) + "]", 4);
      if (!(v[0] < v[2]) || !(v[1] < v[3]))
        m.fail(obs[i], "room.obstacles[" + std::to_string(i) + "]", "need x0 < x1 and y0 < y1");
      scene.room.obstacles.push_back({v[0], v[1], v[2], v[3]});
    }
  }
  m.reject_unknown();
}

// A target's `markers:` and `motion:` (one scripted move, or a list of them, one per visit at most).
void read_markers_and_motions(MapReader& t, const std::string& path, const std::string& file, TargetConfig& target) {
  if (YAML::Node mk = t.child("markers", false)) {
    if (!mk.IsSequence() || mk.size() == 0) t.fail(mk, path + ".markers", "expected a non-empty list of [x, y, z]");
    for (std::size_t k = 0; k < mk.size(); ++k)
      target.markers_m.push_back(t.vector3(mk[k], path + ".markers[" + std::to_string(k) + "]"));
  }
  if (YAML::Node mo = t.child("motion", false)) {
    const bool list = mo.IsSequence();
    for (std::size_t k = 0; k < (list ? mo.size() : 1); ++k) {
      const std::string where = path + ".motion" + (list ? "[" + std::to_string(k) + "]" : "");
      TargetMotion motion = read_motion(list ? mo[k] : mo, where, file);
      if (target.motion_on(motion.visit))
        t.fail(list ? mo[k] : mo, where, "visit " + std::to_string(motion.visit) + " already has a motion");
      target.motions.push_back(motion);
    }
  }
}

// One entry of `targets:` (`names` so far: a duplicate is refused).
TargetConfig read_target(const YAML::Node& node, const std::string& path, const std::string& file,
                         const std::filesystem::path& base, const Scene& scene, std::set<std::string>& names) {
  MapReader t(node, path, file);
  TargetConfig target;
  target.name = t.get<std::string>("name", "", true);
  if (target.name.empty()) t.fail(node, path + ".name", "must not be empty");
  if (!names.insert(target.name).second) t.fail(node, path + ".name", "duplicate target name '" + target.name + "'");
  read_model_ref(t, node, path, base, target.model, target.scale, target.recenter);
  target.present = t.get<bool>("present", true);
  target.support = read_support(t, path + ".support");
  target.surface = read_surface(t, path + ".surface", base);
  target.content = read_content(t, path + ".content", base);
  target.T_projector_target = read_pose(t, path + ".pose");
  if (t.has("world_pose")) target.T_world_target = read_pose(t, path + ".world_pose", "world_pose");
  if (t.has("map_pose")) {
    if (!target.T_world_target) t.fail(node["map_pose"], path + ".map_pose", "needs world_pose too");
    target.T_map_target = read_pose(t, path + ".map_pose", "map_pose");
  }
  if (YAML::Node st = t.child("stop", false)) {
    target.stop = t.vector3(st, path + ".stop");
    target.stop->z() = radians(target.stop->z());
    if (const std::string why = place_problem(scene.room, target.stop->x(), target.stop->y()); !why.empty())
      t.fail(st, path + ".stop", "the robot's stop for '" + target.name + "' " + why);
  }
  read_markers_and_motions(t, path, file, target);
  t.reject_unknown();
  return target;
}

// `targets:`, each with a pose or a world pose.
void read_targets(MapReader& r, const std::string& file, const std::filesystem::path& base, Scene& scene) {
  YAML::Node targets = r.child("targets", true);
  if (!targets.IsSequence()) r.fail(targets, "targets", "expected a list of targets");
  std::set<std::string> names;
  for (std::size_t i = 0; i < targets.size(); ++i)
    scene.targets.push_back(read_target(targets[i], "targets[" + std::to_string(i) + "]", file, base, scene, names));
  for (std::size_t i = 0; i < targets.size(); ++i)  // after the keys and names are known to be right
    if (!targets[i]["pose"] && !scene.targets[i].T_world_target)
      r.fail(targets[i], "targets[" + std::to_string(i) + "]",
             "needs a pose (where it stands in the projector frame) or a world_pose (a tour's map frame)");
}

// `props:`, named apart from the targets and each other.
void read_props(MapReader& r, const std::string& file, const std::filesystem::path& base, Scene& scene) {
  YAML::Node props = r.child("props", false);
  if (!props) return;
  if (!props.IsSequence()) r.fail(props, "props", "expected a list of props");
  std::set<std::string> prop_names;
  for (std::size_t i = 0; i < props.size(); ++i) {
    const std::string path = "props[" + std::to_string(i) + "]";
    scene.props.push_back(read_prop(props[i], path, file, base));
    if (!prop_names.insert(scene.props.back().name).second || scene.target_index(scene.props.back().name) >= 0)
      r.fail(props[i], path + ".name", "'" + scene.props.back().name + "' is already the name of a target or prop");
  }
}

// `tour: {visits: [...]}`: targets by name, each with a world pose and a stop.
void read_tour(MapReader& r, const std::string& file, Scene& scene) {
  YAML::Node tour = r.child("tour", false);
  if (!tour) return;
  MapReader m(tour, "tour", file);
  YAML::Node visits = m.child("visits", true);
  if (!visits.IsSequence() || visits.size() == 0) m.fail(visits, "tour.visits", "expected a non-empty list of target names");
  for (std::size_t i = 0; i < visits.size(); ++i) {
    const std::string name = visits[i].IsScalar() ? visits[i].Scalar() : std::string();
    const int index = scene.target_index(name);
    if (index < 0) m.fail(visits[i], "tour.visits[" + std::to_string(i) + "]", "no target named '" + name + "'");
    const TargetConfig& t = scene.targets[static_cast<std::size_t>(index)];
    if (!t.T_world_target || !t.stop)
      m.fail(visits[i], "tour.visits[" + std::to_string(i) + "]",
             "target '" + name + "' needs world_pose and stop to be visited");
    scene.visits.push_back(name);
  }
  m.reject_unknown();
}

Scene parse_scene_nodes(std::string_view yaml_text, const std::filesystem::path& source) {
  const std::string file = source.empty() ? std::string("<scene>") : source.string();
  if (const std::string problem = yaml_text_problem(yaml_text, file); !problem.empty()) throw ConfigError(problem);
  YAML::Node root;
  try {
    root = YAML::Load(std::string(yaml_text));
  } catch (const YAML::ParserException& e) {
    throw ConfigError(yaml_error_message(e, file));
  }
  if (!root || root.IsNull()) throw ConfigError(file + ": the scene file is empty");

  Scene scene;
  scene.source = source;
  MapReader r(root, "", file);
  // With a calibration file, the scene's projector section only adds what a calibration does not measure.
  scene.projector =
      read_pinhole(r, "projector", r.has("calibration") ? std::optional<ProjectorConfig>(ProjectorConfig{}) : std::nullopt);
  scene.pan_tilt = read_robot(r, scene);
  scene.depth_camera = read_pinhole(r, "camera", ProjectorConfig(Scene::kinect_v1_depth_camera()));
  read_room(r, file, scene);
  if (root["robot"] && root["robot"].IsMap() && root["robot"]["start"]) {
    if (const std::string why = place_problem(scene.room, scene.robot_start.x(), scene.robot_start.y()); !why.empty())
      r.fail(root["robot"]["start"], "robot.start", "the robot's start " + why);
  }
  const std::filesystem::path base = source.empty() ? std::filesystem::path() : source.parent_path();
  read_targets(r, file, base, scene);
  read_props(r, file, base, scene);
  scene.devices = read_devices(r);
  read_operator(r, base, scene);
  read_fleet(r, scene);
  apply_calibration(r, scene, base);
  read_tour(r, file, scene);
  r.reject_unknown();
  // Last, so that a value the reader refuses is named first: a key given twice reads as its first.
  if (const std::string twice = duplicate_key_message(root, file); !twice.empty()) throw ConfigError(twice);
  return scene;
}

}  // namespace

int Scene::target_index(std::string_view name) const {
  for (std::size_t i = 0; i < targets.size(); ++i)
    if (targets[i].name == name) return static_cast<int>(i);
  return -1;
}

Scene load_scene(const std::filesystem::path& path) {
  // Checked by kind before it is opened: a FIFO would block open(), /dev/zero never end.
  if (const std::string problem = input_file_problem(path); !problem.empty())
    throw ConfigError(path.string() + ": " + problem + (problem == "is a folder, not a file" ? " (a scene file, .yaml)" : ""));
  return parse_scene(read_yaml_text(path, 16U << 20, "a scene file"), path);
}

Scene parse_scene(std::string_view yaml_text, const std::filesystem::path& source) {
  try {
    return parse_scene_nodes(yaml_text, source);
  } catch (const YAML::Exception& e) {  // what the readers above do not name themselves (a fuzzer found one)
    const std::string file = source.empty() ? std::string("<scene>") : source.string();
    throw ConfigError(file + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) : std::string()) + ": " + e.msg);
  }
}

}  // namespace projbot::config
