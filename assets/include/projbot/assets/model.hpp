#pragma once
// CPU-side textured meshes: what the engine uploads and what alignment samples into points.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
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

/// A texture's placement (glTF KHR_texture_transform): uv' = T(offset) R(rotation) S(scale) uv, the rotation
/// counter-clockwise in UV space.
struct TextureTransform {
  std::array<double, 2> offset{0.0, 0.0};
  std::array<double, 2> scale{1.0, 1.0};
  double rotation_rad = 0.0;
  /// Row-major 2x3: u' = m0 u + m1 v + m2, v' = m3 u + m4 v + m5.
  std::array<double, 6> matrix() const;
  bool operator==(const TextureTransform&) const = default;
};

/// What of a material changes over time (issue 44): what glTF's KHR_animation_pointer channels and a
/// scene's content timeline animate.
struct MaterialState {
  std::array<float, 4> base_color_factor{1.0F, 1.0F, 1.0F, 1.0F};
  std::array<float, 3> emissive_factor{0.0F, 0.0F, 0.0F};  ///< glTF emissiveFactor
  float emissive_strength = 1.0F;                          ///< KHR_materials_emissive_strength
  TextureTransform base_color_transform;                   ///< of the base colour texture
  TextureTransform emissive_transform;                     ///< of the emissive texture
  bool operator==(const MaterialState&) const = default;
};

/// Unlit material: a pixel shows texture * base_color_factor * vertex colour, plus its emission
/// (emissive texture * emissive_factor * emissive_strength), each as stored.
struct Material {
  std::string name;                                                ///< as the file names it (glTF), or empty
  std::array<float, 4> base_color_factor{1.0F, 1.0F, 1.0F, 1.0F};  ///< linear RGBA multiplier
  int base_color_image = -1;                                       ///< index into Model::images, -1 for none
  Sampler sampler;
  AlphaMode alpha_mode = AlphaMode::kOpaque;
  float alpha_cutoff = 0.5F;  ///< used with kMask
  bool double_sided = false;
  std::array<float, 3> emissive_factor{0.0F, 0.0F, 0.0F};  ///< 0: no emission
  float emissive_strength = 1.0F;
  int emissive_image = -1;  ///< index into Model::images, -1 for none (white)
  Sampler emissive_sampler;
  /// The base colour texture's transform as loaded: already baked into the primitives' texture coordinates
  /// (what the CPU samplers and the renderer read), kept to place an animated one relative to it.
  TextureTransform base_color_transform;
  TextureTransform emissive_transform;  ///< the emissive texture's, from the file's texture coordinates

  /// Its state as loaded.
  MaterialState state() const;
};

/// One glTF KHR_animation_pointer channel on a material property, sampled as glTF says (step, linear, or
/// cubic spline with in- and out-tangents).
struct MaterialChannel {
  enum class Property {
    kBaseColorFactor,    // 4 numbers
    kEmissiveFactor,     // 3
    kEmissiveStrength,   // 1
    kBaseColorOffset,    // 2
    kBaseColorScale,     // 2
    kBaseColorRotation,  // 1
    kEmissiveOffset,     // 2
    kEmissiveScale,      // 2
    kEmissiveRotation    // 1
  };
  enum class Interpolation { kStep, kLinear, kCubicSpline };
  int material = 0;
  Property property = Property::kBaseColorFactor;
  Interpolation interpolation = Interpolation::kLinear;
  std::vector<float> times;   ///< seconds, increasing
  std::vector<float> values;  ///< width(property) numbers per time; cubic spline: in-tangent, value, out-tangent
  /// The numbers a value of `p` has.
  static int width(Property p);
};

/// A glTF animation's material channels, repeating every duration_s (its last key's time).
struct MaterialAnimation {
  std::string name;
  double duration_s = 0.0;
  std::vector<MaterialChannel> channels;
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
  /// The files it was read from: the model file, a glTF's external buffers and images, a mesh's
  /// textures and an OBJ's material libraries (what `run` watches for changes).
  std::vector<std::filesystem::path> files;
  std::vector<Primitive> primitives;
  std::vector<Material> materials;  ///< never empty after loading (a default material is added)
  std::vector<Image> images;
  /// The file's animations of material properties (KHR_animation_pointer); node animations are not kept.
  std::vector<MaterialAnimation> material_animations;

  std::size_t triangle_count() const;
  Eigen::AlignedBox3d bounds() const;
  /// Area-weighted centroid of the surface (the paper's model frame origin after recentring).
  Eigen::Vector3d surface_centroid() const;
};

/// Loads a glTF 2.0 file (.gltf with external or data-URI buffers, or .glb).
/// Throws AssetError naming the file and the problem; never returns a partly loaded model.
/// Honours KHR_texture_transform (the base colour texture's baked into the UVs), KHR_materials_emissive_strength
/// and KHR_animation_pointer on material properties (Model::material_animations); node animations are not
/// played (the object does not move with them: one warning per file).
Model load_gltf(const std::filesystem::path& path);

/// Each animated material's state at `t_s` seconds: every animation plays from 0 and repeats over its own
/// duration (a negative time is its first key); a channel sets its property over the material's state as
/// loaded. Pairs of (material index, state), by material; empty for a model without material animations.
std::vector<std::pair<int, MaterialState>> animate_materials(const Model& model, double t_s);

/// Loads a PLY (binary or ASCII), OBJ (with its .mtl) or STL mesh through Assimp, in a child process (the
/// importers are not safe on hostile files). Faces are triangulated; normals come from the faces where the
/// file has none; UVs are flipped to glTF's top-left origin. A material's texture that is missing or
/// unreadable is a warning on stderr and the material keeps its base colour. Units as stored (scale with
/// scale_and_recenter). Throws AssetError naming the file; a file without faces is an error.
Model load_mesh(const std::filesystem::path& path);

/// load_gltf for .gltf / .glb, load_mesh for .ply / .obj / .stl; any other extension is an AssetError.
Model load_model(const std::filesystem::path& path);

/// The files loading `path` reads, listed without loading it (a command checks its outputs against them
/// before any work): the file itself, a glTF's external buffers and images, an OBJ's material libraries
/// and the texture maps they name. What cannot be read is left out: the loader names it when it loads.
std::vector<std::filesystem::path> model_files(const std::filesystem::path& path);

/// Writes the model's triangles as one binary PLY mesh (vertices with normals; no materials), positions
/// times `units_per_metre` (1000: BOP's millimetres), atomically. Throws AssetError naming the file.
void write_ply(const std::filesystem::path& path, const Model& model, double units_per_metre);

/// Scales the model frame uniformly, then (if recenter) moves the origin to the surface centroid.
void scale_and_recenter(Model& model, double scale, bool recenter);

/// Whether any vertex of `model` has texture coordinates other than (0, 0): a texture can be laid on it.
bool has_texture_coordinates(const Model& model);

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
