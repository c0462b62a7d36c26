// libFuzzer entry for the video path (FFmpeg's demuxers and decoders behind assets::VideoDecoder): any bytes
// must open and decode or fail with AssetError; a frame whose size or pixel count is outside the decoder's
// limits, or whose buffer disagrees with its size, is a finding. At most 64 frames per input (memory bounded
// by the size limits: one frame of at most 64 MiB at a time).
#include "projbot/assets/video.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using projbot::assets::VideoDecoder;
  try {
    VideoDecoder d(std::span<const std::uint8_t>(data, size), "fuzz");
    projbot::assets::VideoFrame f;
    for (int i = 0; i < 64 && d.next(f); ++i) {
      const auto& img = f.image;
      if (img.width <= 0 || img.height <= 0 || img.width > VideoDecoder::kMaxSide || img.height > VideoDecoder::kMaxSide ||
          static_cast<std::int64_t>(img.width) * img.height > VideoDecoder::kMaxPixels ||
          img.rgba.size() != static_cast<std::size_t>(img.width) * img.height * 4)
        __builtin_trap();
    }
  } catch (const projbot::assets::AssetError&) {
  }
  return 0;
}
