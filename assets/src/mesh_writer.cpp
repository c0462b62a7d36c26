// Meshes written as binary PLY (what BOP datasets ship their models in): vertices with normals, triangles.

#include <cstring>
#include <string>

#include "projbot/assets/model.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::assets {
namespace {

template <typename T>
void append(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // little-endian hosts only, as the header says
  out.append(bytes, sizeof(T));
}

}  // namespace

void write_ply(const std::filesystem::path& path, const Model& model, double units_per_metre) {
  std::size_t vertices = 0, triangles = 0;
  for (const auto& p : model.primitives) vertices += p.vertices.size(), triangles += p.indices.size() / 3;
  if (vertices == 0 || triangles == 0 || !(units_per_metre > 0.0))
    throw AssetError(path.string() + ": refusing to write a mesh without triangles or with a scale <= 0");
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by projbot\nelement vertex " +
                    std::to_string(vertices) +
                    "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
                    "property float nz\nelement face " +
                    std::to_string(triangles) + "\nproperty list uchar int vertex_indices\nend_header\n";
  const auto scale = static_cast<float>(units_per_metre);
  for (const auto& p : model.primitives)
    for (const auto& v : p.vertices) {
      for (const float c : v.position) append(out, c * scale);
      for (const float n : v.normal) append(out, n);
    }
  std::uint32_t first = 0;
  for (const auto& p : model.primitives) {
    for (std::size_t i = 0; i + 2 < p.indices.size(); i += 3) {
      append(out, std::uint8_t{3});
      for (std::size_t k = 0; k < 3; ++k) append(out, static_cast<std::int32_t>(first + p.indices[i + k]));
    }
    first += static_cast<std::uint32_t>(p.vertices.size());
  }
  try {
    config::write_file_atomically(path, out);
  } catch (const config::OutputError& e) {
    throw AssetError(e.what());
  }
}

}  // namespace projbot::assets
