// glTF KHR_animation_pointer channels on material properties (issue 44). tinygltf 2.7 drops a channel whose
// target has no node, which is what a pointer channel is, so the channels are read from the document's JSON
// here; their samplers (times and values) are tinygltf's, read through the checked accessors.

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>

#include "gltf_reader.hpp"
#include "projbot/config/json_message.hpp"

namespace projbot::assets::detail {
namespace {

using Property = MaterialChannel::Property;
using json = nlohmann::json;

// The material and property a pointer names; none for anything else.
std::optional<std::pair<int, Property>> pointer_target(const std::string& pointer) {
  static const std::regex kMaterial(R"(^/materials/(\d{1,9})/(.+)$)");
  std::smatch m;
  if (!std::regex_match(pointer, m, kMaterial)) return std::nullopt;
  const int material = std::stoi(m[1].str());
  const std::string rest = m[2].str();
  static const std::pair<const char*, Property> kPaths[] = {
      {"pbrMetallicRoughness/baseColorFactor", Property::kBaseColorFactor},
      {"emissiveFactor", Property::kEmissiveFactor},
      {"extensions/KHR_materials_emissive_strength/emissiveStrength", Property::kEmissiveStrength},
      {"pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/offset", Property::kBaseColorOffset},
      {"pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/scale", Property::kBaseColorScale},
      {"pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/rotation", Property::kBaseColorRotation},
      {"emissiveTexture/extensions/KHR_texture_transform/offset", Property::kEmissiveOffset},
      {"emissiveTexture/extensions/KHR_texture_transform/scale", Property::kEmissiveScale},
      {"emissiveTexture/extensions/KHR_texture_transform/rotation", Property::kEmissiveRotation}};
  for (const auto& [path, property] : kPaths)
    if (rest == path) return std::make_pair(material, property);
  return std::nullopt;
}

MaterialChannel::Interpolation interpolation_of(const GltfReader& r, const std::string& name, const std::string& what) {
  if (name.empty() || name == "LINEAR") return MaterialChannel::Interpolation::kLinear;
  if (name == "STEP") return MaterialChannel::Interpolation::kStep;
  if (name == "CUBICSPLINE") return MaterialChannel::Interpolation::kCubicSpline;
  r.fail(what + ": interpolation '" + name + "' is not LINEAR, STEP or CUBICSPLINE");
}

// The channel's keys from sampler `s`: times increasing and finite, values finite and as many as glTF says.
void read_keys(const GltfReader& r, const tinygltf::AnimationSampler& s, const std::string& what, MaterialChannel& ch) {
  const GltfReader::View in = r.accessor_view(s.input, what + " input");
  if (in.type != TINYGLTF_TYPE_SCALAR || in.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT)
    r.fail(what + ": its input (times) must be float scalars");
  const int n = MaterialChannel::width(ch.property);
  static constexpr int kTypes[] = {0, TINYGLTF_TYPE_SCALAR, TINYGLTF_TYPE_VEC2, TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4};
  const GltfReader::View outv = r.accessor_view(s.output, what + " output");
  const bool floats = outv.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT || outv.normalized;
  if (outv.type != kTypes[n] || !floats)
    r.fail(what + ": its output must be " + std::to_string(n) + " float (or normalised) number(s) per key for its pointer");
  const std::size_t per_key = ch.interpolation == MaterialChannel::Interpolation::kCubicSpline ? 3 : 1;
  if (in.count == 0 || outv.count != in.count * per_key)
    r.fail(what + ": " + std::to_string(in.count) + " key times need " + std::to_string(in.count * per_key) + " values, not " +
           std::to_string(outv.count));
  for (std::size_t k = 0; k < in.count; ++k) {
    const float t = GltfReader::read_component(in, k, 0);
    if (!std::isfinite(t) || t < 0.0F || t > 1e6F || (k > 0 && !(t > ch.times.back())))
      r.fail(what + ": key time " + std::to_string(k) + " is not a finite time 0..1e6 s after the one before");
    ch.times.push_back(t);
  }
  for (std::size_t e = 0; e < outv.count; ++e)
    for (int c = 0; c < n; ++c) {
      const float v = GltfReader::read_component(outv, e, c);
      if (!std::isfinite(v) || std::abs(v) > 1e6F) r.fail(what + ": value " + std::to_string(e) + " is not finite");
      ch.values.push_back(v);
    }
}

// Channel `c` of animation `a` when it is a pointer to a material property we play; counts node channels.
std::optional<MaterialChannel> read_channel(const GltfReader& r, const json& c, std::size_t a, std::size_t index,
                                            std::size_t& node_channels) {
  const std::string what = "animation " + std::to_string(a) + " channel " + std::to_string(index);
  const json* target = c.is_object() && c.contains("target") ? &c["target"] : nullptr;
  if (target == nullptr || !target->is_object()) r.fail(what + ": has no target");
  const auto path = target->value("path", std::string());
  if (path != "pointer") {
    ++node_channels;
    return std::nullopt;
  }
  const json pointer = target->value(json::json_pointer("/extensions/KHR_animation_pointer/pointer"), json());
  if (!pointer.is_string()) r.fail(what + ": target path 'pointer' without a KHR_animation_pointer.pointer string");
  const auto property = pointer_target(pointer.get<std::string>());
  if (!property) {
    r.warn_once("animation pointer '" + pointer.get<std::string>() +
                "' is not played (only materials' base colour, emission and texture transforms are)");
    return std::nullopt;
  }
  const tinygltf::Model& g = r.document();
  r.check_index(property->first, g.materials, what + ": material");
  if (!c.contains("sampler") || !c["sampler"].is_number_integer()) r.fail(what + ": has no sampler index");
  const auto& samplers = g.animations[a].samplers;
  const long long sampler = c["sampler"].get<long long>();  // glTF's indices are unsigned 32-bit: never read as int
  r.check_index(sampler, samplers, what + ": sampler");
  const tinygltf::AnimationSampler& s = samplers[static_cast<std::size_t>(sampler)];
  MaterialChannel ch;
  ch.material = property->first;
  ch.property = property->second;
  ch.interpolation = interpolation_of(r, s.interpolation, what);
  read_keys(r, s, what, ch);
  return ch;
}

}  // namespace

void read_material_animations(const GltfReader& r, const std::string& json_text, Model& out) try {
  const json doc = json::parse(json_text, nullptr, false);
  const tinygltf::Model& g = r.document();
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("animations") || !doc["animations"].is_array()) return;
  const json& animations = doc["animations"];
  std::size_t node_channels = 0;
  // tinygltf kept every animation, in order, or refused the file.
  for (std::size_t a = 0; a < animations.size() && a < g.animations.size(); ++a) {
    const json& channels = animations[a].is_object() ? animations[a].value("channels", json::array()) : json::array();
    if (!channels.is_array()) r.fail("animation " + std::to_string(a) + ": channels is not a list");
    MaterialAnimation anim;
    anim.name = g.animations[a].name;
    for (std::size_t c = 0; c < channels.size(); ++c)
      if (auto ch = read_channel(r, channels[c], a, c, node_channels)) {
        anim.duration_s = std::max(anim.duration_s, static_cast<double>(ch->times.back()));
        anim.channels.push_back(std::move(*ch));
      }
    if (!anim.channels.empty()) out.material_animations.push_back(std::move(anim));
  }
  if (node_channels > 0)
    r.warn_once("its " + std::to_string(node_channels) +
                " node animation channel(s) are not played (the object does not move with them)");
} catch (const json::exception& e) {  // a channel's parts of the wrong JSON type
  r.fail("an animation channel is malformed: " + config::without_json_tag(e.what()));
}

}  // namespace projbot::assets::detail
