// PLY, OBJ (+ .mtl) and STL meshes through Assimp (Debian's libassimp). Assimp's importers are not safe
// on hostile files (its own fuzzers keep finding crashes), so it runs in a child process
// (config::read_isolated) and only plain vertices, indices and material values come back; textures
// named by a material are read here, by our own PNG/JPEG reader.

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <fstream>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "default_material.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/isolated_read.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/ply_body.hpp"
#include "referenced_files.hpp"

namespace projbot::assets {
namespace {

// What the child hands back for a material: its diffuse colour and the texture file it names (relative to
// the model's folder, as OBJ's map_Kd is), if any.
struct MaterialValues {
  std::array<float, 4> base_color_factor{1.0F, 1.0F, 1.0F, 1.0F};
  bool double_sided = false;
};

constexpr unsigned kImportFlags = aiProcess_Triangulate | aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                                  aiProcess_SortByPType | aiProcess_FlipUVs | aiProcess_ValidateDataStructure |
                                  aiProcess_FindInvalidData | aiProcess_FindDegenerates;

Vertex vertex_of(const aiMesh& mesh, unsigned i) {
  Vertex v;
  v.position = {mesh.mVertices[i].x, mesh.mVertices[i].y, mesh.mVertices[i].z};
  if (mesh.HasNormals()) v.normal = {mesh.mNormals[i].x, mesh.mNormals[i].y, mesh.mNormals[i].z};
  if (mesh.HasTextureCoords(0)) v.uv = {mesh.mTextureCoords[0][i].x, mesh.mTextureCoords[0][i].y};
  if (mesh.HasVertexColors(0)) {
    const aiColor4D& c = mesh.mColors[0][i];
    v.color = {c.r, c.g, c.b, c.a};
  }
  return v;
}

// One triangle mesh as bytes: material index, vertices, indices.
void put_mesh(const aiMesh& mesh, config::Bytes& out) {
  std::vector<Vertex> vertices;
  vertices.reserve(mesh.mNumVertices);
  for (unsigned i = 0; i < mesh.mNumVertices; ++i) vertices.push_back(vertex_of(mesh, i));
  std::vector<std::uint32_t> indices;
  indices.reserve(3 * static_cast<std::size_t>(mesh.mNumFaces));
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines: SortByPType put them in meshes of their own
    for (unsigned k = 0; k < 3; ++k) indices.push_back(face.mIndices[k]);  // checked where they arrive
  }
  out.put<std::int32_t>(static_cast<std::int32_t>(mesh.mMaterialIndex));
  out.put_vector(vertices);
  out.put_vector(indices);
}

void put_material(const aiMaterial& material, config::Bytes& out) {
  MaterialValues values;
  aiColor4D diffuse;
  if (material.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == aiReturn_SUCCESS)
    values.base_color_factor = {diffuse.r, diffuse.g, diffuse.b, 1.0F};
  int two_sided = 0;
  if (material.Get(AI_MATKEY_TWOSIDED, two_sided) == aiReturn_SUCCESS) values.double_sided = two_sided != 0;
  aiString texture;
  std::string name;
  if (material.GetTextureCount(aiTextureType_DIFFUSE) > 0 &&
      material.GetTexture(aiTextureType_DIFFUSE, 0, &texture) == aiReturn_SUCCESS)
    name = texture.C_Str();
  out.put(values);
  out.put_vector(std::vector<char>(name.begin(), name.end()));
}

// Assimp drops the meshes FindInvalidData finds a NaN or infinite position in, and then says only "No
// meshes remaining": read again without that step, and name the value if that was the cause.
std::string import_error(const std::filesystem::path& path, const std::string& assimp_error) {
  Assimp::Importer again;
  const aiScene* raw = again.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_ValidateDataStructure);
  for (unsigned m = 0; raw != nullptr && m < raw->mNumMeshes; ++m)
    for (unsigned i = 0; i < raw->mMeshes[m]->mNumVertices; ++i) {
      const aiVector3D& p = raw->mMeshes[m]->mVertices[i];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return "a vertex position is not a finite number (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
               std::to_string(p.z) + ")";
    }
  return "Assimp cannot read it: " + assimp_error;
}

// Runs in the child: the whole import, as bytes.
std::string import_in_child(const std::filesystem::path& path) {
  Assimp::Importer importer;
  // A PLY or STL without faces would come back as points; we want surfaces, and say so below.
  const aiScene* scene = importer.ReadFile(path.string(), kImportFlags);
  if (scene == nullptr) throw AssetError(import_error(path, importer.GetErrorString()));
  config::Bytes out;
  std::uint32_t triangle_meshes = 0;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    if ((scene->mMeshes[m]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0) ++triangle_meshes;
  out.put(triangle_meshes);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    if ((scene->mMeshes[m]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0) put_mesh(*scene->mMeshes[m], out);
  out.put<std::uint32_t>(scene->mNumMaterials);
  for (unsigned m = 0; m < scene->mNumMaterials; ++m) put_material(*scene->mMaterials[m], out);
  return out.take();
}

bool finite_vertex(const Vertex& v) {
  for (float x : v.position)
    if (!std::isfinite(x)) return false;
  for (float x : v.normal)
    if (!std::isfinite(x)) return false;
  return true;
}

// One primitive as the child sent it, checked: the child's bytes are not trusted.
Primitive read_primitive(config::BytesReader& in, const std::string& file) {
  Primitive p;
  p.material = in.get<std::int32_t>();
  p.vertices = in.get_vector<Vertex>();
  p.indices = in.get_vector<std::uint32_t>();
  for (const Vertex& v : p.vertices)
    if (!finite_vertex(v)) throw AssetError(file + ": a vertex position or normal is not a finite number");
  for (std::uint32_t i : p.indices)
    if (i >= p.vertices.size()) throw AssetError(file + ": a face names a vertex the mesh does not have");
  return p;
}

// A warning on stderr, once per process: a command that loads a model twice (framing it, then drawing it)
// says it once.
void warn_once(const std::string& said) {
  static std::mutex m;
  static std::set<std::string> told;
  const std::lock_guard<std::mutex> lock(m);
  if (told.insert(said).second) std::cerr << "projbot: warning: " << said << "\n";
}

// A material's texture, read beside the model; a missing or unreadable one is a warning and the
// material keeps its base colour (users' OBJ files often name a texture they did not ship).
int load_texture(const std::filesystem::path& model, const std::string& name, Model& out) {
  if (name.empty()) return -1;
  if (name[0] == '*') {
    warn_once(model.string() + ": embedded texture '" + name + "' is not supported; the material's base colour is used");
    return -1;
  }
  const std::filesystem::path file = model.parent_path() / name;
  try {
    out.images.push_back(read_image(file));
    return static_cast<int>(out.images.size() - 1);
  } catch (const AssetError& e) {
    warn_once(model.string() + ": texture " + file.string() + " not used (" + e.what() + "); the material's base colour is used");
    return -1;
  }
}

Model model_from_bytes(const std::string& bytes, const std::filesystem::path& path) {
  const std::string file = path.string();
  config::BytesReader in(bytes);
  Model out;
  out.source = file;
  const auto meshes = in.get<std::uint32_t>();
  std::vector<Primitive> primitives;
  for (std::uint32_t m = 0; m < meshes; ++m) primitives.push_back(read_primitive(in, file));
  const auto materials = in.get<std::uint32_t>();
  for (std::uint32_t m = 0; m < materials; ++m) {
    const auto values = in.get<MaterialValues>();
    const auto name = in.get_vector<char>();
    Material mat;
    mat.base_color_factor = values.base_color_factor;
    mat.double_sided = values.double_sided;
    const std::string texture(name.begin(), name.end());
    mat.base_color_image = load_texture(path, texture, out);
    if (!texture.empty() && texture[0] != '*') out.files.push_back(path.parent_path() / texture);  // watched, read or not
    // OBJ's diffuse colour multiplies the texture in its own renderers only when no map is given
    // (MeshLab writes a grey Kd beside every map_Kd): with a texture, the texture alone is the content.
    if (mat.base_color_image >= 0) mat.base_color_factor = {1.0F, 1.0F, 1.0F, 1.0F};
    out.materials.push_back(mat);
  }
  for (Primitive& p : primitives) {
    if (p.indices.empty()) continue;
    if (p.material < 0 || static_cast<std::uint32_t>(p.material) >= materials) p.material = -1;
    out.primitives.push_back(std::move(p));
  }
  if (out.primitives.empty()) throw AssetError(file + ": no triangles (a mesh file without faces is a point cloud, not a model)");
  detail::give_default_material(out);
  return out;
}

// Assimp, like PCL, reads the counts a PLY header declares and ignores what follows: the body is checked first.
void check_ply(const std::filesystem::path& path) {
  try {
    config::check_ply_body(path);
  } catch (const config::PlyError& e) {
    throw AssetError(e.what());
  }
}

}  // namespace

Model load_mesh(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw AssetError(path.string() + (std::filesystem::exists(path, ec) ? ": not a regular file" : ": no such file"));
  if (detail::lowercase_extension(path) == ".ply") check_ply(path);
  const std::vector<std::string> libraries = detail::obj_material_libraries(path);
  for (const std::string& library : libraries)  // Assimp would block on a FIFO until its time limit
    if (const auto problem = config::input_file_problem(path.parent_path() / library);
        !problem.empty() && problem != "does not exist")
      throw AssetError((path.parent_path() / library).string() + ": " + problem + " (the material library " + path.string() +
                       " names)");
  std::string bytes;
  try {
    bytes = config::read_isolated(path, {"mesh file", "Assimp"}, [&](config::ReadProgress&) { return import_in_child(path); });
  } catch (const config::IsolatedReadError& e) {
    const std::string what = e.what();
    throw AssetError(what.rfind(path.string(), 0) == 0 ? what : path.string() + ": " + what);
  }
  Model model = model_from_bytes(bytes, path);
  model.files.insert(model.files.begin(), path);
  for (const std::string& library : libraries) model.files.push_back(path.parent_path() / library);
  return model;
}

Model load_model(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw AssetError(path.string() + ": is a folder, not a model file");
  const std::string ext = detail::lowercase_extension(path);
  if (ext == ".gltf" || ext == ".glb") return load_gltf(path);
  if (ext == ".ply" || ext == ".obj" || ext == ".stl") return load_mesh(path);
  throw AssetError(path.string() + ": unknown model format '" + ext + "' (use .gltf, .glb, .ply, .obj or .stl)");
}

}  // namespace projbot::assets
