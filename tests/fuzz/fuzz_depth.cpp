// libFuzzer entry for depth images: 16-bit PNG (stb) or, built with FUZZ_TIFF, TIFF (libtiff). Any input
// reads as an image whose pixel count matches its size, or fails with AlignmentError or AssetError.
#include "fuzz_input.hpp"
#include "projbot/alignment/depth.hpp"
#include "projbot/assets/image.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
#ifdef FUZZ_TIFF
    const auto depth = projbot::alignment::read_depth_tiff(projbot::fuzz::input_file(data, size, ".tiff"), 0.001);
#else
    const auto depth = projbot::alignment::read_depth_png(projbot::fuzz::input_file(data, size, ".png"), 1000.0);
#endif
    if (depth.depth_m.size() != static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height)) __builtin_trap();
  } catch (const projbot::alignment::AlignmentError&) {
  } catch (const projbot::assets::AssetError&) {
  }
  return 0;
}
