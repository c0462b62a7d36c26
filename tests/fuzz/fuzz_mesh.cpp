// libFuzzer entry for the mesh reader (Assimp, in its isolated child): any input, as PLY ("ply" first), STL
// ("solid" first, or binary by an odd first byte) or OBJ, must load or fail with AssetError; a model with an
// index out of range, a non-finite vertex or any other outcome is a finding.
#include <cmath>
#include <cstring>

#include "fuzz_input.hpp"
#include "projbot/assets/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto starts = [&](const char* word) {
    return size >= std::strlen(word) && std::memcmp(data, word, std::strlen(word)) == 0;
  };
  const char* extension = starts("ply") ? ".ply" : starts("solid") || (size > 0 && data[0] % 2 == 1) ? ".stl" : ".obj";
  try {
    const auto model = projbot::assets::load_mesh(projbot::fuzz::input_file(data, size, extension));
    for (const auto& p : model.primitives) {
      for (auto i : p.indices)
        if (i >= p.vertices.size()) __builtin_trap();
      for (const auto& v : p.vertices)
        if (!std::isfinite(v.position[0]) || !std::isfinite(v.position[1]) || !std::isfinite(v.position[2])) __builtin_trap();
      if (p.material < 0 || static_cast<std::size_t>(p.material) >= model.materials.size()) __builtin_trap();
    }
  } catch (const projbot::assets::AssetError&) {
  }
  return 0;
}
