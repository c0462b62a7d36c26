#pragma once
// RGBA8 images as stored (no colour-space conversion), and PNG files.

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

namespace projbot::assets {

/// A bad model or image file: the message names the file and what is wrong.
class AssetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Row-major RGBA8 pixels, top row first, values exactly as stored in the source file.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  ///< width * height * 4 bytes

  std::uint8_t* pixel(int x, int y) { return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4; }
  const std::uint8_t* pixel(int x, int y) const { return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4; }
  /// Pixels that are not black (any of R, G, B non-zero): how much of a projector frame carries light.
  std::size_t lit_pixels() const {
    std::size_t lit = 0;
    for (std::size_t i = 0; i + 3 < rgba.size(); i += 4) lit += (rgba[i] | rgba[i + 1] | rgba[i + 2]) != 0 ? 1 : 0;
    return lit;
  }
};

/// Row-major 16-bit single-channel pixels (a depth image), top row first, values as stored.
struct Gray16Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint16_t> values;  ///< width * height
};

/// Writes an RGBA8 PNG atomically (a temporary file beside it, checked, renamed over it): a failed write
/// leaves any previous file unchanged. Throws AssetError naming the file.
void write_png(const std::filesystem::path& path, const Image& image);

/// Writes an 8-bit single-channel PNG (a mask, as BOP's are) of width * height values, as write_png does.
void write_png_gray8(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& values);

/// Writes a 16-bit single-channel PNG (a depth image) atomically, as write_png does. Throws AssetError.
void write_png_gray16(const std::filesystem::path& path, const Gray16Image& image);

/// An RGBA8 image as PNG bytes in memory (what a web page is sent). Throws AssetError for an empty or
/// inconsistent image.
std::vector<std::uint8_t> encode_png(const Image& image);

/// `image` made at most `max_width` pixels wide (its aspect kept; each pixel the mean of those it covers);
/// an image already that small is returned as it is.
Image shrunk(const Image& image, int max_width);

/// Reads a PNG or JPEG into RGBA8. Throws AssetError naming the file.
Image read_image(const std::filesystem::path& path);

/// Checks a PNG's structure before any decoder sees it: every chunk fits in the file and the last is
/// IEND (a truncated capture image once gave only libpng's line). Other formats pass. Throws AssetError.
void check_png_structure(const std::filesystem::path& path);

/// Reads a 16-bit single-channel PNG. Throws AssetError naming the file (and, for another kind of PNG,
/// its channels and bit depth).
Gray16Image read_png_gray16(const std::filesystem::path& path);

}  // namespace projbot::assets
