#pragma once
// What a model file names besides itself, for the loaders and model_files: an OBJ's material libraries,
// and a glTF's JSON document (where its buffers, images and animations are named).

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

/// The JSON document of a glTF file: a .gltf's whole text, or a .glb's JSON chunk (told apart by the
/// .glb's magic bytes); empty where a .glb's header is not sound. The caller has checked that `path` is a
/// regular file (model_files.cpp).
std::string gltf_document_json(const std::filesystem::path& path);

}  // namespace projbot::assets::detail
