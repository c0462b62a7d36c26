// The projector pass: uploads models, builds pipelines, records and submits frames in flight.

#include "projbot/engine/renderer.hpp"

#include <projbot/shaders/depth.frag.spv.h>
#include <projbot/shaders/lens.frag.spv.h>
#include <projbot/shaders/lens.vert.spv.h>
#include <projbot/shaders/mesh.frag.spv.h>
#include <projbot/shaders/mesh.vert.spv.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "gpu.hpp"
#include "projbot/config/lens.hpp"
#include "projbot/engine/projection.hpp"

namespace projbot::engine {
namespace {

using detail::Buffer;
using detail::Gpu;

constexpr std::size_t kFramesInFlight = 2;

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

FrameUniform frame_uniform(const config::Photometry& p) {
  FrameUniform u{};
  const Eigen::Matrix3d unmix = p.mixing.inverse();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) u.values[static_cast<std::size_t>(4 * r + c)] = static_cast<float>(unmix(r, c));
  for (std::size_t i = 0; i < 3; ++i) u.values[12 + i] = static_cast<float>(1.0 / p.gamma_rgb[i]);
  u.values[15] = static_cast<float>(p.black_level);
  return u;
}

/// What every draw of a frame shares: full white's lux at 1 m, and how mesh.vert recovers the
/// projector-frame position from clip coordinates (x = (clip.x - m02 clip.w) / m00, likewise y).
DrawConstants frame_constants(const config::ProjectorConfig& projector, const Eigen::Matrix4d& clip_from_projector_m) {
  DrawConstants c{};
  c.projector = {static_cast<float>(white_gain(projector)), 0.0F, 0.0F, 0.0F};
  c.ray = {static_cast<float>(1.0 / clip_from_projector_m(0, 0)),
           static_cast<float>(-clip_from_projector_m(0, 2) / clip_from_projector_m(0, 0)),
           static_cast<float>(1.0 / clip_from_projector_m(1, 1)),
           static_cast<float>(-clip_from_projector_m(1, 2) / clip_from_projector_m(1, 1))};
  return c;
}

/// Whether two projectors draw the same lens canvas.
bool same_lens(const config::ProjectorConfig& a, const config::ProjectorConfig& b) {
  return a.width_px == b.width_px && a.height_px == b.height_px && a.fx_px == b.fx_px && a.fy_px == b.fy_px &&
         a.cx_px == b.cx_px && a.cy_px == b.cy_px && a.distortion == b.distortion;
}

/// The fragment shader's kAlphaMode specialisation constant.
std::int32_t alpha_mode_id(assets::AlphaMode mode) {
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

GpuVertex to_gpu(const assets::Vertex& v) {
  GpuVertex g{v.position, v.uv, {}};
  for (std::size_t k = 0; k < 4; ++k)
    g.color[k] = static_cast<std::uint8_t>(std::lround(std::clamp(v.color[k], 0.0F, 1.0F) * 255.0F));
  return g;
}

vk::SamplerAddressMode to_vk(assets::Wrap w) {
  switch (w) {
    case assets::Wrap::kClampToEdge:
      return vk::SamplerAddressMode::eClampToEdge;
    case assets::Wrap::kMirroredRepeat:
      return vk::SamplerAddressMode::eMirroredRepeat;
    default:
      return vk::SamplerAddressMode::eRepeat;
  }
}

vk::Filter to_vk(assets::Filter f) { return f == assets::Filter::kNearest ? vk::Filter::eNearest : vk::Filter::eLinear; }

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
  std::vector<vk::raii::Sampler> samplers;
  vk::raii::DescriptorPool pool{nullptr};
  std::vector<vk::raii::DescriptorSet> sets;  // one per material
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

}  // namespace

struct Renderer::Impl {
  std::shared_ptr<Gpu> gpu;
  vk::raii::DescriptorSetLayout set_layout{nullptr};
  vk::raii::DescriptorSetLayout frame_set_layout{nullptr};  // set 1: FrameUniform
  vk::raii::PipelineLayout pipeline_layout{nullptr};
  vk::raii::ShaderModule vert{nullptr};
  vk::raii::ShaderModule frag{nullptr};
  vk::raii::ShaderModule depth_frag{nullptr};
  // (format, cull back, alpha mode, depth camera)
  std::map<std::tuple<vk::Format, bool, std::int32_t, bool>, vk::raii::Pipeline> pipelines;
  // The lens pass (a projector with distortion): one full-target triangle sampling the canvas.
  vk::raii::PipelineLayout lens_layout{nullptr};
  vk::raii::ShaderModule lens_vert{nullptr};
  vk::raii::ShaderModule lens_frag{nullptr};
  vk::raii::Sampler lens_sampler{nullptr};
  vk::raii::Sampler warp_sampler{nullptr};                 // nearest: the warp map is read texel for texel
  vk::raii::DescriptorSetLayout lens_set_layout{nullptr};  // the canvas and the warp map
  std::map<vk::Format, vk::raii::Pipeline> lens_pipelines;
  detail::Image white;  // bound where a material has no texture
  std::vector<GpuModel> models;
  std::vector<StreamedTexture> streamed;
  std::vector<DrawItem> items;
  std::uint64_t frame_index = 0;

  explicit Impl(const RendererOptions& options) : gpu(std::make_shared<Gpu>(options)) {
    vk::DescriptorSetLayoutBinding binding(0, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment);
    set_layout = vk::raii::DescriptorSetLayout(gpu->device, vk::DescriptorSetLayoutCreateInfo({}, binding));
    vk::PushConstantRange push(vk::ShaderStageFlagBits::eVertex | vk::ShaderStageFlagBits::eFragment, 0, sizeof(DrawConstants));
    vk::DescriptorSetLayoutBinding frame_binding(0, vk::DescriptorType::eUniformBuffer, 1, vk::ShaderStageFlagBits::eFragment);
    frame_set_layout = vk::raii::DescriptorSetLayout(gpu->device, vk::DescriptorSetLayoutCreateInfo({}, frame_binding));
    const vk::DescriptorSetLayout layouts[] = {*set_layout, *frame_set_layout};
    pipeline_layout = vk::raii::PipelineLayout(gpu->device, vk::PipelineLayoutCreateInfo({}, layouts, push));
    vert = vk::raii::ShaderModule(gpu->device, vk::ShaderModuleCreateInfo({}, sizeof(k_mesh_vert_spv), k_mesh_vert_spv));
    frag = vk::raii::ShaderModule(gpu->device, vk::ShaderModuleCreateInfo({}, sizeof(k_mesh_frag_spv), k_mesh_frag_spv));
    depth_frag = vk::raii::ShaderModule(gpu->device, vk::ShaderModuleCreateInfo({}, sizeof(k_depth_frag_spv), k_depth_frag_spv));
    const vk::DescriptorSetLayoutBinding lens_bindings[] = {
        {0, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment},
        {1, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment}};
    lens_set_layout = vk::raii::DescriptorSetLayout(gpu->device, vk::DescriptorSetLayoutCreateInfo({}, lens_bindings));
    const vk::DescriptorSetLayout lens_layouts[] = {*lens_set_layout};
    lens_layout = vk::raii::PipelineLayout(gpu->device, vk::PipelineLayoutCreateInfo({}, lens_layouts, {}));
    lens_vert = vk::raii::ShaderModule(gpu->device, vk::ShaderModuleCreateInfo({}, sizeof(k_lens_vert_spv), k_lens_vert_spv));
    lens_frag = vk::raii::ShaderModule(gpu->device, vk::ShaderModuleCreateInfo({}, sizeof(k_lens_frag_spv), k_lens_frag_spv));
    lens_sampler = vk::raii::Sampler(
        gpu->device, vk::SamplerCreateInfo({}, vk::Filter::eLinear, vk::Filter::eLinear, vk::SamplerMipmapMode::eNearest,
                                           vk::SamplerAddressMode::eClampToEdge, vk::SamplerAddressMode::eClampToEdge,
                                           vk::SamplerAddressMode::eClampToEdge));
    warp_sampler = vk::raii::Sampler(
        gpu->device, vk::SamplerCreateInfo({}, vk::Filter::eNearest, vk::Filter::eNearest, vk::SamplerMipmapMode::eNearest,
                                           vk::SamplerAddressMode::eClampToEdge, vk::SamplerAddressMode::eClampToEdge,
                                           vk::SamplerAddressMode::eClampToEdge));
    assets::Image w;
    w.width = w.height = 1;
    w.rgba = {255, 255, 255, 255};
    white = upload_texture(w);
  }

  ~Impl() {
    if (*gpu->device) gpu->device.waitIdle();
  }

  detail::Image upload_texture(const assets::Image& img) {
    // UNORM, not SRGB: texels reach the target exactly as stored in the file.
    return upload_image(vk::Extent2D(static_cast<std::uint32_t>(img.width), static_cast<std::uint32_t>(img.height)),
                        vk::Format::eR8G8B8A8Unorm, img.rgba.data(), img.rgba.size());
  }

  // A sampled image of `format` holding `bytes`, ready for fragment shaders to read.
  detail::Image upload_image(vk::Extent2D extent, vk::Format format, const void* bytes, std::size_t size) {
    detail::Image tex = gpu->make_image(extent, format, vk::ImageUsageFlagBits::eSampled | vk::ImageUsageFlagBits::eTransferDst,
                                        vk::ImageAspectFlagBits::eColor);
    Buffer staging = gpu->make_buffer(size, vk::BufferUsageFlagBits::eTransferSrc,
                                      vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
    std::memcpy(staging.mapped, bytes, size);
    gpu->one_shot([&](vk::raii::CommandBuffer& cmd) {
      record_image_copy(cmd, *staging.buffer, tex, vk::ImageLayout::eUndefined, vk::PipelineStageFlagBits2::eNone,
                        vk::AccessFlagBits2::eNone);
    });
    return tex;
  }

  // A whole colour image from `from`, left for fragment shaders to read; `before` is the image's layout
  // and the last use to wait for.
  static void record_image_copy(const vk::raii::CommandBuffer& cmd, vk::Buffer from, const detail::Image& image,
                                vk::ImageLayout before, vk::PipelineStageFlags2 before_stage, vk::AccessFlags2 before_access) {
    detail::transition(cmd, *image.image, vk::ImageAspectFlagBits::eColor, before, vk::ImageLayout::eTransferDstOptimal,
                       before_stage, before_access, vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferWrite);
    cmd.copyBufferToImage(from, *image.image, vk::ImageLayout::eTransferDstOptimal,
                          vk::BufferImageCopy(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 1),
                                              {0, 0, 0}, vk::Extent3D(image.extent, 1)));
    detail::transition(cmd, *image.image, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eTransferDstOptimal,
                       vk::ImageLayout::eShaderReadOnlyOptimal, vk::PipelineStageFlagBits2::eCopy,
                       vk::AccessFlagBits2::eTransferWrite, vk::PipelineStageFlagBits2::eFragmentShader,
                       vk::AccessFlagBits2::eShaderSampledRead);
  }

  // One pipeline builder: every variant differs only in target format, culling and blending.
  const vk::raii::Pipeline& pipeline(vk::Format format, bool cull_back, std::int32_t alpha_mode, bool depth_camera) {
    const auto key = std::make_tuple(format, cull_back, alpha_mode, depth_camera);
    if (auto it = pipelines.find(key); it != pipelines.end()) return it->second;
    const bool blend = alpha_mode == 2;
    const vk::SpecializationMapEntry entry(0, 0, sizeof(std::int32_t));
    const vk::SpecializationInfo specialization(1, &entry, sizeof(alpha_mode), &alpha_mode);
    const vk::PipelineShaderStageCreateInfo stages[] = {{{}, vk::ShaderStageFlagBits::eVertex, *vert, "main"},
                                                        {{},
                                                         vk::ShaderStageFlagBits::eFragment,
                                                         depth_camera ? *depth_frag : *frag,
                                                         "main",
                                                         depth_camera ? nullptr : &specialization}};
    vk::VertexInputBindingDescription binding(0, sizeof(GpuVertex), vk::VertexInputRate::eVertex);
    const vk::VertexInputAttributeDescription attributes[] = {{0, 0, vk::Format::eR32G32B32Sfloat, offsetof(GpuVertex, position)},
                                                              {1, 0, vk::Format::eR32G32Sfloat, offsetof(GpuVertex, uv)},
                                                              {2, 0, vk::Format::eR8G8B8A8Unorm, offsetof(GpuVertex, color)}};
    vk::PipelineVertexInputStateCreateInfo vertex_input({}, binding, attributes);
    vk::PipelineInputAssemblyStateCreateInfo assembly({}, vk::PrimitiveTopology::eTriangleList);
    vk::PipelineViewportStateCreateInfo viewport({}, 1, nullptr, 1, nullptr);
    // With y down in both the OpenCV image and Vulkan's framebuffer, glTF's counter-clockwise front
    // faces stay counter-clockwise on screen.
    vk::PipelineRasterizationStateCreateInfo raster({}, VK_FALSE, VK_FALSE, vk::PolygonMode::eFill,
                                                    cull_back ? vk::CullModeFlagBits::eBack : vk::CullModeFlagBits::eNone,
                                                    vk::FrontFace::eCounterClockwise, VK_FALSE, 0, 0, 0, 1.0F);
    vk::PipelineMultisampleStateCreateInfo multisample({}, vk::SampleCountFlagBits::e1);
    vk::PipelineDepthStencilStateCreateInfo depth({}, VK_TRUE, blend ? VK_FALSE : VK_TRUE, vk::CompareOp::eLess);
    vk::PipelineColorBlendAttachmentState attachment(blend ? VK_TRUE : VK_FALSE, vk::BlendFactor::eSrcAlpha,
                                                     vk::BlendFactor::eOneMinusSrcAlpha, vk::BlendOp::eAdd, vk::BlendFactor::eOne,
                                                     vk::BlendFactor::eOneMinusSrcAlpha, vk::BlendOp::eAdd,
                                                     vk::ColorComponentFlagBits::eR | vk::ColorComponentFlagBits::eG |
                                                         vk::ColorComponentFlagBits::eB | vk::ColorComponentFlagBits::eA);
    vk::PipelineColorBlendStateCreateInfo blending({}, VK_FALSE, vk::LogicOp::eCopy, attachment);
    const vk::DynamicState dynamic_states[] = {vk::DynamicState::eViewport, vk::DynamicState::eScissor};
    vk::PipelineDynamicStateCreateInfo dynamic({}, dynamic_states);
    vk::PipelineRenderingCreateInfo rendering(0, format, detail::kDepthFormat);
    vk::GraphicsPipelineCreateInfo info({}, stages, &vertex_input, &assembly, nullptr, &viewport, &raster, &multisample, &depth,
                                        &blending, &dynamic, *pipeline_layout);
    info.pNext = &rendering;
    return pipelines.emplace(key, vk::raii::Pipeline(gpu->device, nullptr, info)).first->second;
  }

  const vk::raii::Pipeline& lens_pipeline(vk::Format format) {
    if (auto it = lens_pipelines.find(format); it != lens_pipelines.end()) return it->second;
    const vk::PipelineShaderStageCreateInfo stages[] = {{{}, vk::ShaderStageFlagBits::eVertex, *lens_vert, "main"},
                                                        {{}, vk::ShaderStageFlagBits::eFragment, *lens_frag, "main"}};
    vk::PipelineVertexInputStateCreateInfo vertex_input;
    vk::PipelineInputAssemblyStateCreateInfo assembly({}, vk::PrimitiveTopology::eTriangleList);
    vk::PipelineViewportStateCreateInfo viewport({}, 1, nullptr, 1, nullptr);
    vk::PipelineRasterizationStateCreateInfo raster({}, VK_FALSE, VK_FALSE, vk::PolygonMode::eFill, vk::CullModeFlagBits::eNone,
                                                    vk::FrontFace::eCounterClockwise, VK_FALSE, 0, 0, 0, 1.0F);
    vk::PipelineMultisampleStateCreateInfo multisample({}, vk::SampleCountFlagBits::e1);
    vk::PipelineColorBlendAttachmentState attachment;
    attachment.colorWriteMask = vk::ColorComponentFlagBits::eR | vk::ColorComponentFlagBits::eG | vk::ColorComponentFlagBits::eB |
                                vk::ColorComponentFlagBits::eA;
    vk::PipelineColorBlendStateCreateInfo blending({}, VK_FALSE, vk::LogicOp::eCopy, attachment);
    const vk::DynamicState dynamic_states[] = {vk::DynamicState::eViewport, vk::DynamicState::eScissor};
    vk::PipelineDynamicStateCreateInfo dynamic({}, dynamic_states);
    vk::PipelineRenderingCreateInfo rendering(0, format);
    vk::GraphicsPipelineCreateInfo info({}, stages, &vertex_input, &assembly, nullptr, &viewport, &raster, &multisample, nullptr,
                                        &blending, &dynamic, *lens_layout);
    info.pNext = &rendering;
    return lens_pipelines.emplace(format, vk::raii::Pipeline(gpu->device, nullptr, info)).first->second;
  }

  // The target's canvas at the pixel density of the target, (re)made when its size, its format or the
  // projector's lens changes (the canvas's size and the warp map follow from those three).
  detail::LensCanvasImages& ensure_canvas(detail::TargetBackend& t, const config::ProjectorConfig& p) {
    const vk::Extent2D e = t.extent();
    if (t.canvas && t.canvas->warp.extent == e && t.canvas->color.format == t.color_format() && same_lens(t.canvas->projector, p))
      return *t.canvas;
    const LensCanvas lc = lens_canvas(p);
    const vk::Extent2D size(
        static_cast<std::uint32_t>(std::ceil(e.width * static_cast<double>(lc.pinhole.width_px) / p.width_px)),
        static_cast<std::uint32_t>(std::ceil(e.height * static_cast<double>(lc.pinhole.height_px) / p.height_px)));
    if (size.width > 16384 || size.height > 16384)
      throw EngineError("the projector's lens needs an undistorted canvas of " + std::to_string(size.width) + "x" +
                        std::to_string(size.height) + " pixels, more than 16384 each way");
    if (t.canvas) gpu->device.waitIdle();  // frames in flight may still sample the old one
    t.canvas.reset();
    detail::LensCanvasImages c;
    c.color = gpu->make_image(size, t.color_format(), vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eSampled,
                              vk::ImageAspectFlagBits::eColor);
    c.depth = gpu->make_image(size, detail::kDepthFormat, vk::ImageUsageFlagBits::eDepthStencilAttachment,
                              vk::ImageAspectFlagBits::eDepth);
    const std::vector<float> warp = lens_warp(p, lc, static_cast<int>(e.width), static_cast<int>(e.height));
    c.warp = upload_image(e, vk::Format::eR32G32Sfloat, warp.data(), warp.size() * sizeof(float));
    c.projector = p;
    c.lens = lc;
    vk::DescriptorPoolSize pool_size(vk::DescriptorType::eCombinedImageSampler, 2);
    c.pool = vk::raii::DescriptorPool(
        gpu->device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, pool_size));
    vk::raii::DescriptorSets sets(gpu->device, vk::DescriptorSetAllocateInfo(*c.pool, *lens_set_layout));
    c.set = std::move(sets[0]);
    const vk::DescriptorImageInfo canvas_info(*lens_sampler, *c.color.view, vk::ImageLayout::eShaderReadOnlyOptimal);
    const vk::DescriptorImageInfo warp_info(*warp_sampler, *c.warp.view, vk::ImageLayout::eShaderReadOnlyOptimal);
    gpu->device.updateDescriptorSets(
        {vk::WriteDescriptorSet(*c.set, 0, 0, vk::DescriptorType::eCombinedImageSampler, canvas_info),
         vk::WriteDescriptorSet(*c.set, 1, 0, vk::DescriptorType::eCombinedImageSampler, warp_info)},
        {});
    t.canvas = std::move(c);
    return *t.canvas;
  }

  std::size_t add_model(const assets::Model& model) {
    if (model.primitives.empty()) throw EngineError(model.source + ": model has no triangles to draw");
    GpuModel g;
    std::vector<GpuVertex> vertices;
    std::vector<std::uint32_t> indices;
    for (const auto& p : model.primitives) {
      if (p.material < 0 || static_cast<std::size_t>(p.material) >= model.materials.size())
        throw EngineError(model.source + ": primitive refers to a missing material");
      g.parts.push_back({static_cast<std::uint32_t>(indices.size()), static_cast<std::uint32_t>(p.indices.size()),
                         static_cast<std::int32_t>(vertices.size()), static_cast<std::size_t>(p.material)});
      for (const auto& v : p.vertices) vertices.push_back(to_gpu(v));
      indices.insert(indices.end(), p.indices.begin(), p.indices.end());
    }
    g.vertices = gpu->upload_buffer(vertices.data(), vertices.size() * sizeof(GpuVertex), vk::BufferUsageFlagBits::eVertexBuffer);
    g.indices = gpu->upload_buffer(indices.data(), indices.size() * sizeof(std::uint32_t), vk::BufferUsageFlagBits::eIndexBuffer);
    for (const auto& img : model.images) g.textures.push_back(img.rgba.empty() ? detail::Image{} : upload_texture(img));
    g.materials = model.materials;

    const auto n = static_cast<std::uint32_t>(model.materials.size());
    vk::DescriptorPoolSize size(vk::DescriptorType::eCombinedImageSampler, n);
    g.pool = vk::raii::DescriptorPool(
        gpu->device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, n, size));
    std::vector<vk::DescriptorSetLayout> layouts(n, *set_layout);
    vk::raii::DescriptorSets sets(gpu->device, vk::DescriptorSetAllocateInfo(*g.pool, layouts));
    for (std::uint32_t i = 0; i < n; ++i) {
      const auto& m = model.materials[i];
      const bool textured = m.base_color_image >= 0 && static_cast<std::size_t>(m.base_color_image) < g.textures.size() &&
                            *g.textures[static_cast<std::size_t>(m.base_color_image)].view;
      if (m.base_color_image >= 0 && !textured)
        throw EngineError(model.source + ": material " + std::to_string(i) + " has no usable texture");
      g.samplers.emplace_back(
          gpu->device, vk::SamplerCreateInfo({}, to_vk(m.sampler.mag), to_vk(m.sampler.min), vk::SamplerMipmapMode::eNearest,
                                             to_vk(m.sampler.wrap_s), to_vk(m.sampler.wrap_t), vk::SamplerAddressMode::eRepeat));
      const vk::ImageView view = textured ? *g.textures[static_cast<std::size_t>(m.base_color_image)].view : *white.view;
      vk::DescriptorImageInfo image_info(*g.samplers.back(), view, vk::ImageLayout::eShaderReadOnlyOptimal);
      gpu->device.updateDescriptorSets(
          vk::WriteDescriptorSet(*sets[i], 0, 0, vk::DescriptorType::eCombinedImageSampler, image_info), {});
    }
    for (auto& s : sets) g.sets.push_back(std::move(s));
    models.push_back(std::move(g));
    return models.size() - 1;
  }

  // Model `model`'s uploaded copy, checked to have material `material`.
  GpuModel& model_with_material(std::size_t model, int material) {
    if (model >= models.size()) throw EngineError("streamed texture for model " + std::to_string(model) + ", not uploaded");
    GpuModel& g = models[model];
    if (material < 0 || static_cast<std::size_t>(material) >= g.materials.size())
      throw EngineError("streamed texture for material " + std::to_string(material) + ", but the model has " +
                        std::to_string(g.materials.size()));
    return g;
  }

  std::size_t add_streamed_texture(std::size_t model, int material, int width, int height) {
    model_with_material(model, material);  // refused before anything is made
    if (width <= 0 || height <= 0 || width > 16384 || height > 16384)
      throw EngineError("a streamed texture of " + std::to_string(width) + "x" + std::to_string(height) + " px");
    StreamedTexture tex;
    const std::vector<std::uint8_t> black(static_cast<std::size_t>(width) * height * 4, 0);
    tex.image = upload_image(vk::Extent2D(static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)),
                             vk::Format::eR8G8B8A8Unorm, black.data(), black.size());
    streamed.push_back(std::move(tex));
    bind_streamed_texture(streamed.size() - 1, model, material);
    return streamed.size() - 1;
  }

  void bind_streamed_texture(std::size_t id, std::size_t model, int material) {
    if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
    GpuModel& g = model_with_material(model, material);
    const auto m = static_cast<std::size_t>(material);
    gpu->device.waitIdle();  // the material's descriptor set may be in a frame in flight
    vk::DescriptorImageInfo info(*g.samplers[m], *streamed[id].image.view, vk::ImageLayout::eShaderReadOnlyOptimal);
    gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*g.sets[m], 0, 0, vk::DescriptorType::eCombinedImageSampler, info),
                                     {});
  }

  assets::PixelMemory frame_memory(std::size_t bytes) {
    if (bytes == 0 || bytes > (std::size_t{1} << 30)) throw EngineError("frame memory of " + std::to_string(bytes) + " bytes");
    auto host = std::make_shared<HostFrameBuffer>();
    host->gpu = gpu;
    host->buffer = gpu->make_buffer(bytes, vk::BufferUsageFlagBits::eTransferSrc,
                                    vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
    auto* data = static_cast<std::uint8_t*>(host->buffer.mapped);
    return {data, bytes, std::move(host), this};
  }

  void stream_pixels(std::size_t id, const assets::PixelMemory& pixels, std::shared_ptr<const void> keep) {
    if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
    const vk::Extent2D e = streamed[id].image.extent;
    if (pixels.tag != this || !pixels.owner || pixels.size < static_cast<std::size_t>(e.width) * e.height * 4)
      throw EngineError("pixels for streamed texture " + std::to_string(id) + " not in this renderer's frame memory of its size");
    streamed[id].pending.reset();
    streamed[id].pending_buffer = &static_cast<const HostFrameBuffer*>(pixels.owner.get())->buffer;
    streamed[id].pending_keep = std::move(keep);
  }

  void stream_frame(std::size_t id, std::shared_ptr<const assets::Image> image) {
    if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
    const vk::Extent2D e = streamed[id].image.extent;
    if (!image || image->width != static_cast<int>(e.width) || image->height != static_cast<int>(e.height) ||
        image->rgba.size() != static_cast<std::size_t>(e.width) * e.height * 4)
      throw EngineError("a frame for streamed texture " + std::to_string(id) + " that is not its " + std::to_string(e.width) +
                        "x" + std::to_string(e.height) + " RGBA8");
    streamed[id].pending = std::move(image);
    streamed[id].pending_buffer = nullptr;
    streamed[id].pending_keep.reset();
  }

  // The pending texels of every streamed texture into this slot's staging memory (the render thread's
  // share of an upload: one copy), and the GPU's copy into the image before anything draws.
  // Returns the number of textures uploaded.
  std::size_t record_uploads(const vk::raii::CommandBuffer& cmd, detail::FrameSlot& slot) {
    std::size_t uploaded = 0;
    for (StreamedTexture& tex : streamed) {
      if (!tex.pending && !tex.pending_buffer) continue;
      const Buffer* from = tex.pending_buffer;
      if (from != nullptr) {  // decoded into frame memory: the GPU copies it; held until the slot's fence
        slot.held.push_back(std::move(tex.pending_keep));
        tex.pending_buffer = nullptr;
      } else {
        const std::size_t bytes = tex.pending->rgba.size();
        auto [it, fresh] = tex.staging.try_emplace(&slot);
        if (fresh)
          it->second = gpu->make_buffer(bytes, vk::BufferUsageFlagBits::eTransferSrc,
                                        vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
        std::memcpy(it->second.mapped, tex.pending->rgba.data(), bytes);  // the slot's last frame is done (retired)
        tex.pending.reset();
        from = &it->second;
      }
      // After the frames before it have sampled the image (earlier in submission order: the barrier waits).
      record_image_copy(cmd, *from->buffer, tex.image, vk::ImageLayout::eShaderReadOnlyOptimal,
                        vk::PipelineStageFlagBits2::eFragmentShader, vk::AccessFlagBits2::eShaderSampledRead);
      ++uploaded;
    }
    return uploaded;
  }

  void ensure_slots(detail::TargetBackend& t) {
    if (!t.slots.empty()) return;
    vk::raii::CommandBuffers cmds(gpu->device, vk::CommandBufferAllocateInfo(*gpu->command_pool, vk::CommandBufferLevel::ePrimary,
                                                                             static_cast<std::uint32_t>(kFramesInFlight)));
    for (std::size_t i = 0; i < kFramesInFlight; ++i) {
      detail::FrameSlot slot;
      slot.cmd = std::move(cmds[i]);
      slot.fence = vk::raii::Fence(gpu->device, vk::FenceCreateInfo(vk::FenceCreateFlagBits::eSignaled));
      slot.acquired = vk::raii::Semaphore(gpu->device, vk::SemaphoreCreateInfo());
      make_frame_set(slot);
      t.slots.push_back(std::move(slot));
    }
    if (gpu->info.gpu_timestamps)
      t.timestamps = vk::raii::QueryPool(
          gpu->device, vk::QueryPoolCreateInfo({}, vk::QueryType::eTimestamp, static_cast<std::uint32_t>(2 * kFramesInFlight)));
  }

  // A slot's FrameUniform buffer (host visible, mapped) and its descriptor set.
  void make_frame_set(detail::FrameSlot& slot) {
    slot.photometry = gpu->make_buffer(sizeof(FrameUniform), vk::BufferUsageFlagBits::eUniformBuffer,
                                       vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
    vk::DescriptorPoolSize size(vk::DescriptorType::eUniformBuffer, 1);
    slot.pool = vk::raii::DescriptorPool(
        gpu->device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, size));
    const vk::DescriptorSetLayout layout = *frame_set_layout;
    slot.set = std::move(vk::raii::DescriptorSets(gpu->device, vk::DescriptorSetAllocateInfo(*slot.pool, layout)).front());
    const vk::DescriptorBufferInfo info(*slot.photometry.buffer, 0, sizeof(FrameUniform));
    gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*slot.set, 0, 0, vk::DescriptorType::eUniformBuffer, {}, info), {});
  }

  // Waits for a slot's previous frame and hands its timing to its profiler.
  void retire(detail::TargetBackend& t, std::size_t index) {
    detail::FrameSlot& slot = t.slots[index];
    if (gpu->device.waitForFences(*slot.fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
      throw EngineError("a frame's fence never signalled");
    slot.held.clear();  // the GPU has copied what the frame read from host memory
    if (!slot.pending) return;
    slot.pending = false;
    if (slot.profiler == nullptr) return;
    slot.record.completed_ms = slot.profiler->now_ms();
    slot.record.gpu_ms = std::nan("");
    if (*t.timestamps) {
      const auto [result, ticks] =
          t.timestamps.getResults<std::uint64_t>(static_cast<std::uint32_t>(2 * index), 2, 2 * sizeof(std::uint64_t),
                                                 sizeof(std::uint64_t), vk::QueryResultFlagBits::e64);
      if (result == vk::Result::eSuccess && ticks[1] >= ticks[0])
        slot.record.gpu_ms = static_cast<double>(ticks[1] - ticks[0]) * gpu->timestamp_period_ns * 1e-6;
    }
    slot.profiler->add(slot.record);
  }

  // `projector`: the pinhole drawn through (a lens canvas's, or the projector's); `panel`: the projector
  // whose light compensation divides out.
  void record_draws(const vk::raii::CommandBuffer& cmd, vk::Format format, const config::ProjectorConfig& projector,
                    bool depth_camera, const config::ProjectorConfig& panel, vk::DescriptorSet frame_set) {
    const Eigen::Matrix4d clip_from_projector_m = clip_from_projector(projector);
    const DrawConstants shared = frame_constants(panel, clip_from_projector_m);
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *pipeline_layout, 1, frame_set, {});
    // Opaque and masked first, blended after them so they blend over what is behind.
    // A depth camera sees every surface, whatever its material: one opaque pass.
    static constexpr bool kPasses[] = {false, true};
    for (const bool blend_pass : std::span<const bool>(kPasses, depth_camera ? 1 : 2))
      for (const DrawItem& item : items) {
        const GpuModel& m = models[item.model];
        const vk::Buffer vb = *m.vertices.buffer;
        cmd.bindVertexBuffers(0, vb, vk::DeviceSize(0));
        cmd.bindIndexBuffer(*m.indices.buffer, 0, vk::IndexType::eUint32);
        DrawConstants c = shared;
        c.clip_from_model = to_gpu_matrix(clip_from_projector_m * item.T_projector_target);  // Eq. 3
        const Compensation& comp = item.compensation;
        if (comp.on && !depth_camera) c.compensate = {comp.scale_lux[0], comp.scale_lux[1], comp.scale_lux[2], comp.ambient_lux};
        for (const auto& part : m.parts) {
          const assets::Material& mat = m.materials[part.material];
          if (!depth_camera && (mat.alpha_mode == assets::AlphaMode::kBlend) != blend_pass) continue;
          cmd.bindPipeline(vk::PipelineBindPoint::eGraphics,
                           *pipeline(format, !mat.double_sided, depth_camera ? 0 : alpha_mode_id(mat.alpha_mode), depth_camera));
          cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *pipeline_layout, 0, *m.sets[part.material], {});
          c.base_color_factor =
              static_cast<int>(part.material) == item.animated_material ? item.base_color_factor : mat.base_color_factor;
          c.projector[3] = mat.alpha_cutoff;
          cmd.pushConstants<DrawConstants>(*pipeline_layout,
                                           vk::ShaderStageFlagBits::eVertex | vk::ShaderStageFlagBits::eFragment, 0, c);
          cmd.drawIndexed(part.index_count, 1, part.first_index, part.vertex_offset, 0);
        }
      }
  }

  static void transition_depth(const vk::raii::CommandBuffer& cmd, vk::Image depth) {
    detail::transition(cmd, depth, vk::ImageAspectFlagBits::eDepth, vk::ImageLayout::eUndefined,
                       vk::ImageLayout::eDepthAttachmentOptimal, vk::PipelineStageFlagBits2::eLateFragmentTests,
                       vk::AccessFlagBits2::eDepthStencilAttachmentWrite, vk::PipelineStageFlagBits2::eEarlyFragmentTests,
                       vk::AccessFlagBits2::eDepthStencilAttachmentWrite | vk::AccessFlagBits2::eDepthStencilAttachmentRead);
  }

  // Dynamic rendering into `color` (and `depth`, when given) over the whole of `extent`, cleared to black.
  static void begin_pass(const vk::raii::CommandBuffer& cmd, vk::ImageView color, vk::ImageView depth, vk::Extent2D extent,
                         float clear_alpha) {
    vk::RenderingAttachmentInfo color_att(color, vk::ImageLayout::eColorAttachmentOptimal, {}, {}, {},
                                          vk::AttachmentLoadOp::eClear, vk::AttachmentStoreOp::eStore,
                                          vk::ClearColorValue(std::array<float, 4>{0.0F, 0.0F, 0.0F, clear_alpha}));
    vk::RenderingAttachmentInfo depth_att(depth, vk::ImageLayout::eDepthAttachmentOptimal, {}, {}, {},
                                          vk::AttachmentLoadOp::eClear, vk::AttachmentStoreOp::eDontCare,
                                          vk::ClearDepthStencilValue(1.0F, 0));
    cmd.beginRendering(vk::RenderingInfo({}, vk::Rect2D({0, 0}, extent), 1, 0, color_att, depth ? &depth_att : nullptr));
    cmd.setViewport(0, vk::Viewport(0.0F, 0.0F, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0F, 1.0F));
    cmd.setScissor(0, vk::Rect2D({0, 0}, extent));
  }

  // The lens pass's first half: the models through the canvas's pinhole, left ready to sample. One canvas
  // serves both frames in flight: the barriers order this frame's drawing after the last frame's sampling.
  void record_canvas(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::DescriptorSet frame_set) {
    detail::LensCanvasImages& c = *t.canvas;  // made by draw_frame before the fence was reset
    detail::transition(cmd, *c.color.image, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eUndefined,
                       vk::ImageLayout::eColorAttachmentOptimal, vk::PipelineStageFlagBits2::eFragmentShader,
                       vk::AccessFlagBits2::eShaderSampledRead, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                       vk::AccessFlagBits2::eColorAttachmentWrite);
    transition_depth(cmd, *c.depth.image);
    begin_pass(cmd, *c.color.view, *c.depth.view, c.color.extent, 1.0F);
    record_draws(cmd, t.color_format(), c.lens.pinhole, false, c.projector, frame_set);
    cmd.endRendering();
    detail::transition(cmd, *c.color.image, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eColorAttachmentOptimal,
                       vk::ImageLayout::eShaderReadOnlyOptimal, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                       vk::AccessFlagBits2::eColorAttachmentWrite, vk::PipelineStageFlagBits2::eFragmentShader,
                       vk::AccessFlagBits2::eShaderSampledRead);
  }

  // The lens pass's second half: every target pixel takes the canvas at its panel position's ray.
  // (ensure_canvas made its warp map for this projector and target size.)
  void record_lens(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::ImageView color) {
    begin_pass(cmd, color, nullptr, t.extent(), 1.0F);
    cmd.bindPipeline(vk::PipelineBindPoint::eGraphics, *lens_pipeline(t.color_format()));
    cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *lens_layout, 0, *t.canvas->set, {});
    cmd.draw(3, 1, 0, 0);
    cmd.endRendering();
  }

  bool draw_frame(detail::TargetBackend& t, const config::ProjectorConfig& projector, const PoseReader& read_poses,
                  FrameProfiler* profiler) {
    ensure_slots(t);
    FrameRecord rec;
    rec.index = frame_index;
    rec.start_ms = profiler ? profiler->now_ms() : 0.0;
    const std::size_t si = t.next_slot;
    retire(t, si);
    detail::FrameSlot& slot = t.slots[si];
    const auto frame = t.acquire(*slot.acquired);
    if (!frame) return false;

    items.clear();
    read_poses(items);
    if (profiler) rec.pose_read_ms = profiler->now_ms();
    // Checked before the fence is reset: a throw past that point would leave the slot unsignalled forever.
    for (const DrawItem& item : items)
      if (item.model >= models.size())
        throw EngineError("draw item refers to model " + std::to_string(item.model) + ", but " + std::to_string(models.size()) +
                          " are uploaded");

    const bool lens = !t.depth_output() && config::has_distortion(projector.distortion);
    if (lens) ensure_canvas(t, projector);

    gpu->device.resetFences(*slot.fence);
    const FrameUniform uniform = frame_uniform(projector.photometry);  // the slot's last frame is done (retired)
    std::memcpy(slot.photometry.mapped, &uniform, sizeof uniform);
    const vk::raii::CommandBuffer& cmd = slot.cmd;
    cmd.reset();
    cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
    const auto q0 = static_cast<std::uint32_t>(2 * si);
    if (*t.timestamps) {
      cmd.resetQueryPool(*t.timestamps, q0, 2);
      cmd.writeTimestamp2(vk::PipelineStageFlagBits2::eTopOfPipe, *t.timestamps, q0);
    }
    const double upload_start_ms = profiler ? profiler->now_ms() : 0.0;
    if (record_uploads(cmd, slot) > 0 && profiler) rec.upload_ms = profiler->now_ms() - upload_start_ms;
    if (lens) record_canvas(cmd, t, *slot.set);
    detail::transition(cmd, frame->color, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eUndefined,
                       vk::ImageLayout::eColorAttachmentOptimal, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                       vk::AccessFlagBits2::eNone, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                       vk::AccessFlagBits2::eColorAttachmentWrite);
    if (lens) {
      record_lens(cmd, t, frame->color_view);
    } else {
      transition_depth(cmd, *t.depth().image);
      begin_pass(cmd, frame->color_view, *t.depth().view, t.extent(), t.depth_output() ? 0.0F : 1.0F);
      // The projector image (width x height of the intrinsics) is stretched onto the target.
      record_draws(cmd, t.color_format(), projector, t.depth_output(), projector, *slot.set);
      cmd.endRendering();
    }
    const bool to_present = frame->color_final_layout == vk::ImageLayout::ePresentSrcKHR;
    detail::transition(cmd, frame->color, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eColorAttachmentOptimal,
                       frame->color_final_layout, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                       vk::AccessFlagBits2::eColorAttachmentWrite,
                       to_present ? vk::PipelineStageFlagBits2::eNone : vk::PipelineStageFlagBits2::eCopy,
                       to_present ? vk::AccessFlagBits2::eNone : vk::AccessFlagBits2::eTransferRead);
    if (*t.timestamps) cmd.writeTimestamp2(vk::PipelineStageFlagBits2::eAllCommands, *t.timestamps, q0 + 1);
    cmd.end();
    if (profiler) rec.recorded_ms = profiler->now_ms();

    const vk::CommandBuffer raw = *cmd;
    const vk::PipelineStageFlags wait_stage = vk::PipelineStageFlagBits::eColorAttachmentOutput;
    vk::SubmitInfo submit(0, nullptr, nullptr, 1, &raw);
    if (frame->wait) submit.setWaitSemaphoreCount(1).setPWaitSemaphores(&frame->wait).setPWaitDstStageMask(&wait_stage);
    if (frame->signal) submit.setSignalSemaphoreCount(1).setPSignalSemaphores(&frame->signal);
    gpu->queue.submit(submit, *slot.fence);
    if (profiler) rec.submitted_ms = profiler->now_ms();
    t.present(*frame);
    if (profiler) rec.presented_ms = profiler->now_ms();

    slot.record = rec;
    slot.profiler = profiler;
    slot.pending = true;
    t.next_slot = (si + 1) % t.slots.size();
    ++frame_index;
    return true;
  }
};

RenderTarget::RenderTarget(std::unique_ptr<detail::TargetBackend> backend) : backend_(std::move(backend)) {}
RenderTarget::~RenderTarget() = default;
int RenderTarget::width() const { return static_cast<int>(backend_->extent().width); }
int RenderTarget::height() const { return static_cast<int>(backend_->extent().height); }
bool RenderTarget::poll_close() { return backend_->poll_close(); }
std::uint64_t RenderTarget::native_window() const { return backend_->native_window(); }
assets::Image RenderTarget::read_back() { return backend_->read_back(); }
DepthMap RenderTarget::read_back_depth() { return backend_->read_back_depth(); }

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;
const DeviceInfo& Renderer::device_info() const { return impl_->gpu->info; }
std::size_t Renderer::add_model(const assets::Model& model) { return impl_->add_model(model); }
std::size_t Renderer::add_streamed_texture(std::size_t model, int material, int width_px, int height_px) {
  return impl_->add_streamed_texture(model, material, width_px, height_px);
}
void Renderer::bind_streamed_texture(std::size_t texture, std::size_t model, int material) {
  impl_->bind_streamed_texture(texture, model, material);
}
assets::PixelMemory Renderer::frame_memory(std::size_t bytes) { return impl_->frame_memory(bytes); }
void Renderer::stream_pixels(std::size_t texture, const assets::PixelMemory& pixels, std::shared_ptr<const void> keep) {
  impl_->stream_pixels(texture, pixels, std::move(keep));
}
void Renderer::stream_frame(std::size_t texture, std::shared_ptr<const assets::Image> image) {
  impl_->stream_frame(texture, std::move(image));
}

std::unique_ptr<RenderTarget> Renderer::make_offscreen(int width_px, int height_px) {
  if (width_px <= 0 || height_px <= 0) throw EngineError("offscreen target size must be positive");
  return std::make_unique<RenderTarget>(detail::make_offscreen_backend(
      impl_->gpu, vk::Extent2D(static_cast<std::uint32_t>(width_px), static_cast<std::uint32_t>(height_px)), false));
}

std::unique_ptr<RenderTarget> Renderer::make_depth_camera(int width_px, int height_px) {
  if (width_px <= 0 || height_px <= 0) throw EngineError("depth camera size must be positive");
  return std::make_unique<RenderTarget>(detail::make_offscreen_backend(
      impl_->gpu, vk::Extent2D(static_cast<std::uint32_t>(width_px), static_cast<std::uint32_t>(height_px)), true));
}

std::unique_ptr<RenderTarget> Renderer::make_window(const WindowOptions& options) {
  return std::make_unique<RenderTarget>(detail::make_window_backend(impl_->gpu, options));
}

bool Renderer::draw_frame(RenderTarget& target, const config::ProjectorConfig& projector, const PoseReader& read_poses,
                          FrameProfiler* profiler) {
  return impl_->draw_frame(target.backend(), projector, read_poses, profiler);
}

bool Renderer::draw_frame(RenderTarget& target, const config::ProjectorConfig& projector, std::span<const DrawItem> items,
                          FrameProfiler* profiler) {
  return draw_frame(
      target, projector, [items](std::vector<DrawItem>& out) { out.assign(items.begin(), items.end()); }, profiler);
}

void Renderer::finish(RenderTarget& target) {
  auto& t = target.backend();
  for (std::size_t k = 0; k < t.slots.size(); ++k) impl_->retire(t, (t.next_slot + k) % t.slots.size());
}

std::size_t Renderer::validation_warnings() const { return impl_->gpu->validation_warnings; }
std::size_t Renderer::validation_errors() const { return impl_->gpu->validation_errors; }

}  // namespace projbot::engine
