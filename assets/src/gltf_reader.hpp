#pragma once
// Internal to assets: what every part of the glTF loader reads a tinygltf document through (gltf_loader.cpp
// the meshes, gltf_materials.cpp the materials, gltf_animation.cpp their animations). Every index, offset and
// value is checked before use: a malformed file is an AssetError naming it, never a crash.

#include <tiny_gltf.h>

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "projbot/assets/model.hpp"

namespace projbot::assets::detail {

class GltfReader {
 public:
  GltfReader(const tinygltf::Model& gltf, std::string file) : g_(gltf), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& why) const { throw AssetError(file_ + ": " + why); }

  template <typename T>
  // 64-bit: an index read from JSON past int's range (4294967296) must not wrap into range.
  void check_index(long long index, const std::vector<T>& items, const std::string& what) const {
    if (index < 0 || static_cast<unsigned long long>(index) >= items.size())
      fail(what + " index " + std::to_string(index) + " is out of range (have " + std::to_string(items.size()) + ")");
  }

  /// An accessor's elements, checked to lie inside its buffer view and buffer.
  struct View {
    const unsigned char* base = nullptr;
    std::size_t stride = 0;
    std::size_t count = 0;
    int component_type = 0;
    int type = 0;
    bool normalized = false;
  };
  View accessor_view(int accessor_index, const std::string& what) const;

  /// Component c of element i as float, with glTF's normalisation rules (0 for a type the caller refused).
  static float read_component(const View& v, std::size_t i, int c);

  /// A warning on stderr, once per file and process (a tour loads its models several times).
  void warn_once(const std::string& what) const;

  const tinygltf::Model& document() const { return g_; }
  const std::string& file() const { return file_; }

 protected:
  const tinygltf::Model& g_;
  std::string file_;
};

}  // namespace projbot::assets::detail

namespace projbot::assets::detail {

/// The document's materials (its images already in `out.images`): base colour, emission
/// (KHR_materials_emissive_strength), their textures and samplers and KHR_texture_transform.
void read_materials(const GltfReader& reader, Model& out);

/// Each primitive's material's base colour transform baked into its texture coordinates.
void bake_texture_transforms(Model& out);

/// The document's KHR_animation_pointer channels on material properties into out.material_animations
/// (`json`: the document's JSON, which tinygltf drops such channels from). Channels on anything else are
/// said once and left; a malformed channel is an AssetError.
void read_material_animations(const GltfReader& reader, const std::string& json, Model& out);

}  // namespace projbot::assets::detail
