#include "target_reader.hpp"

#include <cmath>

namespace projbot::config {
namespace {

// An optional list of n numbers at `name` in a timeline key, each within [lo, hi].
template <std::size_t N>
std::optional<std::array<double, N>> key_numbers(MapReader& key, const YAML::Node& node, const std::string& where,
                                                 const char* name, double lo, double hi, const char* range) {
  const YAML::Node f = key.child(name, false);
  if (!f) return std::nullopt;
  const auto v = key.numbers(f, where + "." + name, N);
  std::array<double, N> out{};
  for (std::size_t i = 0; i < N; ++i) {
    if (!(v[i] >= lo && v[i] <= hi)) key.fail(node[name], where + "." + name, range);
    out[i] = v[i];
  }
  return out;
}

TargetContent::Key read_key(MapReader& key, const YAML::Node& node, const std::string& where) {
  TargetContent::Key out;
  out.at_s = key.get<double>("at_s", 0.0, true);
  if (!(out.at_s >= 0.0 && out.at_s <= 1e6)) key.fail(node["at_s"], where + ".at_s", "must be 0..1e6 seconds");
  out.base_color_factor = key_numbers<4>(key, node, where, "base_color_factor", 0.0, 1.0, "each of r, g, b, a must be 0..1");
  out.emissive_factor = key_numbers<3>(key, node, where, "emissive_factor", 0.0, 1.0, "each of r, g, b must be 0..1");
  out.uv_offset = key_numbers<2>(key, node, where, "uv_offset", -1e6, 1e6, "each of u, v must be -1e6..1e6");
  out.uv_scale = key_numbers<2>(key, node, where, "uv_scale", -1e6, 1e6, "each of u, v must be -1e6..1e6");
  if (key.has("uv_rotation_deg")) {
    out.uv_rotation_deg = key.get<double>("uv_rotation_deg", 0.0);
    if (!(std::abs(*out.uv_rotation_deg) <= 1e6))
      key.fail(node["uv_rotation_deg"], where + ".uv_rotation_deg", "must be -1e6..1e6 degrees");
  }
  key.reject_unknown();
  return out;
}

// Which of a key's properties it gives, as a word each.
std::string given(const TargetContent::Key& k) {
  std::string out;
  const auto add = [&](bool has, const char* name) {
    if (has) out += (out.empty() ? "" : ", ") + std::string(name);
  };
  add(k.base_color_factor.has_value(), "base_color_factor");
  add(k.emissive_factor.has_value(), "emissive_factor");
  add(k.uv_offset.has_value(), "uv_offset");
  add(k.uv_scale.has_value(), "uv_scale");
  add(k.uv_rotation_deg.has_value(), "uv_rotation_deg");
  return out;
}

// `content.timeline`: keys of a material's properties over content time, times increasing, each key giving
// the same properties.
std::vector<TargetContent::Key> read_timeline(MapReader& m, const YAML::Node& list, const std::string& path) {
  if (!list.IsSequence() || list.size() == 0)
    m.fail(list, path, "expected a non-empty list of {at_s: S, base_color_factor: [r, g, b, a], ...}");
  std::vector<TargetContent::Key> keys;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string where = path + "[" + std::to_string(k) + "]";
    MapReader key(list[k], where, m.file());
    TargetContent::Key out = read_key(key, list[k], where);
    if (!keys.empty() && !(out.at_s > keys.back().at_s))
      key.fail(list[k]["at_s"], where + ".at_s", "must come after the key before it (times increase)");
    if (given(out).empty())
      key.fail(list[k], where,
               "gives nothing to animate: base_color_factor, emissive_factor, uv_offset, uv_scale or uv_rotation_deg");
    if (!keys.empty() && given(out) != given(keys.front()))
      key.fail(
          list[k], where,
          "gives " + given(out) + " but the first key gives " + given(keys.front()) + ": every key gives the same properties");
    keys.push_back(out);
  }
  return keys;
}

}  // namespace

// A target's `surface: {albedo: [r, g, b]}` (linear reflectance, each 0..1) or `surface: {texture: F}`
// (a picture of it over the model's UVs, beside the scene; read where it is used).
TargetSurface read_surface(MapReader& t, const std::string& path, const std::filesystem::path& base) {
  TargetSurface surface;
  YAML::Node node = t.child("surface", false);
  if (!node) return surface;
  MapReader m(node, path, t.file());
  if (m.has("texture")) {
    if (m.has("albedo")) m.fail(node["albedo"], m.key_path("albedo"), "give surface.albedo or surface.texture, not both");
    const auto texture = m.get<std::string>("texture", "");
    if (texture.empty()) m.fail(node["texture"], m.key_path("texture"), "must not be empty");
    surface.texture = beside_scene(texture, base);
    surface.albedo = Eigen::Vector3d::Ones();  // the texture carries it
    m.reject_unknown();
    return surface;
  }
  const YAML::Node albedo = m.child("albedo", true);
  surface.albedo = m.vector3(albedo, m.key_path("albedo"));
  if (!((surface.albedo.array() >= 0.0).all() && (surface.albedo.array() <= 1.0).all()))
    m.fail(albedo, m.key_path("albedo"), "each of r, g, b must be 0..1 (linear reflectance)");
  m.reject_unknown();
  return surface;
}

// A target's `content: {video: F, material: NAME_OR_INDEX, loop: B, start: arrival | tour | SECONDS, timeline: [...]}`.
std::optional<TargetContent> read_content(MapReader& t, const std::string& path, const std::filesystem::path& base) {
  YAML::Node node = t.child("content", false);
  if (!node) return std::nullopt;
  MapReader m(node, path, t.file());
  TargetContent c;
  if (m.has("video")) {
    const auto video = m.get<std::string>("video", "");
    if (video.empty()) m.fail(node["video"], m.key_path("video"), "must not be empty");
    c.video = beside_scene(video, base);
  }
  if (YAML::Node tl = m.child("timeline", false)) c.timeline = read_timeline(m, tl, m.key_path("timeline"));
  if (c.video.empty() && c.timeline.empty()) m.fail(node, path, "needs a video or a timeline (or both): nothing would move");
  c.material = m.get<std::string>("material", "");
  c.loop = m.get<bool>("loop", true);
  if (YAML::Node st = m.child("start", false)) {
    if (!st.IsScalar()) m.fail(st, m.key_path("start"), "expected arrival, tour or seconds after the tour began");
    double at = 0.0;
    if (st.Scalar() == "arrival") {
      c.start = TargetContent::Start::kArrival;
    } else if (st.Scalar() == "tour") {
      c.start = TargetContent::Start::kTour;
    } else if (YAML::convert<double>::decode(st, at) && at >= 0.0 && at <= 1e6) {
      c.start = TargetContent::Start::kAt;
      c.at_s = at;
    } else {
      m.fail(st, m.key_path("start"), "expected arrival, tour or 0..1e6 seconds after the tour began, not '" + st.Scalar() + "'");
    }
  }
  m.reject_unknown();
  return c;
}

TargetMotion read_motion(const YAML::Node& mo, const std::string& path, const std::string& file) {
  MapReader m(mo, path, file);
  TargetMotion motion;
  motion.visit = m.get<int>("visit", motion.visit);
  if (motion.visit < 1) m.fail(mo["visit"], m.key_path("visit"), "must be >= 1");
  motion.start_s = m.get<double>("start_s", motion.start_s);
  motion.duration_s = m.get<double>("duration_s", motion.duration_s);
  if (motion.start_s < 0.0 || !(motion.duration_s > 0.0)) m.fail(mo, path, "need start_s >= 0 and duration_s > 0");
  if (YAML::Node tr = m.child("translation", false)) motion.translation_m = m.vector3(tr, m.key_path("translation"));
  if (YAML::Node rpy = m.child("rpy_deg", false)) motion.rpy_deg = m.vector3(rpy, m.key_path("rpy_deg"));
  const std::string profile = m.get<std::string>("profile", "smooth");
  if (profile == "constant")
    motion.profile = MotionProfile::constant;
  else if (profile == "accelerate")
    motion.profile = MotionProfile::accelerate;
  else if (profile != "smooth")
    m.fail(mo["profile"], m.key_path("profile"), "must be smooth, constant or accelerate, not '" + profile + "'");
  motion.stays = m.get<bool>("stays", false);
  motion.removed = m.get<bool>("removed", false);
  if (motion.removed && motion.stays) m.fail(mo, path, "a removed target cannot also stay: choose one");
  m.reject_unknown();
  return motion;
}

}  // namespace projbot::config
