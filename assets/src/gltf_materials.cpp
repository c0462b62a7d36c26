// glTF materials: base colour and emission, their textures, samplers and KHR_texture_transform, checked.

#include <cmath>

#include "gltf_reader.hpp"

namespace projbot::assets::detail {
namespace {

Wrap wrap_of(int mode) {
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
      return Wrap::kClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
      return Wrap::kMirroredRepeat;
    default:
      return Wrap::kRepeat;
  }
}

// A material's texture (`slot`: "baseColorTexture", "emissiveTexture"): its decoded image's index, and its
// sampler into `sampler`; -1 where the material has none.
int texture_image(const GltfReader& r, const Model& out, const tinygltf::TextureInfo& info, const std::string& name,
                  const std::string& slot, Sampler& sampler) {
  const int tex = info.index;
  if (tex < 0) return -1;
  const tinygltf::Model& g = r.document();
  r.check_index(tex, g.textures, name + ": " + slot);
  const auto& t = g.textures[static_cast<std::size_t>(tex)];
  r.check_index(t.source, g.images, name + ": texture " + std::to_string(tex) + " source image");
  if (out.images[static_cast<std::size_t>(t.source)].rgba.empty()) {
    const auto& uri = g.images[static_cast<std::size_t>(t.source)].uri;
    r.fail(name + ": " + (slot == "baseColorTexture" ? "base colour" : "emissive") + " image " + std::to_string(t.source) +
           (uri.empty() || uri.rfind("data:", 0) == 0 ? "" : " ('" + uri + "')") + " is missing or could not be decoded");
  }
  if (info.texCoord != 0)
    r.fail(name + ": " + slot + " uses TEXCOORD_" + std::to_string(info.texCoord) + "; only TEXCOORD_0 is supported");
  if (t.sampler >= 0) {
    r.check_index(t.sampler, g.samplers, name + ": sampler");
    const auto& s = g.samplers[static_cast<std::size_t>(t.sampler)];
    sampler.wrap_s = wrap_of(s.wrapS);
    sampler.wrap_t = wrap_of(s.wrapT);
    sampler.mag = s.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST ? Filter::kNearest : Filter::kLinear;
    sampler.min =
        (s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST || s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST ||
         s.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR)
            ? Filter::kNearest
            : Filter::kLinear;
  }
  return t.source;
}

// KHR_texture_transform in a texture's extensions; identity without it.
TextureTransform texture_transform(const GltfReader& r, const tinygltf::ExtensionMap& ext, const std::string& name) {
  TextureTransform out;
  const auto it = ext.find("KHR_texture_transform");
  if (it == ext.end()) return out;
  const tinygltf::Value& t = it->second;
  if (!t.IsObject()) r.fail(name + ": KHR_texture_transform is not an object");
  const auto pair = [&](const char* key, std::array<double, 2>& into) {
    if (!t.Has(key)) return;
    const tinygltf::Value& v = t.Get(key);
    if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
      r.fail(name + ": KHR_texture_transform." + key + " is not two numbers");
    into = {v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble()};
  };
  pair("offset", out.offset);
  pair("scale", out.scale);
  if (t.Has("rotation")) {
    if (!t.Get("rotation").IsNumber()) r.fail(name + ": KHR_texture_transform.rotation is not a number");
    out.rotation_rad = t.Get("rotation").GetNumberAsDouble();
  }
  if (t.Has("texCoord") && t.Get("texCoord").GetNumberAsInt() != 0)
    r.fail(name + ": KHR_texture_transform.texCoord names another UV set; only TEXCOORD_0 is supported");
  for (const double x : {out.offset[0], out.offset[1], out.scale[0], out.scale[1], out.rotation_rad})
    if (!std::isfinite(x) || std::abs(x) > 1e6) r.fail(name + ": KHR_texture_transform has a value that is not finite");
  return out;
}

// emissiveFactor and KHR_materials_emissive_strength.
void read_emission(const GltfReader& r, const tinygltf::Material& gm, const std::string& name, Material& m) {
  if (gm.emissiveFactor.size() == 3)
    for (std::size_t k = 0; k < 3; ++k) {
      if (!std::isfinite(gm.emissiveFactor[k]) || gm.emissiveFactor[k] < 0.0)
        r.fail(name + ": emissiveFactor must be three finite numbers >= 0");
      m.emissive_factor[k] = static_cast<float>(gm.emissiveFactor[k]);
    }
  const auto it = gm.extensions.find("KHR_materials_emissive_strength");
  if (it == gm.extensions.end()) return;
  const tinygltf::Value& e = it->second;
  if (!e.IsObject()) r.fail(name + ": KHR_materials_emissive_strength is not an object");
  if (!e.Has("emissiveStrength")) return;
  const tinygltf::Value& v = e.Get("emissiveStrength");
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()) || v.GetNumberAsDouble() < 0.0 || v.GetNumberAsDouble() > 1e6)
    r.fail(name + ": KHR_materials_emissive_strength.emissiveStrength must be a number 0..1e6");
  m.emissive_strength = static_cast<float>(v.GetNumberAsDouble());
}

void read_alpha(const GltfReader& r, const tinygltf::Material& gm, const std::string& name, Material& m) {
  if (gm.alphaMode == "MASK")
    m.alpha_mode = AlphaMode::kMask;
  else if (gm.alphaMode == "BLEND")
    m.alpha_mode = AlphaMode::kBlend;
  else if (gm.alphaMode.empty() || gm.alphaMode == "OPAQUE")
    m.alpha_mode = AlphaMode::kOpaque;
  else
    r.fail(name + ": alphaMode '" + gm.alphaMode + "' is not OPAQUE, MASK or BLEND");
  if (!std::isfinite(gm.alphaCutoff) || gm.alphaCutoff < 0.0) r.fail(name + ": alphaCutoff must be a finite number >= 0");
  m.alpha_cutoff = static_cast<float>(gm.alphaCutoff);
}

}  // namespace

void read_materials(const GltfReader& r, Model& out) {
  const tinygltf::Model& g = r.document();
  for (std::size_t i = 0; i < g.materials.size(); ++i) {
    const auto& gm = g.materials[i];
    const std::string name = "material " + std::to_string(i);
    Material m;
    m.name = gm.name;
    const auto& f = gm.pbrMetallicRoughness.baseColorFactor;
    if (f.size() == 4)
      for (std::size_t k = 0; k < 4; ++k) {
        if (!(f[k] >= 0.0 && f[k] <= 1.0))  // NaN too; glTF's range, which the renderer and compensation assume
          r.fail(name + ": baseColorFactor must be four numbers within 0..1 (glTF's range), not " + std::to_string(f[k]));
        m.base_color_factor[k] = static_cast<float>(f[k]);
      }
    const auto& base = gm.pbrMetallicRoughness.baseColorTexture;
    m.base_color_image = texture_image(r, out, base, name, "baseColorTexture", m.sampler);
    m.base_color_transform = texture_transform(r, base.extensions, name);
    read_emission(r, gm, name, m);
    m.emissive_image = texture_image(r, out, gm.emissiveTexture, name, "emissiveTexture", m.emissive_sampler);
    m.emissive_transform = texture_transform(r, gm.emissiveTexture.extensions, name + " emissiveTexture");
    read_alpha(r, gm, name, m);
    m.double_sided = gm.doubleSided;
    out.materials.push_back(m);
  }
}

void bake_texture_transforms(Model& out) {
  for (auto& p : out.primitives) {
    if (p.material < 0 || static_cast<std::size_t>(p.material) >= out.materials.size()) continue;
    const TextureTransform& t = out.materials[static_cast<std::size_t>(p.material)].base_color_transform;
    if (t == TextureTransform{}) continue;
    const auto m = t.matrix();
    for (auto& v : p.vertices) {
      const double u = v.uv[0], w = v.uv[1];
      v.uv = {static_cast<float>(m[0] * u + m[1] * w + m[2]), static_cast<float>(m[3] * u + m[4] * w + m[5])};
    }
  }
}

}  // namespace projbot::assets::detail
