#pragma once
// What both model loaders share (glTF, and the meshes Assimp reads): the file's kind, and the step they
// end with.

#include <cctype>
#include <filesystem>
#include <string>

#include "projbot/assets/model.hpp"

namespace projbot::assets::detail {

/// The file's extension in lower case, with its dot (".obj"); empty where it has none.
inline std::string lowercase_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// Primitives without a material (index < 0) get one default material, added once at the end.
inline void give_default_material(Model& model) {
  bool need_default = false;
  for (auto& p : model.primitives)
    if (p.material < 0) {
      p.material = static_cast<int>(model.materials.size());
      need_default = true;
    }
  if (need_default) model.materials.emplace_back();
}

}  // namespace projbot::assets::detail
