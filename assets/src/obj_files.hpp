#pragma once
// What an OBJ file names besides itself, for the mesh loader and model_files.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "default_material.hpp"

namespace projbot::assets::detail {

/// The material libraries an OBJ file names (`mtllib a.mtl b.mtl`), declared before its faces: what it
/// is drawn with besides itself. None for other formats. The caller has checked that `path` is a regular file.
inline std::vector<std::string> obj_material_libraries(const std::filesystem::path& path) {
  std::vector<std::string> out;
  if (lowercase_extension(path) != ".obj") return out;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line) && line.rfind("f ", 0) != 0;) {
    if (line.rfind("mtllib", 0) != 0) continue;
    std::istringstream names(line.substr(6));
    for (std::string name; names >> name;) out.push_back(name);
  }
  return out;
}

}  // namespace projbot::assets::detail
