// The renderer's resources: the device's layouts and shaders, models and their textures, streamed
// textures (video) and the frame memory they are decoded into, and the pipelines.

#include <projbot/shaders/depth.frag.spv.h>
#include <projbot/shaders/lens.frag.spv.h>
#include <projbot/shaders/lens.vert.spv.h>
#include <projbot/shaders/mesh.frag.spv.h>
#include <projbot/shaders/mesh.vert.spv.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>

#include "projbot/config/stop_request.hpp"
#include "renderer_impl.hpp"

namespace projbot::engine {

using namespace detail;

Renderer::Impl::Impl(const RendererOptions& options) : gpu(std::make_shared<Gpu>(options)) {
  const vk::DescriptorSetLayoutBinding bindings[] = {
      // a material's base colour, its target's surface, the material's emission
      {0, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment},
      {1, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment},
      {2, vk::DescriptorType::eCombinedImageSampler, 1, vk::ShaderStageFlagBits::eFragment}};
  set_layout = vk::raii::DescriptorSetLayout(gpu->device, vk::DescriptorSetLayoutCreateInfo({}, bindings));
  vk::PushConstantRange push(vk::ShaderStageFlagBits::eVertex | vk::ShaderStageFlagBits::eFragment, 0, sizeof(DrawConstants));
  const vk::DescriptorSetLayoutBinding frame_bindings[] = {
      // the projector's response; each draw's material block
      {0, vk::DescriptorType::eUniformBuffer, 1, vk::ShaderStageFlagBits::eFragment},
      {1, vk::DescriptorType::eUniformBufferDynamic, 1, vk::ShaderStageFlagBits::eVertex | vk::ShaderStageFlagBits::eFragment}};
  frame_set_layout = vk::raii::DescriptorSetLayout(gpu->device, vk::DescriptorSetLayoutCreateInfo({}, frame_bindings));
  const vk::DeviceSize align = std::max<vk::DeviceSize>(1, gpu->physical.getProperties().limits.minUniformBufferOffsetAlignment);
  draw_stride = (sizeof(DrawUniform) + align - 1) / align * align;
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
  surface_sampler =
      vk::raii::Sampler(gpu->device, vk::SamplerCreateInfo({}, vk::Filter::eLinear, vk::Filter::eLinear,
                                                           vk::SamplerMipmapMode::eNearest, vk::SamplerAddressMode::eRepeat,
                                                           vk::SamplerAddressMode::eRepeat, vk::SamplerAddressMode::eRepeat));
}

Renderer::Impl::~Impl() {
  if (*gpu->device) gpu->device.waitIdle();
}

detail::Image Renderer::Impl::upload_texture(const assets::Image& img) {
  // UNORM, not SRGB: texels reach the target exactly as stored in the file.
  return upload_image(vk::Extent2D(static_cast<std::uint32_t>(img.width), static_cast<std::uint32_t>(img.height)),
                      vk::Format::eR8G8B8A8Unorm, img.rgba.data(), img.rgba.size());
}

detail::Image Renderer::Impl::upload_image(vk::Extent2D extent, vk::Format format, const void* bytes, std::size_t size) {
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

void Renderer::Impl::record_image_copy(const vk::raii::CommandBuffer& cmd, vk::Buffer from, const detail::Image& image,
                                       vk::ImageLayout before, vk::PipelineStageFlags2 before_stage,
                                       vk::AccessFlags2 before_access) {
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

const vk::raii::Pipeline& Renderer::Impl::pipeline(vk::Format format, bool cull_back, const detail::Shading& shading,
                                                   bool depth_camera) {
  const auto key = std::make_tuple(format, cull_back, shading.alpha_mode, shading.placed, shading.emissive, depth_camera);
  if (auto it = pipelines.find(key); it != pipelines.end()) return it->second;
  const bool blend = shading.alpha_mode == 2;
  const vk::SpecializationMapEntry entries[] = {{0, offsetof(Shading, alpha_mode), sizeof(std::int32_t)},
                                                {1, offsetof(Shading, placed), sizeof(vk::Bool32)},
                                                {2, offsetof(Shading, emissive), sizeof(vk::Bool32)}};
  const vk::SpecializationInfo specialization(3, entries, sizeof(Shading), &shading);
  const vk::PipelineShaderStageCreateInfo stages[] = {{{}, vk::ShaderStageFlagBits::eVertex, *vert, "main", &specialization},
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

const vk::raii::Pipeline& Renderer::Impl::lens_pipeline(vk::Format format) {
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

namespace {

std::string megabytes(vk::DeviceSize bytes) { return std::to_string((bytes + (1U << 20) - 1) >> 20) + " MB"; }

// What a model too large for the device is told: its file, its triangles, and the limit it passed.
EngineError too_large(const assets::Model& model, vk::DeviceSize bytes, const std::string& limit) {
  return EngineError(model.source + ": " + std::to_string(model.triangle_count()) + " triangles (" + megabytes(bytes) +
                     " of vertices and indices) do not fit the GPU: " + limit + "; simplify the mesh");
}

}  // namespace

void Renderer::Impl::upload_geometry(GpuModel& g, const assets::Model& model, const std::vector<GpuVertex>& vertices,
                                     const std::vector<std::uint32_t>& indices) {
  const vk::DeviceSize vertex_bytes = vertices.size() * sizeof(GpuVertex), index_bytes = indices.size() * sizeof(std::uint32_t);
  const auto props = gpu->physical.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceMaintenance3Properties>();
  const vk::DeviceSize most = props.get<vk::PhysicalDeviceMaintenance3Properties>().maxMemoryAllocationSize;
  if (std::max(vertex_bytes, index_bytes) > most)
    throw too_large(model, vertex_bytes + index_bytes, "one buffer may hold at most " + megabytes(most));
  try {
    g.vertices = gpu->upload_buffer(vertices.data(), vertex_bytes, vk::BufferUsageFlagBits::eVertexBuffer);
    g.indices = gpu->upload_buffer(indices.data(), index_bytes, vk::BufferUsageFlagBits::eIndexBuffer);
  } catch (const vk::OutOfDeviceMemoryError&) {
    throw too_large(model, vertex_bytes + index_bytes, "its memory is full");
  } catch (const vk::OutOfHostMemoryError&) {
    throw too_large(model, vertex_bytes + index_bytes, "the memory it maps is full");
  }
}

GpuModel Renderer::Impl::make_gpu_model(const assets::Model& model) {
  if (model.primitives.empty()) throw EngineError(model.source + ": model has no triangles to draw");
  GpuModel g;
  std::vector<GpuVertex> vertices;
  std::vector<std::uint32_t> indices;
  for (const auto& p : model.primitives) {
    if (p.material < 0 || static_cast<std::size_t>(p.material) >= model.materials.size())
      throw EngineError(model.source + ": primitive refers to a missing material");
    g.parts.push_back({static_cast<std::uint32_t>(indices.size()), static_cast<std::uint32_t>(p.indices.size()),
                       static_cast<std::int32_t>(vertices.size()), static_cast<std::size_t>(p.material)});
    for (const auto& v : p.vertices) {
      if (vertices.size() % config::kStopCheckEvery == 0) config::stop_if_requested("uploading " + model.source);
      vertices.push_back(to_gpu(v));
    }
    indices.insert(indices.end(), p.indices.begin(), p.indices.end());
  }
  upload_geometry(g, model, vertices, indices);
  for (const auto& img : model.images) g.textures.push_back(img.rgba.empty() ? detail::Image{} : upload_texture(img));
  g.materials = model.materials;

  const auto n = static_cast<std::uint32_t>(model.materials.size());
  vk::DescriptorPoolSize size(vk::DescriptorType::eCombinedImageSampler, 3 * n);
  g.pool = vk::raii::DescriptorPool(gpu->device,
                                    vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, n, size));
  std::vector<vk::DescriptorSetLayout> layouts(n, *set_layout);
  vk::raii::DescriptorSets sets(gpu->device, vk::DescriptorSetAllocateInfo(*g.pool, layouts));
  for (std::uint32_t i = 0; i < n; ++i) {
    const auto& m = model.materials[i];
    bind_material_texture(g, *sets[i], 0, m.base_color_image, m.sampler, "material " + std::to_string(i));
    bind_material_texture(g, *sets[i], 2, m.emissive_image, m.emissive_sampler, "material " + std::to_string(i) + "'s emission");
  }
  for (auto& s : sets) g.sets.push_back(std::move(s));
  bind_surface(g, *white.view);
  return g;
}

std::size_t Renderer::Impl::add_model(const assets::Model& model) {
  models.push_back(make_gpu_model(model));
  return models.size() - 1;
}

void Renderer::Impl::replace_model(std::size_t model, const assets::Model& fresh) {
  if (model >= models.size()) throw EngineError("model " + std::to_string(model) + " to replace, not uploaded");
  GpuModel& old = models[model];
  if (fresh.materials.size() != old.materials.size())
    throw EngineError(fresh.source + ": " + std::to_string(fresh.materials.size()) + " materials where the model drawn has " +
                      std::to_string(old.materials.size()));
  GpuModel g = make_gpu_model(fresh);  // refused (thrown) before anything drawn changes
  gpu->device.waitIdle();              // the old model's buffers and sets may be in a frame in flight
  g.surface = std::move(old.surface);
  if (*g.surface.view) bind_surface(g, *g.surface.view);
  const std::map<int, std::size_t> streamed_before = old.streamed;
  old.sets.clear();              // freed into their pool before it goes (a move would destroy the pool first)
  models[model] = std::move(g);  // `old` is the new one from here
  for (const auto& [material, texture] : streamed_before) bind_streamed_texture(texture, model, material);
}

void Renderer::Impl::bind_material_texture(GpuModel& g, vk::DescriptorSet set, std::uint32_t binding, int image,
                                           const assets::Sampler& sampler, const std::string& what) {
  const bool textured =
      image >= 0 && static_cast<std::size_t>(image) < g.textures.size() && *g.textures[static_cast<std::size_t>(image)].view;
  if (image >= 0 && !textured) throw EngineError(what + " has no usable texture");
  g.samplers.emplace_back(gpu->device,
                          vk::SamplerCreateInfo({}, to_vk(sampler.mag), to_vk(sampler.min), vk::SamplerMipmapMode::eNearest,
                                                to_vk(sampler.wrap_s), to_vk(sampler.wrap_t), vk::SamplerAddressMode::eRepeat));
  const vk::ImageView view = textured ? *g.textures[static_cast<std::size_t>(image)].view : *white.view;
  const vk::DescriptorImageInfo info(*g.samplers.back(), view, vk::ImageLayout::eShaderReadOnlyOptimal);
  gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(set, binding, 0, vk::DescriptorType::eCombinedImageSampler, info), {});
}

void Renderer::Impl::bind_surface(GpuModel& g, vk::ImageView view) {
  const vk::DescriptorImageInfo info(*surface_sampler, view, vk::ImageLayout::eShaderReadOnlyOptimal);
  for (const auto& set : g.sets)
    gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*set, 1, 0, vk::DescriptorType::eCombinedImageSampler, info), {});
}

void Renderer::Impl::set_surface(std::size_t model, const assets::Image& reflectance) {
  if (model >= models.size()) throw EngineError("a surface for model " + std::to_string(model) + ", not uploaded");
  if (reflectance.width <= 0 || reflectance.height <= 0 || reflectance.width > 16384 || reflectance.height > 16384 ||
      reflectance.rgba.size() != static_cast<std::size_t>(reflectance.width) * reflectance.height * 4)
    throw EngineError("a surface texture of " + std::to_string(reflectance.width) + "x" + std::to_string(reflectance.height) +
                      " px that is not RGBA8 of that size");
  GpuModel& g = models[model];
  gpu->device.waitIdle();  // the model's descriptor sets may be in a frame in flight
  // sRGB: the sampler reads linear reflectance, which compensation divides by.
  g.surface =
      upload_image(vk::Extent2D(static_cast<std::uint32_t>(reflectance.width), static_cast<std::uint32_t>(reflectance.height)),
                   vk::Format::eR8G8B8A8Srgb, reflectance.rgba.data(), reflectance.rgba.size());
  bind_surface(g, *g.surface.view);
}

GpuModel& Renderer::Impl::model_with_material(std::size_t model, int material) {
  if (model >= models.size()) throw EngineError("streamed texture for model " + std::to_string(model) + ", not uploaded");
  GpuModel& g = models[model];
  if (material < 0 || static_cast<std::size_t>(material) >= g.materials.size())
    throw EngineError("streamed texture for material " + std::to_string(material) + ", but the model has " +
                      std::to_string(g.materials.size()));
  return g;
}

std::size_t Renderer::Impl::add_streamed_texture(std::size_t model, int material, int width, int height) {
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

void Renderer::Impl::bind_streamed_texture(std::size_t id, std::size_t model, int material) {
  if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
  GpuModel& g = model_with_material(model, material);
  const auto m = static_cast<std::size_t>(material);
  gpu->device.waitIdle();  // the material's descriptor set may be in a frame in flight
  g.streamed[material] = id;
  vk::DescriptorImageInfo info(*g.samplers[2 * m], *streamed[id].image.view, vk::ImageLayout::eShaderReadOnlyOptimal);
  gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*g.sets[m], 0, 0, vk::DescriptorType::eCombinedImageSampler, info), {});
}

assets::PixelMemory Renderer::Impl::frame_memory(std::size_t bytes) {
  if (bytes == 0 || bytes > (std::size_t{1} << 30)) throw EngineError("frame memory of " + std::to_string(bytes) + " bytes");
  auto host = std::make_shared<HostFrameBuffer>();
  host->gpu = gpu;
  host->buffer = gpu->make_buffer(bytes, vk::BufferUsageFlagBits::eTransferSrc,
                                  vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
  auto* data = static_cast<std::uint8_t*>(host->buffer.mapped);
  return {data, bytes, std::move(host), this};
}

void Renderer::Impl::stream_pixels(std::size_t id, const assets::PixelMemory& pixels, std::shared_ptr<const void> keep) {
  if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
  const vk::Extent2D e = streamed[id].image.extent;
  if (pixels.tag != this || !pixels.owner || pixels.size < static_cast<std::size_t>(e.width) * e.height * 4)
    throw EngineError("pixels for streamed texture " + std::to_string(id) + " not in this renderer's frame memory of its size");
  streamed[id].pending.reset();
  streamed[id].pending_buffer = &static_cast<const HostFrameBuffer*>(pixels.owner.get())->buffer;
  streamed[id].pending_keep = std::move(keep);
}

void Renderer::Impl::stream_frame(std::size_t id, std::shared_ptr<const assets::Image> image) {
  if (id >= streamed.size()) throw EngineError("no streamed texture " + std::to_string(id));
  const vk::Extent2D e = streamed[id].image.extent;
  if (!image || image->width != static_cast<int>(e.width) || image->height != static_cast<int>(e.height) ||
      image->rgba.size() != static_cast<std::size_t>(e.width) * e.height * 4)
    throw EngineError("a frame for streamed texture " + std::to_string(id) + " that is not its " + std::to_string(e.width) + "x" +
                      std::to_string(e.height) + " RGBA8");
  streamed[id].pending = std::move(image);
  streamed[id].pending_buffer = nullptr;
  streamed[id].pending_keep.reset();
}

std::size_t Renderer::Impl::record_uploads(const vk::raii::CommandBuffer& cmd, detail::FrameSlot& slot) {
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

}  // namespace projbot::engine
