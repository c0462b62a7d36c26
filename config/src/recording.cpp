#include "projbot/config/recording.hpp"

#include <iomanip>

#include "map_reader.hpp"
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
  if (s.frames.empty() || s.frames.find("..") != std::string::npos || s.frames.front() == '/')
    r.fail(node, r.key_path("frames"), "must name a folder inside the recording");
  if (s.frame_count < 1) r.fail(node, r.key_path("frame_count"), "a recorded stop has at least one frame");
  r.reject_unknown();
  return s;
}

}  // namespace

std::string recording_yaml(const Recording& r) {
  std::ostringstream out;
  out << std::setprecision(17);
  out << "# projbot record: one fakenect dump per stop (stopNN/), the poses tracked in each frame (poses.csv)\n"
      << "format: 1\nscene: " << quoted(r.scene.string()) << "\ncamera: " << quoted(r.camera) << "\nseed: " << r.seed
      << "\ndwell_s: " << r.dwell_s << "\ninterrupted: " << (r.interrupted ? "true" : "false") << "\n";
  if (!r.laser.empty()) out << "laser: " << quoted(r.laser) << "\n";
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
  std::error_code ec;
  if (!std::filesystem::is_directory(folder, ec))
    throw ConfigError(folder.string() + ": no such recording folder (projbot record --out writes one)");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw ConfigError(file + ": cannot read (not a recording made by projbot record?)");
  } catch (const YAML::Exception& e) {
    throw ConfigError(file + (e.mark.line >= 0 ? ":" + std::to_string(e.mark.line + 1) : std::string()) + ": " + e.msg);
  }
  if (const std::string twice = duplicate_key_message(root, file); !twice.empty()) throw ConfigError(twice);
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
  const YAML::Node stops = r.child("stops", true);
  if (!stops.IsSequence()) r.fail(stops, "stops", "expected a list of stops");
  for (std::size_t k = 0; k < stops.size(); ++k)
    rec.stops.push_back(read_stop(stops[k], "stops[" + std::to_string(k) + "]", file));
  r.reject_unknown();
  if (rec.stops.empty()) throw ConfigError(file + ": the recording holds no stop");
  return rec;
}

}  // namespace projbot::config
