#pragma once
// A PLY file's body against its header, checked by us before PCL's or Assimp's reader sees the file:
// both read the counts the header declares and silently ignore what follows, so a file holding more
// vertices or faces than it declares was half read (a scan's pose accepted, a mesh drawn in half).
// One check for both paths: alignment's clouds and the assets' meshes.

#include <cstdint>
#include <filesystem>
#include <stdexcept>

namespace projbot::config {

/// A PLY file whose header and body disagree; the message names the file.
class PlyError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What the header declares.
struct PlyCounts {
  std::uint64_t vertices = 0;
  std::uint64_t faces = 0;
  bool vertex_xyz = false;  ///< the vertex element has scalar x, y and z properties
};

/// Walks the body element by element (list properties included) and throws PlyError naming the
/// file unless it ends exactly where the header's counts say (ASCII: one line per element, blank lines
/// aside). Returns the declared vertex and face counts.
PlyCounts check_ply_body(const std::filesystem::path& path);

}  // namespace projbot::config
