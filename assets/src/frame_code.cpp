// The frame-number test pattern (a hue wash over a row of bits): drawn and read back without FFmpeg.
#include <algorithm>
#include <cmath>

#include "projbot/assets/video.hpp"

namespace projbot::assets {

Image frame_code_image(std::int64_t index, int width, int height) {
  Image img;
  img.width = width;
  img.height = height;
  img.rgba.assign(static_cast<std::size_t>(width) * height * 4, 255);
  const double hue = std::fmod(static_cast<double>(index) * 12.0, 360.0) / 60.0;  // a turn every 30 frames
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = img.pixel(x, y);
      if (y < height / 2) {  // the wash: hue by frame, brighter to the right
        const double v = 0.35 + 0.6 * x / std::max(1, width - 1);
        for (int c = 0; c < 3; ++c) {
          const double k = std::fmod(hue + 4.0 - 2.0 * c + 6.0, 6.0);  // r, g, b phases of an HSV hue
          const double level = std::clamp(std::min(k, 4.0 - k), 0.0, 1.0);
          p[c] = static_cast<std::uint8_t>(std::lround(255.0 * v * (0.25 + 0.75 * level)));
        }
      } else {
        const int bit = std::min(kFrameCodeBits - 1, x * kFrameCodeBits / width);
        const bool set = ((index >> (kFrameCodeBits - 1 - bit)) & 1) != 0;
        p[0] = p[1] = p[2] = set ? 255 : 0;
      }
    }
  return img;
}

std::int64_t read_frame_code(const Image& image, int x0, int y0, int w, int h) {
  std::int64_t value = 0;
  for (int bit = 0; bit < kFrameCodeBits; ++bit) {
    const int x = x0 + static_cast<int>((bit + 0.5) * w / kFrameCodeBits);
    const int y = y0 + static_cast<int>(0.75 * h);
    if (x < 0 || y < 0 || x >= image.width || y >= image.height) return -1;
    const std::uint8_t* p = image.pixel(x, y);
    const int level = (p[0] + p[1] + p[2]) / 3;
    if (level > 96 && level < 160) return -1;
    value = (value << 1) | (level >= 160 ? 1 : 0);
  }
  return value;
}

}  // namespace projbot::assets
