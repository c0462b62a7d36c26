#pragma once
// CPU-side textured meshes: what the engine uploads and what alignment samples into points.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "projbot/assets/image.hpp"

namespace projbot::assets {

enum class AlphaMode { kOpaque, kMask, kBlend };
enum class Wrap { kRepeat, kClampToEdge, kMirroredRepeat };
enum class Filter { kNearest, kLinear };

/// Texture sampling state (glTF sampler; defaults: repeat, linear).
struct Sampler {
  Wrap wrap_s = Wrap::kRepeat;
  Wrap wrap_t = Wrap::kRepeat;
  Filter mag = Filter::kLinear;
  Filter min = Filter::kLinear;
};

/// Unlit material: a pixel shows texture * base_color_factor * vertex colour.
struct Material {
  std::string name;                                                ///< as the file names it (glTF), or empty
  std::array<float, 4> base_color_factor{1.0F, 1.0F, 1.0F, 1.0F};  ///< linear RGBA multiplier
  int base_color_image = -1;                                       ///< index into Model::images, -1 for none
  Sampler sampler;
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5F;  ///< used with kMask
  bool double_sided = false;
};

/// Interleaved vertex as uploaded to the GPU. Position in the model frame, metres.
struct Vertex {
  std::array<float, 3> position{};
  std::array<float, 3> normal{};                       ///< unit length, model frame
  std::array<float, 2> uv{};                           ///< TEXCOORD_0 (0,0 when absent)
  std::array<float, 4> color{1.0F, 1.0F, 1.0F, 1.0F};  ///< COLOR_0 (white when absent)
};

/// A triangle list with one material. Indices are counter-clockwise seen from the front.
struct Primitive {
  std::vector<Vertex> vertices;
  std::vector<std::uint32_t> indices;
  int material = 0;  ///< index into Model::materials
};

/// A whole model in its model frame (glTF scene frame with node transforms applied), metres.
struct Model {
  std::string source;  ///< file name, for messages
  std::vector<Primitive> primitives;
  std::vector<Material> materials;  ///< never empty after loading (a default material is added)
  std::vector<Image> images;

  std::size_t triangle_count() const;
  Eigen::AlignedBox3d bounds() const;
  /// Area-weighted centroid of the surface (the paper's model frame origin after recentring).
  Eigen::Vector3d surface_centroid() const;
};

/// Loads a glTF 2.0 file (.gltf with external or data-URI buffers, or .glb).
/// Throws AssetError naming the file and the problem; never returns a partly loaded model.
Model load_gltf(const std::filesystem::path& path);

/// Loads a PLY (binary or ASCII), OBJ (with its .mtl) or STL mesh through Assimp, in a child process (the
/// importers are not safe on hostile files). Faces are triangulated; normals come from the faces where the
/// file has none; UVs are flipped to glTF's top-left origin. A material's texture that is missing or
/// unreadable is a warning on stderr and the material keeps its base colour. Units as stored (scale with
/// scale_and_recenter). Throws AssetError naming the file; a file without faces is an error.
Model load_mesh(const std::filesystem::path& path);

/// load_gltf for .gltf / .glb, load_mesh for .ply / .obj / .stl; any other extension is an AssetError.
Model load_model(const std::filesystem::path& path);

/// Scales the model frame uniformly, then (if recenter) moves the origin to the surface centroid.
void scale_and_recenter(Model& model, double scale, bool recenter);

/// The texel column (or row) of n that texture coordinate t falls in, wrapped as given: 0..n-1.
int texel_index(double t, int n, Wrap wrap = Wrap::kRepeat);

/// The texel of `image` at texture coordinate (u, v), nearest, wrapped as given: RGB 0..1 as stored (white
/// for an empty image).
Eigen::Vector3f texel_colour(const Image& image, double u, double v, Wrap wrap_s = Wrap::kRepeat, Wrap wrap_t = Wrap::kRepeat);

/// The colour material `material` shows at texture coordinate (u, v) with vertex colour `vc`: texture
/// (nearest texel, the sampler's wrap) x base colour factor x vertex colour, RGB 0..1 as stored (what the
/// unlit renderer draws).
Eigen::Vector3f surface_colour(const Model& model, int material, double u, double v, const Eigen::Vector3f& vc);

/// Points with normals sampled uniformly by area over the surface, model frame.
struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points;
  std::vector<Eigen::Vector3f> normals;  ///< unit, from the triangle's geometric normal
  /// RGB 0..1 as stored: texture (nearest texel) x base colour factor x vertex colour, what the unlit
  /// renderer draws there.
  std::vector<Eigen::Vector3f> colours;
};

/// Samples `count` points uniformly over the model's surface area, reproducibly for a seed.
SurfaceSamples sample_surface(const Model& model, std::size_t count, std::uint32_t seed);

/// A textured UV sphere (rings x segments quads, two triangles each): a large mesh for benchmarks.
Model make_uv_sphere(double radius_m, int rings, int segments);

/// A box spanning [min, max] (metres, model frame), faces outward, one flat colour: floors, pedestals.
Model make_box(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const std::array<float, 4>& rgba);

}  // namespace projbot::assets
