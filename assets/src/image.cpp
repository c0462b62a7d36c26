#include "projbot/assets/image.hpp"

// stb compiled here, privately (static functions): the packaged libstb exports the same names as older
// copies inside libraries projbot links (MRPT's nanogui, draco), and the dynamic linker bound our calls
// to those: their stbi_info could not read 16-bit PNGs, and every depth PNG failed in the executable.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wimplicit-fallthrough"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <stb_image.h>
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <memory>

#include "projbot/config/output_file.hpp"

namespace projbot::assets {

namespace {

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

void write_png(const std::filesystem::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    throw AssetError(path.string() + ": refusing to write an empty or inconsistent image");
  std::vector<std::uint8_t> png;
  if (stbi_write_png_to_func(append_bytes, &png, image.width, image.height, 4, image.rgba.data(), image.width * 4) == 0)
    throw AssetError(path.string() + ": cannot encode PNG");
  try {
    config::write_file_atomically(path, png.data(), png.size());
  } catch (const config::OutputError& e) {
    throw AssetError(e.what());
  }
}

Image read_image(const std::filesystem::path& path) {
  int w = 0, h = 0, comps = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &comps, 4);
  if (data == nullptr) throw AssetError(path.string() + ": cannot read image: " + stbi_failure_reason());
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.assign(data, data + static_cast<std::size_t>(w) * h * 4);
  stbi_image_free(data);
  return img;
}

Gray16Image read_png_gray16(const std::filesystem::path& path) {
  int w = 0, h = 0, comps = 0;
  if (!stbi_info(path.c_str(), &w, &h, &comps)) throw AssetError(path.string() + ": cannot read PNG: " + stbi_failure_reason());
  const bool sixteen = stbi_is_16_bit(path.c_str()) != 0;
  if (!sixteen || comps != 1)
    throw AssetError(path.string() + ": a depth PNG must be 16-bit single-channel (this one has " + std::to_string(comps) +
                     " channel(s), " + (sixteen ? "16" : "8") + " bits)");
  std::unique_ptr<stbi_us, void (*)(void*)> data(stbi_load_16(path.c_str(), &w, &h, &comps, 1), stbi_image_free);
  if (!data)
    throw AssetError(path.string() + ": cannot decode PNG (truncated or corrupt; stb says: " + stbi_failure_reason() + ")");
  Gray16Image img;
  img.width = w;
  img.height = h;
  img.values.assign(data.get(), data.get() + static_cast<std::size_t>(w) * h);
  return img;
}

}  // namespace projbot::assets
