// libFuzzer entry: any input must load or fail with AssetError; anything else (a crash, an ASan report,
// another exception type) is a finding.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "projbot/assets/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("projbot_fuzz_" + std::to_string(::getpid()) + ".gltf");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const auto model = projbot::assets::load_gltf(file);
    for (const auto& p : model.primitives)
      for (auto i : p.indices)
        if (i >= p.vertices.size()) __builtin_trap();  // the loader promised in-range indices
  } catch (const projbot::assets::AssetError&) {
  }
  return 0;
}
