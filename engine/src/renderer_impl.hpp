#pragma once
// Internal to the engine: the renderer's state (Renderer::Impl) and the types it keeps on the GPU, shared
// by renderer_resources.cpp (models, textures, streamed frames, pipelines) and renderer.cpp (frames).

#include <cstdint>
#include <map>
#include <memory>
#include <tuple>
#include <vector>

#include "gpu.hpp"
#include "projbot/config/lens.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::engine {
namespace detail {

inline constexpr std::size_t kFramesInFlight = 2;

/// Push constants of mesh.vert / mesh.frag (std430 layout: 128 bytes, the size Vulkan guarantees).
struct DrawConstants {
  std::array<float, 16> clip_from_model;
  std::array<float, 4> base_color_factor;
  std::array<float, 4> compensate;  // Compensation::scale_lux (0: off), ambient_lux
  std::array<float, 4> projector;   // white_gain, -, -, alpha cutoff
  std::array<float, 4> ray;         // the projector-frame position from clip coordinates (mesh.vert)
};
static_assert(sizeof(DrawConstants) == 128);

/// mesh.frag's set 1 (std140: 64 bytes): the rows of the projector's mixing matrix's inverse, then the
/// inverse of each channel's gamma and the black level. Per frame in flight, written before its frame.
struct FrameUniform {
  std::array<float, 16> values;
};
static_assert(sizeof(FrameUniform) == 64);

inline FrameUniform frame_uniform(const config::Photometry& p) {
  FrameUniform u{};
  const Eigen::Matrix3d unmix = p.mixing.inverse();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) u.values[static_cast<std::size_t>(4 * r + c)] = static_cast<float>(unmix(r, c));
  for (std::size_t i = 0; i < 3; ++i) u.values[12 + i] = static_cast<float>(1.0 / p.gamma_rgb[i]);
  u.values[15] = static_cast<float>(p.black_level);
  return u;
}

/// mesh.frag's per-draw material block (set 1 binding 1, a dynamic uniform buffer; std140: 80 bytes): the
/// emission, and where the base colour and emissive textures lie over the model's texture coordinates (the
/// base colour transform as loaded is baked into those), as the rows of two 2x3 matrices.
struct DrawUniform {
  std::array<float, 4> emissive;     // rgb: emissive factor x strength
  std::array<float, 8> base_uv;      // rows (xyz_) of the base colour texture's placement
  std::array<float, 8> emissive_uv;  // rows of the emissive texture's
};
static_assert(sizeof(DrawUniform) == 80);

/// A material's block in a draw where its state is `now` (its state as loaded, or animated).
DrawUniform draw_uniform(const assets::Material& loaded, const assets::MaterialState& now);

/// What every draw of a frame shares: full white's lux at 1 m, and how mesh.vert recovers the
/// projector-frame position from clip coordinates (x = (clip.x - m02 clip.w) / m00, likewise y).
inline DrawConstants frame_constants(const config::ProjectorConfig& projector, const Eigen::Matrix4d& clip_from_projector_m) {
  DrawConstants c{};
  c.projector = {static_cast<float>(white_gain(projector)), 0.0F, 0.0F, 0.0F};
  c.ray = {static_cast<float>(1.0 / clip_from_projector_m(0, 0)),
           static_cast<float>(-clip_from_projector_m(0, 2) / clip_from_projector_m(0, 0)),
           static_cast<float>(1.0 / clip_from_projector_m(1, 1)),
           static_cast<float>(-clip_from_projector_m(1, 2) / clip_from_projector_m(1, 1))};
  return c;
}

/// Whether two projectors draw the same lens canvas.
inline bool same_lens(const config::ProjectorConfig& a, const config::ProjectorConfig& b) {
  return a.width_px == b.width_px && a.height_px == b.height_px && a.fx_px == b.fx_px && a.fy_px == b.fy_px &&
         a.cx_px == b.cx_px && a.cy_px == b.cy_px && a.distortion == b.distortion;
}

/// The mesh shaders' specialisation constants (constant_id 0, 1, 2): glTF's alpha mode; whether the draw's
/// textures are placed other than over the model's UVs as they are (an animated KHR_texture_transform, an
/// emissive texture's own); whether it emits. A draw without either runs the shaders as they were before
/// materials moved (no per-vertex placement, no emissive fetch): on lavapipe that kept the 1080p frame of
/// the 100k-triangle sphere at its former time.
struct Shading {
  std::int32_t alpha_mode = 0;
  vk::Bool32 placed = VK_FALSE;
  vk::Bool32 emissive = VK_FALSE;
};

/// How a draw whose material block is `u` shades (alpha mode aside).
Shading shading(const DrawUniform& u);

/// The fragment shader's kAlphaMode specialisation constant.
inline std::int32_t alpha_mode_id(assets::AlphaMode mode) {
  return mode == assets::AlphaMode::kOpaque ? 0 : mode == assets::AlphaMode::kMask ? 1 : 2;
}

/// What a vertex is on the GPU: 24 bytes, half of assets::Vertex. The projector pass needs no normal, and
/// COLOR_0 as UNORM8 is exact for 8-bit glTF colours and within half a step of the 8-bit output otherwise.
struct GpuVertex {
  std::array<float, 3> position;
  std::array<float, 2> uv;
  std::array<std::uint8_t, 4> color;
};
static_assert(sizeof(GpuVertex) == 24);

inline GpuVertex to_gpu(const assets::Vertex& v) {
  GpuVertex g{v.position, v.uv, {}};
  for (std::size_t k = 0; k < 4; ++k)
    g.color[k] = static_cast<std::uint8_t>(std::lround(std::clamp(v.color[k], 0.0F, 1.0F) * 255.0F));
  return g;
}

inline vk::SamplerAddressMode to_vk(assets::Wrap w) {
  switch (w) {
    case assets::Wrap::kClampToEdge:
      return vk::SamplerAddressMode::eClampToEdge;
    case assets::Wrap::kMirroredRepeat:
      return vk::SamplerAddressMode::eMirroredRepeat;
    default:
      return vk::SamplerAddressMode::eRepeat;
  }
}

inline vk::Filter to_vk(assets::Filter f) { return f == assets::Filter::kNearest ? vk::Filter::eNearest : vk::Filter::eLinear; }

// A model on the GPU: one vertex and one index buffer for all its primitives, its textures, and one
// descriptor set per material.
struct GpuModel {
  struct Part {
    std::uint32_t first_index = 0;
    std::uint32_t index_count = 0;
    std::int32_t vertex_offset = 0;
    std::size_t material = 0;
  };
  Buffer vertices;
  Buffer indices;
  std::vector<Part> parts;
  std::vector<assets::Material> materials;
  std::vector<detail::Image> textures;
  std::vector<vk::raii::Sampler> samplers;  // two per material: its base colour's, then its emission's
  vk::raii::DescriptorPool pool{nullptr};
  std::vector<vk::raii::DescriptorSet> sets;  // one per material: binding 0 its base colour, 1 the surface, 2 its emission
  detail::Image surface;                      // Renderer::set_surface's, sRGB; none: `white` is bound
  std::map<int, std::size_t> streamed;        // material -> the streamed texture bound as its base colour
};

// A texture rewritten while it is drawn (a video on a material): the image the material samples, and one
// staging buffer per frame slot that has uploaded into it (reused only after that slot's fence).
struct StreamedTexture {
  detail::Image image;
  std::map<const detail::FrameSlot*, Buffer> staging;
  std::shared_ptr<const assets::Image> pending;  // texels for the next frame, copied into staging
  const Buffer* pending_buffer = nullptr;        // or texels already in host memory the GPU copies from
  std::shared_ptr<const void> pending_keep;      // what keeps pending_buffer's contents unchanged
};

// Host memory handed out for decoding into (Renderer::frame_memory): the GPU copies textures from it.
struct HostFrameBuffer {
  std::shared_ptr<Gpu> gpu;  // first: outlives the buffer
  Buffer buffer;
};

}  // namespace detail

using detail::Buffer;
using detail::Gpu;
using detail::GpuModel;
using detail::HostFrameBuffer;
using detail::StreamedTexture;

struct Renderer::Impl {
  std::shared_ptr<Gpu> gpu;
  vk::raii::DescriptorSetLayout set_layout{nullptr};
  vk::raii::DescriptorSetLayout frame_set_layout{nullptr};  // set 1: FrameUniform
  vk::raii::PipelineLayout pipeline_layout{nullptr};
  vk::raii::ShaderModule vert{nullptr};
  vk::raii::ShaderModule frag{nullptr};
  vk::raii::ShaderModule depth_frag{nullptr};
  // (format, cull back, alpha mode, placed, emissive, depth camera)
  std::map<std::tuple<vk::Format, bool, std::int32_t, vk::Bool32, vk::Bool32, bool>, vk::raii::Pipeline> pipelines;
  // The lens pass (a projector with distortion): one full-target triangle sampling the canvas.
  vk::raii::PipelineLayout lens_layout{nullptr};
  vk::raii::ShaderModule lens_vert{nullptr};
  vk::raii::ShaderModule lens_frag{nullptr};
  vk::raii::Sampler lens_sampler{nullptr};
  vk::raii::Sampler warp_sampler{nullptr};                 // nearest: the warp map is read texel for texel
  vk::raii::DescriptorSetLayout lens_set_layout{nullptr};  // the canvas and the warp map
  std::map<vk::Format, vk::raii::Pipeline> lens_pipelines;
  detail::Image white;                         // bound where a material has no texture, and as a surface's reflectance until set
  vk::raii::Sampler surface_sampler{nullptr};  // a surface's reflectance: linear, repeating
  std::vector<GpuModel> models;
  std::vector<StreamedTexture> streamed;
  std::vector<DrawItem> items;
  std::uint64_t frame_index = 0;

  explicit Impl(const RendererOptions& options);

  ~Impl();

  detail::Image upload_texture(const assets::Image& img);

  // A sampled image of `format` holding `bytes`, ready for fragment shaders to read.
  detail::Image upload_image(vk::Extent2D extent, vk::Format format, const void* bytes, std::size_t size);

  // A whole colour image from `from`, left for fragment shaders to read; `before` is the image's layout
  // and the last use to wait for.
  static void record_image_copy(const vk::raii::CommandBuffer& cmd, vk::Buffer from, const detail::Image& image,
                                vk::ImageLayout before, vk::PipelineStageFlags2 before_stage, vk::AccessFlags2 before_access);

  // One pipeline builder: every variant differs only in target format, culling and blending.
  const vk::raii::Pipeline& pipeline(vk::Format format, bool cull_back, const detail::Shading& shading, bool depth_camera);

  const vk::raii::Pipeline& lens_pipeline(vk::Format format);

  // The target's canvas at the pixel density of the target, (re)made when its size, its format or the
  // projector's lens changes (the canvas's size and the warp map follow from those three).
  detail::LensCanvasImages& ensure_canvas(detail::TargetBackend& t, const config::ProjectorConfig& p);

  // A model's buffers, textures and descriptor sets (its surface white).
  GpuModel make_gpu_model(const assets::Model& model);
  /// The model's vertex and index buffers on the device; EngineError naming the file and its triangle count
  /// when they pass the device's limits (not Vulkan's bare ErrorOutOfDeviceMemory).
  void upload_geometry(GpuModel& g, const assets::Model& model, const std::vector<detail::GpuVertex>& vertices,
                       const std::vector<std::uint32_t>& indices);
  std::size_t add_model(const assets::Model& model);
  void replace_model(std::size_t model, const assets::Model& fresh);
  void set_surface(std::size_t model, const assets::Image& reflectance);
  // A material's texture (`image` in the model's, -1: white) and a sampler of its own at `binding` of `set`.
  void bind_material_texture(GpuModel& g, vk::DescriptorSet set, std::uint32_t binding, int image, const assets::Sampler& sampler,
                             const std::string& what);
  // Binds `view` as each of model g's materials' surface (binding 1).
  void bind_surface(GpuModel& g, vk::ImageView view);

  // Model `model`'s uploaded copy, checked to have material `material`.
  GpuModel& model_with_material(std::size_t model, int material);

  std::size_t add_streamed_texture(std::size_t model, int material, int width, int height);

  void bind_streamed_texture(std::size_t id, std::size_t model, int material);

  assets::PixelMemory frame_memory(std::size_t bytes);

  void stream_pixels(std::size_t id, const assets::PixelMemory& pixels, std::shared_ptr<const void> keep);

  void stream_frame(std::size_t id, std::shared_ptr<const assets::Image> image);

  // The pending texels of every streamed texture into this slot's staging memory (the render thread's
  // share of an upload: one copy), and the GPU's copy into the image before anything draws.
  // Returns the number of textures uploaded.
  std::size_t record_uploads(const vk::raii::CommandBuffer& cmd, detail::FrameSlot& slot);

  void ensure_slots(detail::TargetBackend& t);
  // The slot's material blocks: room for `count` draws (grown when short; its last frame is retired).
  void ensure_draw_blocks(detail::FrameSlot& slot, std::size_t count);
  vk::DeviceSize draw_stride = 0;  // a material block's size rounded up to the device's uniform offset alignment

  // A slot's FrameUniform buffer (host visible, mapped) and its descriptor set.
  void make_frame_set(detail::FrameSlot& slot);

  // Waits for a slot's previous frame and hands its timing to its profiler.
  void retire(detail::TargetBackend& t, std::size_t index);
  void record_copy(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::Image color, std::size_t slot);

  // `projector`: the pinhole drawn through (a lens canvas's, or the projector's); `panel`: the projector
  // whose light compensation divides out.
  // `slot`'s material blocks are written from `first_block` on; returns the next free one.
  std::size_t record_draws(const vk::raii::CommandBuffer& cmd, vk::Format format, const config::ProjectorConfig& projector,
                           bool depth_camera, const config::ProjectorConfig& panel, detail::FrameSlot& slot,
                           std::size_t first_block);

  static void transition_depth(const vk::raii::CommandBuffer& cmd, vk::Image depth);

  // Dynamic rendering into `color` (and `depth`, when given) over the whole of `extent`, cleared to black.
  static void begin_pass(const vk::raii::CommandBuffer& cmd, vk::ImageView color, vk::ImageView depth, vk::Extent2D extent,
                         const std::array<float, 4>& clear);
  std::array<float, 4> background{0.0F, 0.0F, 0.0F, 1.0F};  // set_background's, for a projector's frames

  // The lens pass's first half: the models through the canvas's pinhole, left ready to sample. One canvas
  // serves both frames in flight: the barriers order this frame's drawing after the last frame's sampling.
  void record_canvas(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, detail::FrameSlot& slot);

  // The lens pass's second half: every target pixel takes the canvas at its panel position's ray.
  // (ensure_canvas made its warp map for this projector and target size.)
  void record_lens(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::ImageView color);

  bool draw_frame(detail::TargetBackend& t, const config::ProjectorConfig& projector, const PoseReader& read_poses,
                  FrameProfiler* profiler);
};

}  // namespace projbot::engine
