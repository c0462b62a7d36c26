#include "projbot/config/recording.hpp"

#include <algorithm>
#include <iomanip>

#include "map_reader.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/yaml_keys.hpp"

namespace projbot::config {
namespace {

// A string as a YAML double-quoted scalar.
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string triple(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << std::setprecision(17) << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return out.str();
}

// A path a recording's file names: relative, inside the folder.
bool inside_folder(const std::string& path) {
  return !path.empty() && path.front() != '/' && path.find("..") == std::string::npos;
}

RecordedStop read_stop(const YAML::Node& node, const std::string& path, const std::string& file) {
  MapReader r(node, path, file);
  RecordedStop s;
  s.visit = r.get<int>("visit", 0, true);
  s.target = r.get<std::string>("target", "", true);
  s.goal = r.vector3(r.child("goal", true), r.key_path("goal"));
  s.believed = r.vector3(r.child("believed", true), r.key_path("believed"));
  s.pan_rad = r.get<double>("pan_rad", 0.0, true);
  s.tilt_rad = r.get<double>("tilt_rad", 0.0, true);
  s.drive_s = r.get<double>("drive_s", 0.0, true);
  s.arrived = r.get<bool>("arrived", false, true);
  s.frames = r.get<std::string>("frames", "", true);
  s.frame_count = r.get<int>("frame_count", 0, true);
  if (!inside_folder(s.frames)) r.fail(node, r.key_path("frames"), "must name a folder inside the recording");
  if (s.frame_count < 1) r.fail(node, r.key_path("frame_count"), "a recorded stop has at least one frame");
  r.reject_unknown();
  return s;
}

// One `reflectance:` entry: a PNG inside the recording that is there, or an albedo [r, g, b] in 0..1.
TargetSurface read_learnt(const MapReader& r, const YAML::Node& value, const std::string& key,
                          const std::filesystem::path& folder) {
  TargetSurface surface;
  if (value.IsSequence()) {
    const auto v = r.numbers(value, key, 3);
    for (int ch = 0; ch < 3; ++ch)
      if (v[static_cast<std::size_t>(ch)] < 0.0 || v[static_cast<std::size_t>(ch)] > 1.0)
        r.fail(value, key, "an albedo is 0..1 per channel");
    surface.albedo = {v[0], v[1], v[2]};
    return surface;
  }
  if (!value.IsScalar() || !inside_folder(value.Scalar()))
    r.fail(value, key, "must name a PNG file inside the recording, or give an albedo [r, g, b]");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(folder / value.Scalar(), ec))
    r.fail(value, key, "no such file: " + (folder / value.Scalar()).string());
  surface.texture = value.Scalar();
  return surface;
}

// `reflectance:`, target name -> what was learnt of it.
std::map<std::string, TargetSurface> read_reflectance(MapReader& r, const std::filesystem::path& folder) {
  std::map<std::string, TargetSurface> out;
  const YAML::Node node = r.child("reflectance", false);
  if (!node) return out;
  if (!node.IsMap()) r.fail(node, "reflectance", "expected a map of target: file.png or [r, g, b]");
  for (const auto& kv : node) {
    const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    if (name.empty()) r.fail(kv.first, "reflectance", "a key must be a target's name");
    out[name] = read_learnt(r, kv.second, "reflectance." + name, folder);
  }
  return out;
}

}  // namespace

void use_learnt_reflectance(Scene& scene, const Recording& recording) {
  for (const auto& [name, learnt] : recording.reflectance) {
    const std::string& wanted = name;  // a structured binding is not captured by a lambda in clang's C++20
    const auto it =
        std::find_if(scene.targets.begin(), scene.targets.end(), [&](const TargetConfig& t) { return t.name == wanted; });
    if (it == scene.targets.end())
      throw ConfigError(recording.source.string() + ": reflectance." + name + ": " + scene.source.string() +
                        " has no target of that name");
    it->surface = learnt;
    if (!learnt.texture.empty()) it->surface.texture = recording.folder() / learnt.texture;
  }
}

std::string recording_yaml(const Recording& r) {
  std::ostringstream out;
  out << std::setprecision(17);
  out << "# projbot record: one fakenect dump per stop (stopNN/), the poses tracked in each frame (poses.csv)\n"
      << "format: 1\nscene: " << quoted(r.scene.string()) << "\ncamera: " << quoted(r.camera) << "\nseed: " << r.seed
      << "\ndwell_s: " << r.dwell_s << "\ninterrupted: " << (r.interrupted ? "true" : "false") << "\n";
  if (!r.laser.empty()) out << "laser: " << quoted(r.laser) << "\n";
  if (!r.reflectance.empty()) {
    out << "reflectance:\n";
    for (const auto& [name, learnt] : r.reflectance)
      out << "  " << quoted(name) << ": " << (learnt.texture.empty() ? triple(learnt.albedo) : quoted(learnt.texture.string()))
          << "\n";
  }
  out << "stops:\n";
  if (r.stops.empty()) out << "  []\n";
  for (const RecordedStop& s : r.stops)
    out << "  - {visit: " << s.visit << ", target: " << quoted(s.target) << ", goal: " << triple(s.goal)
        << ", believed: " << triple(s.believed) << ", pan_rad: " << s.pan_rad << ", tilt_rad: " << s.tilt_rad
        << ", drive_s: " << s.drive_s << ", arrived: " << (s.arrived ? "true" : "false") << ", frames: " << quoted(s.frames)
        << ", frame_count: " << s.frame_count << "}\n";
  return out.str();
}

Recording load_recording(const std::filesystem::path& folder) {
  const std::string file = (folder / "recording.yaml").string();
  if (const std::string why = input_folder_problem(folder); !why.empty())
    throw ConfigError(folder.string() + ": " + (why == "no such folder" ? "no such recording folder" : why) +
                      " (projbot record --out writes one)");
  if (input_file_problem(file) == "does not exist")
    throw ConfigError(file + ": does not exist (not a recording made by projbot record?)");
  const YAML::Node root = load_yaml_file(file, 16U << 20, "a recording's manifest");
  MapReader r(root, "", file);
  Recording rec;
  rec.source = file;
  if (r.get<int>("format", 0, true) != 1) r.fail(r.child("format", true), "format", "unknown recording format (1 is read)");
  rec.scene = r.get<std::string>("scene", "", true);
  rec.camera = r.get<std::string>("camera", "", true);
  rec.seed = static_cast<std::uint64_t>(r.get<long long>("seed", 0, true));
  rec.dwell_s = r.get<double>("dwell_s", 0.0, true);
  rec.interrupted = r.get<bool>("interrupted", false, true);
  rec.laser = r.get<std::string>("laser", "");
  rec.reflectance = read_reflectance(r, folder);
  const YAML::Node stops = r.child("stops", true);
  if (!stops.IsSequence()) r.fail(stops, "stops", "expected a list of stops");
  for (std::size_t k = 0; k < stops.size(); ++k)
    rec.stops.push_back(read_stop(stops[k], "stops[" + std::to_string(k) + "]", file));
  r.reject_unknown();
  if (rec.stops.empty()) throw ConfigError(file + ": the recording holds no stop");
  return rec;
}

}  // namespace projbot::config
