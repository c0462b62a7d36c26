// libFuzzer entry: any input must load or fail with AssetError; anything else (a crash, an ASan report,
// another exception type) is a finding.
#include "fuzz_input.hpp"
#include "projbot/assets/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto model = projbot::assets::load_gltf(projbot::fuzz::input_file(data, size, ".gltf"));
    for (const auto& p : model.primitives)
      for (auto i : p.indices)
        if (i >= p.vertices.size()) __builtin_trap();  // the loader promised in-range indices
    for (const double t : {-1.0, 0.0, 0.7, 1e3})       // its material animations played, whatever their keys
      for (const auto& [material, state] : projbot::assets::animate_materials(model, t))
        if (material < 0 || static_cast<std::size_t>(material) >= model.materials.size()) __builtin_trap();
  } catch (const projbot::assets::AssetError&) {
  }
  return 0;
}
