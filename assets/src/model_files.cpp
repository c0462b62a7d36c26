// The files a model's loader reads, listed without loading it: a command checks its outputs against
// them before any work (writing a model's texture would destroy the content it draws).

#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "default_material.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/paths.hpp"
#include "referenced_files.hpp"

namespace projbot::assets {
namespace {

constexpr std::uintmax_t kMaxDocumentBytes = 256u << 20;  // a glTF, OBJ or .mtl beyond this is not read here

bool readable(const std::filesystem::path& file) {
  std::error_code ec;
  return config::input_file_problem(file).empty() && std::filesystem::file_size(file, ec) <= kMaxDocumentBytes && !ec;
}

void add_gltf_uris(const std::filesystem::path& file, std::vector<std::filesystem::path>& out) {
  const nlohmann::json doc = nlohmann::json::parse(detail::gltf_document_json(file), nullptr, false);
  if (!doc.is_object()) return;  // malformed: the loader says so
  for (const char* key : {"buffers", "images"}) {
    if (!doc.contains(key) || !doc[key].is_array()) continue;
    for (const auto& entry : doc[key])
      if (entry.is_object() && entry.contains("uri") && entry["uri"].is_string()) {
        const std::string uri = entry["uri"];
        if (!uri.empty() && uri.rfind("data:", 0) != 0) out.push_back(file.parent_path() / uri);
      }
  }
}

// An OBJ's material libraries, and the texture maps each names (`map_Kd [options] file`: the last word).
void add_obj_files(const std::filesystem::path& file, std::vector<std::filesystem::path>& out) {
  for (const std::string& library : detail::obj_material_libraries(file)) {
    const std::filesystem::path mtl = file.parent_path() / library;
    out.push_back(mtl);
    if (!readable(mtl)) continue;
    std::ifstream in(mtl);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("map_", 0) != 0) continue;
      std::istringstream words(line);
      std::string word, last;
      while (words >> word) last = word;
      if (!last.empty() && last.rfind("map_", 0) != 0) out.push_back(file.parent_path() / last);
    }
  }
}

}  // namespace

std::string detail::gltf_document_json(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char header[20] = {};
  in.read(header, sizeof header);
  if (in.gcount() < 4 || std::memcmp(header, "glTF", 4) != 0) {  // a .gltf: the text is the document
    in.clear();
    in.seekg(0);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  std::uint32_t length = 0;
  std::memcpy(&length, header + 12, 4);
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (in.gcount() < 20 || std::memcmp(header + 16, "JSON", 4) != 0 || ec || length > size - 20) return {};
  std::string json(length, '\0');
  return in.read(json.data(), length) ? json : std::string();
}

std::vector<std::filesystem::path> model_files(const std::filesystem::path& path) {
  std::vector<std::filesystem::path> out{path};
  if (!readable(path)) return out;
  const std::string ext = detail::lowercase_extension(path);
  if (ext == ".gltf" || ext == ".glb") add_gltf_uris(path, out);
  if (ext == ".obj") add_obj_files(path, out);
  return out;
}

}  // namespace projbot::assets
