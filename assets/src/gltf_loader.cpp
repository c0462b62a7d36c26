// glTF 2.0 loading through tinygltf (Debian's libtinygltf). Every index, offset and value read from the
// file is checked here before use: tinygltf parses the JSON but does not bound accessors by their
// buffers, and a malformed file must give an error, never a crash or a half-loaded model.

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <mutex>
#include <new>
#include <set>
#include <sstream>

#include "default_material.hpp"
#include "gltf_reader.hpp"
#include "image_info.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/json_message.hpp"
#include "projbot/config/paths.hpp"
#include "referenced_files.hpp"

namespace projbot::assets {
namespace {

class Loader : detail::GltfReader {
 public:
  using GltfReader::GltfReader;

  // `json`: the document's JSON (the animations' pointer channels are read from it).
  Model build(const std::string& json) {
    Model out;
    out.source = file_;
    load_images(out);
    detail::read_materials(*this, out);
    for (int root : root_nodes()) {
      std::set<int> path;
      visit_node(root, Eigen::Matrix4d::Identity(), path, out);
    }
    if (out.primitives.empty()) fail("no triangle meshes in the scene");
    detail::bake_texture_transforms(out);
    if (!g_.animations.empty()) detail::read_material_animations(*this, json, out);
    detail::give_default_material(out);
    return out;
  }

 private:
  static constexpr std::size_t kMaxNodeDepth = 256;
  static constexpr std::size_t kMaxNodeVisits = 100000;
  std::size_t visits_ = 0;

  std::vector<int> root_nodes() const {
    if (!g_.scenes.empty()) {
      const int scene = g_.defaultScene >= 0 ? g_.defaultScene : 0;
      check_index(scene, g_.scenes, "scene");
      return g_.scenes[static_cast<std::size_t>(scene)].nodes;
    }
    // No scenes: every node that is nobody's child is a root.
    std::set<int> children;
    for (const auto& n : g_.nodes) children.insert(n.children.begin(), n.children.end());
    std::vector<int> roots;
    for (int i = 0; i < static_cast<int>(g_.nodes.size()); ++i)
      if (!children.contains(i)) roots.push_back(i);
    return roots;
  }

  Eigen::Matrix4d local_transform(const tinygltf::Node& n, int index) const {
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    if (n.matrix.size() == 16) {
      for (int i = 0; i < 16; ++i) M(i % 4, i / 4) = n.matrix[static_cast<std::size_t>(i)];  // column-major
    } else if (!n.matrix.empty()) {
      fail("node " + std::to_string(index) + ": matrix must have 16 numbers");
    } else {
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
      Eigen::Vector3d s = Eigen::Vector3d::Ones();
      if (n.translation.size() == 3) t = {n.translation[0], n.translation[1], n.translation[2]};
      if (n.rotation.size() == 4) {
        q = Eigen::Quaterniond(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]);  // glTF is x y z w
        if (!(q.norm() > 1e-9)) fail("node " + std::to_string(index) + ": rotation quaternion has zero length");
        q.normalize();
      }
      if (n.scale.size() == 3) s = {n.scale[0], n.scale[1], n.scale[2]};
      M.topLeftCorner<3, 3>() = q.toRotationMatrix() * s.asDiagonal();
      M.topRightCorner<3, 1>() = t;
    }
    if (!M.allFinite()) fail("node " + std::to_string(index) + ": transform is not finite");
    return M;
  }

  void visit_node(int index, const Eigen::Matrix4d& parent, std::set<int>& path, Model& out) {
    check_index(index, g_.nodes, "node");
    if (!path.insert(index).second) fail("node " + std::to_string(index) + " is its own ancestor (cycle in node hierarchy)");
    // Bounded: a 20000-deep chain overflowed the stack, and nodes shared as children multiply the visits.
    if (path.size() > kMaxNodeDepth)
      fail("node " + std::to_string(index) + ": the node hierarchy is deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    if (++visits_ > kMaxNodeVisits)
      fail("the node hierarchy places more than " + std::to_string(kMaxNodeVisits) +
           " nodes (children shared between parents, many levels deep)");
    const auto& node = g_.nodes[static_cast<std::size_t>(index)];
    const Eigen::Matrix4d world = parent * local_transform(node, index);
    if (node.mesh >= 0) {
      check_index(node.mesh, g_.meshes, "mesh");
      const auto& mesh = g_.meshes[static_cast<std::size_t>(node.mesh)];
      for (std::size_t p = 0; p < mesh.primitives.size(); ++p)
        load_primitive(mesh.primitives[p], world, "mesh " + std::to_string(node.mesh) + " primitive " + std::to_string(p), out);
    }
    for (int child : node.children) visit_node(child, world, path, out);
    path.erase(index);
  }

  View float_attribute(int accessor, const std::string& what, std::initializer_list<int> types, bool allow_normalized) const {
    View v = accessor_view(accessor, what);
    if (std::find(types.begin(), types.end(), v.type) == types.end()) fail(what + ": unexpected element type");
    const bool ok_component =
        v.component_type == TINYGLTF_COMPONENT_TYPE_FLOAT || (allow_normalized && v.normalized &&
                                                              (v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                                               v.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT));
    if (!ok_component) fail(what + ": unsupported component type " + std::to_string(v.component_type));
    return v;
  }

  void load_primitive(const tinygltf::Primitive& prim, const Eigen::Matrix4d& world, const std::string& what, Model& out) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
      fail(what + ": mode " + std::to_string(mode) + " is not a triangle primitive (points and lines cannot be projected)");
    const auto pos_it = prim.attributes.find("POSITION");
    if (pos_it == prim.attributes.end()) fail(what + ": has no POSITION attribute");
    const View pos = float_attribute(pos_it->second, what + " POSITION", {TINYGLTF_TYPE_VEC3}, false);
    const std::size_t n = pos.count;
    if (n == 0) return;

    Primitive p;
    p.vertices.resize(n);
    const Eigen::Matrix3d L = world.topLeftCorner<3, 3>();
    if (!(std::abs(L.determinant()) > 1e-18)) fail(what + ": node transform is singular");
    read_positions(pos, world, what, p);
    const bool have_normals = read_normals(prim, L.inverse().transpose(), what, p);
    read_texcoords(prim, what, p);
    read_colours(prim, what, p);
    // A mirroring transform flips the winding back.
    unroll_triangles(read_indices(prim, what, n), mode, L.determinant() < 0.0, what, p);
    if (!have_normals) compute_normals(p);
    if (prim.material >= 0) check_index(prim.material, g_.materials, what + ": material");
    p.material = prim.material;
    out.primitives.push_back(std::move(p));
  }

  void read_positions(const View& pos, const Eigen::Matrix4d& world, const std::string& what, Primitive& p) {
    for (std::size_t i = 0; i < pos.count; ++i) {
      Eigen::Vector4d x(read_component(pos, i, 0), read_component(pos, i, 1), read_component(pos, i, 2), 1.0);
      if (!x.allFinite()) fail(what + ": POSITION " + std::to_string(i) + " is not finite");
      const Eigen::Vector4d w = world * x;
      p.vertices[i].position = {static_cast<float>(w.x()), static_cast<float>(w.y()), static_cast<float>(w.z())};
    }
  }

  // NORMAL, moved by the normal matrix; false when the file has none or a degenerate one (then all are
  // computed from the faces).
  bool read_normals(const tinygltf::Primitive& prim, const Eigen::Matrix3d& normal_matrix, const std::string& what,
                    Primitive& p) {
    const auto it = prim.attributes.find("NORMAL");
    if (it == prim.attributes.end()) return false;
    const View nv = float_attribute(it->second, what + " NORMAL", {TINYGLTF_TYPE_VEC3}, false);
    if (nv.count != p.vertices.size()) fail(what + ": NORMAL count differs from POSITION count");
    for (std::size_t i = 0; i < nv.count; ++i) {
      Eigen::Vector3d nn(read_component(nv, i, 0), read_component(nv, i, 1), read_component(nv, i, 2));
      nn = normal_matrix * nn;
      if (!nn.allFinite() || nn.norm() < 1e-12) return false;  // degenerate normals in the file: recompute them all
      nn.normalize();
      p.vertices[i].normal = {static_cast<float>(nn.x()), static_cast<float>(nn.y()), static_cast<float>(nn.z())};
    }
    return true;
  }

  void read_texcoords(const tinygltf::Primitive& prim, const std::string& what, Primitive& p) {
    const auto it = prim.attributes.find("TEXCOORD_0");
    if (it == prim.attributes.end()) return;
    const View tv = float_attribute(it->second, what + " TEXCOORD_0", {TINYGLTF_TYPE_VEC2}, true);
    if (tv.count != p.vertices.size()) fail(what + ": TEXCOORD_0 count differs from POSITION count");
    for (std::size_t i = 0; i < tv.count; ++i) {
      p.vertices[i].uv = {read_component(tv, i, 0), read_component(tv, i, 1)};
      if (!std::isfinite(p.vertices[i].uv[0]) || !std::isfinite(p.vertices[i].uv[1]))
        fail(what + ": TEXCOORD_0 " + std::to_string(i) + " is not finite");
    }
  }

  void read_colours(const tinygltf::Primitive& prim, const std::string& what, Primitive& p) {
    const auto it = prim.attributes.find("COLOR_0");
    if (it == prim.attributes.end()) return;
    const View cv = float_attribute(it->second, what + " COLOR_0", {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4}, true);
    if (cv.count != p.vertices.size()) fail(what + ": COLOR_0 count differs from POSITION count");
    const int comps = cv.type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
    for (std::size_t i = 0; i < cv.count; ++i)
      for (int c = 0; c < comps; ++c) {
        const float value = read_component(cv, i, c);
        if (!std::isfinite(value)) fail(what + ": COLOR_0 " + std::to_string(i) + " is not finite");
        p.vertices[i].color[static_cast<std::size_t>(c)] = value;
      }
  }

  // The primitive's indices, each checked against its n vertices; without an index accessor, 0..n-1.
  std::vector<std::uint32_t> read_indices(const tinygltf::Primitive& prim, const std::string& what, std::size_t n) {
    std::vector<std::uint32_t> raw;
    if (prim.indices < 0) {
      raw.resize(n);
      for (std::size_t i = 0; i < n; ++i) raw[i] = static_cast<std::uint32_t>(i);
      return raw;
    }
    const View iv = accessor_view(prim.indices, what + " indices");
    if (iv.type != TINYGLTF_TYPE_SCALAR) fail(what + ": indices must be scalars");
    raw.resize(iv.count);
    for (std::size_t i = 0; i < iv.count; ++i) {
      const unsigned char* q = iv.base + iv.stride * i;
      switch (iv.component_type) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          raw[i] = q[0];
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          std::uint16_t s;
          std::memcpy(&s, q, 2);
          raw[i] = s;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          std::memcpy(&raw[i], q, 4);
          break;
        default:
          fail(what + ": index component type " + std::to_string(iv.component_type) + " is not an unsigned integer");
      }
      if (raw[i] >= n)
        fail(what + ": index " + std::to_string(raw[i]) + " at position " + std::to_string(i) + " is out of range (" +
             std::to_string(n) + " vertices)");
    }
    return raw;
  }

  // Triangle lists, with strips and fans unrolled; `flip` swaps each triangle's winding.
  void unroll_triangles(const std::vector<std::uint32_t>& raw, int mode, bool flip, const std::string& what, Primitive& p) {
    auto emit = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
      if (flip) std::swap(b, c);
      p.indices.insert(p.indices.end(), {a, b, c});
    };
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (raw.size() % 3 != 0) fail(what + ": " + std::to_string(raw.size()) + " indices is not a multiple of 3");
      for (std::size_t i = 0; i + 2 < raw.size(); i += 3) emit(raw[i], raw[i + 1], raw[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (std::size_t i = 0; i + 2 < raw.size(); ++i)
        (i % 2 == 0) ? emit(raw[i], raw[i + 1], raw[i + 2]) : emit(raw[i + 1], raw[i], raw[i + 2]);
    } else {
      for (std::size_t i = 1; i + 1 < raw.size(); ++i) emit(raw[0], raw[i], raw[i + 1]);
    }
  }

  // Area-weighted vertex normals, for primitives without NORMAL.
  static void compute_normals(Primitive& p) {
    std::vector<Eigen::Vector3d> acc(p.vertices.size(), Eigen::Vector3d::Zero());
    auto at = [&](std::uint32_t i) {
      const auto& v = p.vertices[i].position;
      return Eigen::Vector3d(v[0], v[1], v[2]);
    };
    for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const auto a = p.indices[t], b = p.indices[t + 1], c = p.indices[t + 2];
      const Eigen::Vector3d fn = (at(b) - at(a)).cross(at(c) - at(a));  // length = 2 * area
      acc[a] += fn;
      acc[b] += fn;
      acc[c] += fn;
    }
    for (std::size_t i = 0; i < acc.size(); ++i) {
      const Eigen::Vector3d nn = acc[i].norm() > 0 ? acc[i].normalized() : Eigen::Vector3d::UnitZ();
      p.vertices[i].normal = {static_cast<float>(nn.x()), static_cast<float>(nn.y()), static_cast<float>(nn.z())};
    }
  }

  void load_images(Model& out) {
    for (std::size_t i = 0; i < g_.images.size(); ++i) {
      const auto& im = g_.images[i];
      const std::string name =
          "image " + std::to_string(i) + (im.uri.empty() || im.uri.rfind("data:", 0) == 0 ? "" : " ('" + im.uri + "')");
      Image img;
      if (im.image.empty() || im.width <= 0 || im.height <= 0) {
        // tinygltf keeps going when an image file is missing or undecodable; an unused image is harmless,
        // so record it empty and fail only if a material uses it.
        out.images.push_back(std::move(img));
        continue;
      }
      if (im.bits != 8 && im.bits != 16) fail(name + ": " + std::to_string(im.bits) + "-bit images are not supported");
      const int comps = im.component;
      if (comps < 1 || comps > 4) fail(name + ": " + std::to_string(comps) + " components per pixel");
      const std::size_t pixels = static_cast<std::size_t>(im.width) * static_cast<std::size_t>(im.height);
      const std::size_t bytes_per = static_cast<std::size_t>(im.bits / 8);
      if (im.image.size() < pixels * static_cast<std::size_t>(comps) * bytes_per) fail(name + ": decoded data is short");
      img.width = im.width;
      img.height = im.height;
      img.rgba.resize(pixels * 4);
      for (std::size_t px = 0; px < pixels; ++px) {
        std::uint8_t c[4] = {0, 0, 0, 255};
        for (int k = 0; k < comps; ++k) {
          // 16-bit: keep the high byte (big-endian in PNG, decoded to native by stb).
          const std::size_t off = (px * static_cast<std::size_t>(comps) + static_cast<std::size_t>(k)) * bytes_per;
          std::uint8_t value = im.image[off];
          if (bytes_per == 2) {
            std::uint16_t s;
            std::memcpy(&s, &im.image[off], 2);
            value = static_cast<std::uint8_t>(s >> 8);
          }
          c[k] = value;
        }
        if (comps == 1) c[1] = c[2] = c[0];
        if (comps == 2) {
          c[3] = c[1];
          c[1] = c[2] = c[0];
        }  // grey + alpha
        std::memcpy(&img.rgba[px * 4], c, 4);
      }
      out.images.push_back(std::move(img));
    }
  }
};

bool is_glb(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  return in.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
}

}  // namespace

namespace {

// tinygltf's own image loader, after a look at the size the header claims: a 20000 x 20000 texture was
// decoded into 1.6 GB and then refused as "Unknown image format".
bool load_checked_image(tinygltf::Image* image, const int index, std::string* err, std::string* warn, int width, int height,
                        const unsigned char* bytes, int size, void* user) {
  int w = 0, h = 0;
  if (detail::claimed_image_size(bytes, size, w, h) && (w > detail::kMaxTextureSide || h > detail::kMaxTextureSide)) {
    if (err != nullptr)
      *err += "image " + std::to_string(index) + ": " + std::to_string(w) + "x" + std::to_string(h) +
              " pixels, larger than the " + std::to_string(detail::kMaxTextureSide) + " pixels a side a texture may have";
    return false;
  }
  if (tinygltf::LoadImageData(image, index, err, warn, width, height, bytes, size, user)) return true;
  if (err != nullptr && image != nullptr && !image->uri.empty() && image->uri.rfind("data:", 0) != 0) {
    while (!err->empty() && (err->back() == '\n' || err->back() == ' ')) err->pop_back();
    *err += " (image " + std::to_string(index) + " is " + image->uri + ")\n";  // tinygltf names it by its index only
  }
  return false;
}

// Whether a file exists, without opening it (tinygltf's fopen()s it: on a FIFO that blocks).
bool file_exists(const std::string& file, void*) {
  std::error_code ec;
  return std::filesystem::exists(file, ec);
}

// tinygltf's file reader, after a look at what the file is: a buffer or image URI naming a FIFO would
// block in open(), /dev/zero read until memory ran out.
bool read_regular_file(std::vector<unsigned char>* out, std::string* err, const std::string& file, void* user) {
  if (const std::string kind = config::input_file_problem(file); !kind.empty()) {
    if (err != nullptr) *err += "'" + file + "' " + kind + "\n";
    return false;
  }
  return tinygltf::ReadWholeFile(out, err, file, user);
}

}  // namespace

Model load_gltf(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw AssetError(file + ": is a folder, not a model file (.gltf or .glb)");
  if (const std::string kind = config::input_file_problem(path); !kind.empty())
    throw AssetError(file + (kind == "does not exist" ? std::string(": no such model file") : ": " + kind));
  const std::string ext = detail::lowercase_extension(path);
  if (ext == ".glb" && !is_glb(path))
    throw AssetError(file + ": not a binary glTF: a .glb file starts with the bytes 'glTF' (wrong extension, or not a model?)");
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(load_checked_image, nullptr);
  loader.SetFsCallbacks({&file_exists, &tinygltf::ExpandFilePath, &read_regular_file, &tinygltf::WriteWholeFile, nullptr});
  tinygltf::Model gltf;
  std::string err;
  std::string warn;
  bool ok = false;
  try {
    ok = is_glb(path) ? loader.LoadBinaryFromFile(&gltf, &err, &warn, file) : loader.LoadASCIIFromFile(&gltf, &err, &warn, file);
  } catch (const std::bad_alloc&) {  // a valid file too large for what memory is left (many targets' copies)
    std::error_code size_ec;
    const auto bytes = std::filesystem::file_size(path, size_ec);
    throw AssetError(file + ": out of memory while reading it" + (size_ec ? "" : " (" + std::to_string(bytes) + " bytes)"));
  } catch (const std::exception& e) {  // nlohmann::json throws on some malformed input
    throw AssetError(file + ": malformed glTF: " + config::without_json_tag(e.what()));
  }
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    const bool json = config::has_json_tag(err);  // tinygltf passes the JSON library's text on
    throw AssetError(file + ": " +
                     (err.empty() ? std::string("tinygltf could not parse the file")
                      : json      ? "not valid JSON: " + config::without_json_tag(err)
                                  : err));
  }
  Model model = Loader(gltf, file).build(gltf.animations.empty() ? std::string() : detail::gltf_document_json(path));
  model.files = {path};
  const auto external = [&](const std::string& uri) {
    if (!uri.empty() && uri.rfind("data:", 0) != 0) model.files.push_back(path.parent_path() / uri);
  };
  for (const auto& b : gltf.buffers) external(b.uri);
  for (const auto& i : gltf.images) external(i.uri);
  return model;
}

}  // namespace projbot::assets
