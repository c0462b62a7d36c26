#include "projbot/assets/image.hpp"

#include <stb_image.h>
#include <stb_image_write.h>

namespace projbot::assets {

void write_png(const std::filesystem::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
    throw AssetError(path.string() + ": refusing to write an empty or inconsistent image");
  if (stbi_write_png(path.c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4) == 0)
    throw AssetError(path.string() + ": cannot write PNG (does the folder exist and is it writable?)");
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

}  // namespace projbot::assets
