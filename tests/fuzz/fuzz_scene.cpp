// libFuzzer entry for scene YAML: any text parses into a scene that passed validation, or fails with
// ConfigError; a crash, an ASan report or another exception type is a finding.
#include <cmath>
#include <string_view>

#include "projbot/config/scene.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto scene = projbot::config::parse_scene(std::string_view(reinterpret_cast<const char*>(data), size),
                                                    PROJBOT_ASSET_DIR "/scenes/fuzz.yaml");
    const auto& p = scene.projector;  // what validation promised
    if (!(p.width_px > 0 && p.height_px > 0 && p.fx_px > 0 && std::isfinite(p.fx_px) && p.near_m > 0 && p.near_m < p.far_m))
      __builtin_trap();
  } catch (const projbot::config::ConfigError&) {
  }
  return 0;
}
