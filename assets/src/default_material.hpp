#pragma once
// A step both model loaders end with (glTF, and the meshes Assimp reads).

#include "projbot/assets/model.hpp"

namespace projbot::assets::detail {

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
