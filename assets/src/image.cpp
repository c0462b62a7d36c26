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

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>

#include "image_info.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/paths.hpp"

namespace projbot::assets {

namespace {

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(context);
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

}  // namespace

namespace {

// An 8-bit PNG of `channels` per pixel in memory; `what` names it in the errors.
std::vector<std::uint8_t> encode_png_8bit(const std::string& what, int width, int height, int channels,
                                          const std::vector<std::uint8_t>& data) {
  if (width <= 0 || height <= 0 || data.size() != static_cast<std::size_t>(width) * height * channels)
    throw AssetError(what + ": refusing to write an empty or inconsistent image");
  std::vector<std::uint8_t> png;
  if (stbi_write_png_to_func(append_bytes, &png, width, height, channels, data.data(), width * channels) == 0)
    throw AssetError(what + ": cannot encode PNG");
  return png;
}

// An 8-bit PNG of `channels` per pixel, written atomically.
void write_png_8bit(const std::filesystem::path& path, int width, int height, int channels,
                    const std::vector<std::uint8_t>& data) {
  const std::vector<std::uint8_t> png = encode_png_8bit(path.string(), width, height, channels, data);
  try {
    config::write_file_atomically(path, png.data(), png.size());
  } catch (const config::OutputError& e) {
    throw AssetError(e.what());
  }
}

}  // namespace

std::vector<std::uint8_t> encode_png(const Image& image) {
  return encode_png_8bit("encode_png", image.width, image.height, 4, image.rgba);
}

// A box filter: each output pixel averages the source pixels whose centres fall in its footprint.
Image shrunk(const Image& image, int max_width) {
  if (max_width <= 0 || image.width <= max_width) return image;
  const double step = static_cast<double>(image.width) / max_width;
  Image out{max_width, std::max(1, static_cast<int>(std::lround(image.height / step))), {}};
  out.rgba.assign(static_cast<std::size_t>(out.width) * out.height * 4, 0);
  for (int y = 0; y < out.height; ++y) {
    const int y0 = static_cast<int>(y * step), y1 = std::min(image.height, std::max(y0 + 1, static_cast<int>((y + 1) * step)));
    for (int x = 0; x < out.width; ++x) {
      const int x0 = static_cast<int>(x * step), x1 = std::min(image.width, std::max(x0 + 1, static_cast<int>((x + 1) * step)));
      std::array<unsigned, 4> sum{};
      for (int v = y0; v < y1; ++v)
        for (int u = x0; u < x1; ++u)
          for (int c = 0; c < 4; ++c) sum[static_cast<std::size_t>(c)] += image.pixel(u, v)[c];
      const unsigned n = static_cast<unsigned>((x1 - x0) * (y1 - y0));
      for (int c = 0; c < 4; ++c) out.pixel(x, y)[c] = static_cast<std::uint8_t>((sum[static_cast<std::size_t>(c)] + n / 2) / n);
    }
  }
  return out;
}

void write_png(const std::filesystem::path& path, const Image& image) {
  write_png_8bit(path, image.width, image.height, 4, image.rgba);
}

void write_png_gray8(const std::filesystem::path& path, int width, int height, const std::vector<std::uint8_t>& values) {
  write_png_8bit(path, width, height, 1, values);
}

namespace {

void append_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (const int shift : {24, 16, 8, 0}) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

// One PNG chunk: length, type, data and the CRC of type and data (stb's).
void append_chunk(std::vector<std::uint8_t>& png, const char* type, const std::uint8_t* data, std::size_t size) {
  append_be32(png, static_cast<std::uint32_t>(size));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data, data + size);
  append_be32(png, stbiw__crc32(png.data() + start, static_cast<int>(size + 4)));
}

}  // namespace

// stb writes 8-bit PNGs only; its deflate and CRC make the 16-bit one (rows unfiltered, big-endian samples).
void write_png_gray16(const std::filesystem::path& path, const Gray16Image& image) {
  if (image.width <= 0 || image.height <= 0 || image.values.size() != static_cast<std::size_t>(image.width) * image.height)
    throw AssetError(path.string() + ": refusing to write an empty or inconsistent image");
  const std::size_t row = 1 + 2 * static_cast<std::size_t>(image.width);
  std::vector<std::uint8_t> raw(row * image.height);
  for (int y = 0; y < image.height; ++y) {
    std::uint8_t* out = raw.data() + row * y;
    *out++ = 0;  // filter: none
    for (int x = 0; x < image.width; ++x) {
      const std::uint16_t v = image.values[static_cast<std::size_t>(y) * image.width + x];
      *out++ = static_cast<std::uint8_t>(v >> 8);
      *out++ = static_cast<std::uint8_t>(v & 0xFF);
    }
  }
  int packed_size = 0;
  std::unique_ptr<unsigned char, void (*)(void*)> packed(
      stbi_zlib_compress(raw.data(), static_cast<int>(raw.size()), &packed_size, 6), std::free);
  if (!packed) throw AssetError(path.string() + ": cannot encode PNG");
  std::vector<std::uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'}, header;
  append_be32(header, static_cast<std::uint32_t>(image.width));
  append_be32(header, static_cast<std::uint32_t>(image.height));
  header.insert(header.end(), {16, 0, 0, 0, 0});  // 16 bits, grey, deflate, adaptive filtering, not interlaced
  append_chunk(png, "IHDR", header.data(), header.size());
  append_chunk(png, "IDAT", packed.get(), static_cast<std::size_t>(packed_size));
  append_chunk(png, "IEND", nullptr, 0);
  try {
    config::write_file_atomically(path, png.data(), png.size());
  } catch (const config::OutputError& e) {
    throw AssetError(e.what());
  }
}

namespace {

// stb allocates what the header claims before it inflates a byte. Deflate packs at most 1032 bytes into
// one, so a header that claims more than that from this file's size is corrupt: refused before stb
// allocates it (a 100-byte PNG claiming 20000x20000 pixels once took 550 MB). `bytes_per_pixel`: as the
// file stores them (a grey 8-bit mask 1, not the 4 it is read into: a valid 1.5 kB 640x480 mask was refused).
void check_claimed_size(const std::filesystem::path& path, int w, int h, int bytes_per_pixel) {
  std::error_code ec;
  const double file_bytes = static_cast<double>(std::filesystem::file_size(path, ec));
  const double pixels = static_cast<double>(w) * h;
  if (!ec && (pixels > 1e8 || pixels * bytes_per_pixel > 1032.0 * file_bytes + 65536.0))
    throw AssetError(path.string() + ": the header claims " + std::to_string(w) + "x" + std::to_string(h) +
                     " pixels, more than a " + std::to_string(static_cast<long long>(file_bytes)) +
                     "-byte image file can hold (corrupt header)");
}

// stb allocates what a PNG chunk's length claims before reading it (a 73-byte file claiming a 553 MB
// IDAT): every chunk must fit in the file. Files that are not PNG are left to stb.
void check_png_chunks(const std::filesystem::path& path) {
  // Before any open: a FIFO's open blocks until a writer comes (a texture named by a scene or an .mtl).
  if (const std::string problem = config::input_file_problem(path); !problem.empty())
    throw AssetError(path.string() + ": " + (problem == "does not exist" ? std::string("no such image file") : problem));
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (!ec && size == 0) throw AssetError(path.string() + ": the file is empty (0 bytes), not an image");
  std::ifstream in(path, std::ios::binary);
  unsigned char sig[8] = {};
  if (!in.read(reinterpret_cast<char*>(sig), 8) || sig[0] != 0x89 || sig[1] != 'P' || sig[2] != 'N' || sig[3] != 'G') return;
  std::string last;
  for (std::uint64_t at = 8; !ec && at < size;) {
    unsigned char head[8] = {};
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(reinterpret_cast<char*>(head), 8))
      throw AssetError(path.string() + ": corrupt PNG: the file ends inside a chunk header at byte " + std::to_string(at));
    const std::uint64_t length = (std::uint64_t{head[0]} << 24) | (head[1] << 16) | (head[2] << 8) | head[3];
    last.assign(reinterpret_cast<char*>(head) + 4, 4);
    if (at + 12 + length > size)
      throw AssetError(path.string() + ": corrupt PNG: the " + last + " chunk at byte " + std::to_string(at) + " claims " +
                       std::to_string(length) + " bytes, more than the file holds (truncated?)");
    at += 12 + length;
  }
  if (!ec && last != "IEND")
    throw AssetError(path.string() + ": corrupt PNG: the file ends after " + std::to_string(size) +
                     " bytes without its IEND chunk (truncated?)");
}

}  // namespace

void check_png_structure(const std::filesystem::path& path) { check_png_chunks(path); }

bool detail::claimed_image_size(const unsigned char* bytes, int size, int& width, int& height) {
  // A PNG's IHDR read here: stb's info refuses (as "too large") the very images this is asked about.
  if (size >= 24 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0 && std::memcmp(bytes + 12, "IHDR", 4) == 0) {
    const auto be32 = [&](int at) {
      return (std::uint32_t{bytes[at]} << 24) | (std::uint32_t{bytes[at + 1]} << 16) | (std::uint32_t{bytes[at + 2]} << 8) |
             std::uint32_t{bytes[at + 3]};
    };
    const std::uint32_t w = be32(16), h = be32(20);
    width = static_cast<int>(std::min<std::uint32_t>(w, 1U << 30));
    height = static_cast<int>(std::min<std::uint32_t>(h, 1U << 30));
    return true;
  }
  int comps = 0;
  return stbi_info_from_memory(bytes, size, &width, &height, &comps) != 0;
}

Image read_image(const std::filesystem::path& path) {
  int w = 0, h = 0, comps = 0;
  check_png_chunks(path);
  if (!stbi_info(path.c_str(), &w, &h, &comps)) throw AssetError(path.string() + ": cannot read image: " + stbi_failure_reason());
  check_claimed_size(path, w, h, std::max(1, comps) * (stbi_is_16_bit(path.c_str()) != 0 ? 2 : 1));
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
  check_png_chunks(path);
  if (!stbi_info(path.c_str(), &w, &h, &comps)) throw AssetError(path.string() + ": cannot read PNG: " + stbi_failure_reason());
  const bool sixteen = stbi_is_16_bit(path.c_str()) != 0;
  if (!sixteen || comps != 1)
    throw AssetError(path.string() + ": a depth PNG must be 16-bit single-channel (this one has " + std::to_string(comps) +
                     " channel(s), " + (sixteen ? "16" : "8") + " bits)");
  check_claimed_size(path, w, h, 2);
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
