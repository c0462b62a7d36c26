// The projector pass: records and submits frames in flight (the lens canvas, the uploads, the draws).

#include "projbot/engine/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "projbot/engine/projection.hpp"
#include "renderer_impl.hpp"

namespace projbot::engine {

using namespace detail;

detail::LensCanvasImages& Renderer::Impl::ensure_canvas(detail::TargetBackend& t, const config::ProjectorConfig& p) {
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
  gpu->device.updateDescriptorSets({vk::WriteDescriptorSet(*c.set, 0, 0, vk::DescriptorType::eCombinedImageSampler, canvas_info),
                                    vk::WriteDescriptorSet(*c.set, 1, 0, vk::DescriptorType::eCombinedImageSampler, warp_info)},
                                   {});
  t.canvas = std::move(c);
  return *t.canvas;
}

void Renderer::Impl::ensure_slots(detail::TargetBackend& t) {
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

void Renderer::Impl::make_frame_set(detail::FrameSlot& slot) {
  slot.photometry = gpu->make_buffer(sizeof(FrameUniform), vk::BufferUsageFlagBits::eUniformBuffer,
                                     vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
  const vk::DescriptorPoolSize sizes[] = {{vk::DescriptorType::eUniformBuffer, 1},
                                          {vk::DescriptorType::eUniformBufferDynamic, 1}};
  slot.pool = vk::raii::DescriptorPool(
      gpu->device, vk::DescriptorPoolCreateInfo(vk::DescriptorPoolCreateFlagBits::eFreeDescriptorSet, 1, sizes));
  const vk::DescriptorSetLayout layout = *frame_set_layout;
  slot.set = std::move(vk::raii::DescriptorSets(gpu->device, vk::DescriptorSetAllocateInfo(*slot.pool, layout)).front());
  const vk::DescriptorBufferInfo info(*slot.photometry.buffer, 0, sizeof(FrameUniform));
  gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*slot.set, 0, 0, vk::DescriptorType::eUniformBuffer, {}, info), {});
  ensure_draw_blocks(slot, 16);
}

void Renderer::Impl::ensure_draw_blocks(detail::FrameSlot& slot, std::size_t count) {
  if (count <= slot.draw_capacity) return;
  const std::size_t capacity = std::max(count, 2 * slot.draw_capacity);
  slot.draws = gpu->make_buffer(capacity * draw_stride, vk::BufferUsageFlagBits::eUniformBuffer,
                                vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
  slot.draw_capacity = capacity;
  const vk::DescriptorBufferInfo info(*slot.draws.buffer, 0, sizeof(DrawUniform));
  gpu->device.updateDescriptorSets(vk::WriteDescriptorSet(*slot.set, 1, 0, vk::DescriptorType::eUniformBufferDynamic, {}, info),
                                   {});
}

namespace {

// A 2x3 placement as a 3x3 matrix, and back into a block's two rows.
Eigen::Matrix3d homogeneous(const std::array<double, 6>& m) {
  Eigen::Matrix3d h;
  h << m[0], m[1], m[2], m[3], m[4], m[5], 0.0, 0.0, 1.0;
  return h;
}

void put_rows(const Eigen::Matrix3d& h, std::array<float, 8>& rows) {
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) rows[static_cast<std::size_t>(4 * r + c)] = static_cast<float>(h(r, c));
}

}  // namespace

Shading detail::shading(const DrawUniform& u) {
  static constexpr std::array<float, 8> kIdentity{1, 0, 0, 0, 0, 1, 0, 0};
  Shading s;
  s.emissive = u.emissive[0] > 0.0F || u.emissive[1] > 0.0F || u.emissive[2] > 0.0F ? VK_TRUE : VK_FALSE;
  s.placed = u.base_uv != kIdentity || (s.emissive && u.emissive_uv != kIdentity) ? VK_TRUE : VK_FALSE;
  return s;
}

DrawUniform detail::draw_uniform(const assets::Material& loaded, const assets::MaterialState& now) {
  DrawUniform u{};
  for (std::size_t c = 0; c < 3; ++c) u.emissive[c] = now.emissive_factor[c] * now.emissive_strength;
  // The model's UVs carry the loaded base colour transform: each texture's placement is taken from there.
  const Eigen::Matrix3d baked = homogeneous(loaded.base_color_transform.matrix());
  const Eigen::Matrix3d from_model =
      std::abs(baked.determinant()) > 1e-12 ? Eigen::Matrix3d(baked.inverse()) : Eigen::Matrix3d::Identity();
  put_rows(homogeneous(now.base_color_transform.matrix()) * from_model, u.base_uv);
  put_rows(homogeneous(now.emissive_transform.matrix()) * from_model, u.emissive_uv);
  return u;
}

void Renderer::Impl::retire(detail::TargetBackend& t, std::size_t index) {
  detail::FrameSlot& slot = t.slots[index];
  if (gpu->device.waitForFences(*slot.fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
    throw EngineError("a frame's fence never signalled");
  slot.held.clear();  // the GPU has copied what the frame read from host memory
  if (t.copy.slot == index) t.copy.done = true;
  if (!slot.pending) return;
  slot.pending = false;
  if (slot.profiler == nullptr) return;
  slot.record.completed_ms = slot.profiler->now_ms();
  slot.record.gpu_ms = std::nan("");
  if (*t.timestamps) {
    const auto [result, ticks] = t.timestamps.getResults<std::uint64_t>(
        static_cast<std::uint32_t>(2 * index), 2, 2 * sizeof(std::uint64_t), sizeof(std::uint64_t), vk::QueryResultFlagBits::e64);
    if (result == vk::Result::eSuccess && ticks[1] >= ticks[0])
      slot.record.gpu_ms = static_cast<double>(ticks[1] - ticks[0]) * gpu->timestamp_period_ns * 1e-6;
  }
  slot.profiler->add(slot.record);
}

std::size_t Renderer::Impl::record_draws(const vk::raii::CommandBuffer& cmd, vk::Format format,
                                         const config::ProjectorConfig& projector, bool depth_camera,
                                         const config::ProjectorConfig& panel, detail::FrameSlot& slot, std::size_t first_block) {
  const Eigen::Matrix4d clip_from_projector_m = clip_from_projector(projector);
  const DrawConstants shared = frame_constants(panel, clip_from_projector_m);
  std::size_t block = first_block;
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
        const auto animated = std::find_if(item.materials.begin(), item.materials.end(),
                                           [&](const auto& look) { return look.first == static_cast<int>(part.material); });
        const assets::MaterialState state = animated != item.materials.end() ? animated->second : mat.state();
        const DrawUniform u = draw_uniform(mat, state);
        // An animated material takes the full path throughout: no new pipeline mid-run as its state moves.
        Shading sh = depth_camera ? Shading{} : animated != item.materials.end() ? Shading{0, VK_TRUE, VK_TRUE} : shading(u);
        sh.alpha_mode = depth_camera ? 0 : alpha_mode_id(mat.alpha_mode);
        cmd.bindPipeline(vk::PipelineBindPoint::eGraphics, *pipeline(format, !mat.double_sided, sh, depth_camera));
        const auto offset = static_cast<std::uint32_t>(block++ * draw_stride);
        std::memcpy(static_cast<std::uint8_t*>(slot.draws.mapped) + offset, &u, sizeof u);  // the slot's last frame is retired
        const vk::DescriptorSet sets[] = {*m.sets[part.material], *slot.set};
        cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *pipeline_layout, 0, sets, offset);
        c.base_color_factor = state.base_color_factor;
        c.projector[3] = mat.alpha_cutoff;
        cmd.pushConstants<DrawConstants>(*pipeline_layout, vk::ShaderStageFlagBits::eVertex | vk::ShaderStageFlagBits::eFragment,
                                         0, c);
        cmd.drawIndexed(part.index_count, 1, part.first_index, part.vertex_offset, 0);
      }
    }
  return block;
}

void Renderer::Impl::transition_depth(const vk::raii::CommandBuffer& cmd, vk::Image depth) {
  detail::transition(cmd, depth, vk::ImageAspectFlagBits::eDepth, vk::ImageLayout::eUndefined,
                     vk::ImageLayout::eDepthAttachmentOptimal, vk::PipelineStageFlagBits2::eLateFragmentTests,
                     vk::AccessFlagBits2::eDepthStencilAttachmentWrite, vk::PipelineStageFlagBits2::eEarlyFragmentTests,
                     vk::AccessFlagBits2::eDepthStencilAttachmentWrite | vk::AccessFlagBits2::eDepthStencilAttachmentRead);
}

void Renderer::Impl::begin_pass(const vk::raii::CommandBuffer& cmd, vk::ImageView color, vk::ImageView depth, vk::Extent2D extent,
                                const std::array<float, 4>& clear) {
  vk::RenderingAttachmentInfo color_att(color, vk::ImageLayout::eColorAttachmentOptimal, {}, {}, {}, vk::AttachmentLoadOp::eClear,
                                        vk::AttachmentStoreOp::eStore, vk::ClearColorValue(clear));
  vk::RenderingAttachmentInfo depth_att(depth, vk::ImageLayout::eDepthAttachmentOptimal, {}, {}, {}, vk::AttachmentLoadOp::eClear,
                                        vk::AttachmentStoreOp::eDontCare, vk::ClearDepthStencilValue(1.0F, 0));
  cmd.beginRendering(vk::RenderingInfo({}, vk::Rect2D({0, 0}, extent), 1, 0, color_att, depth ? &depth_att : nullptr));
  cmd.setViewport(0, vk::Viewport(0.0F, 0.0F, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0F, 1.0F));
  cmd.setScissor(0, vk::Rect2D({0, 0}, extent));
}

void Renderer::Impl::record_canvas(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, detail::FrameSlot& slot) {
  detail::LensCanvasImages& c = *t.canvas;  // made by draw_frame before the fence was reset
  detail::transition(cmd, *c.color.image, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eUndefined,
                     vk::ImageLayout::eColorAttachmentOptimal, vk::PipelineStageFlagBits2::eFragmentShader,
                     vk::AccessFlagBits2::eShaderSampledRead, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                     vk::AccessFlagBits2::eColorAttachmentWrite);
  transition_depth(cmd, *c.depth.image);
  begin_pass(cmd, *c.color.view, *c.depth.view, c.color.extent, background);
  record_draws(cmd, t.color_format(), c.lens.pinhole, false, c.projector, slot, 0);
  cmd.endRendering();
  detail::transition(cmd, *c.color.image, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eColorAttachmentOptimal,
                     vk::ImageLayout::eShaderReadOnlyOptimal, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                     vk::AccessFlagBits2::eColorAttachmentWrite, vk::PipelineStageFlagBits2::eFragmentShader,
                     vk::AccessFlagBits2::eShaderSampledRead);
}

void Renderer::Impl::record_lens(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::ImageView color) {
  begin_pass(cmd, color, nullptr, t.extent(), background);
  cmd.bindPipeline(vk::PipelineBindPoint::eGraphics, *lens_pipeline(t.color_format()));
  cmd.bindDescriptorSets(vk::PipelineBindPoint::eGraphics, *lens_layout, 0, *t.canvas->set, {});
  cmd.draw(3, 1, 0, 0);
  cmd.endRendering();
}

// The frame's image copied into the target's host buffer after its last write (its layout is then
// eTransferSrcOptimal), made visible to the host by the time the slot's fence signals.
void Renderer::Impl::record_copy(const vk::raii::CommandBuffer& cmd, detail::TargetBackend& t, vk::Image color,
                                 std::size_t slot) {
  const vk::Extent2D e = t.extent();
  cmd.copyImageToBuffer(color, vk::ImageLayout::eTransferSrcOptimal, t.copy_buffer(),
                        vk::BufferImageCopy(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 1),
                                            {0, 0, 0}, vk::Extent3D(e, 1)));
  const vk::MemoryBarrier2 to_host(vk::PipelineStageFlagBits2::eCopy, vk::AccessFlagBits2::eTransferWrite,
                                   vk::PipelineStageFlagBits2::eHost, vk::AccessFlagBits2::eHostRead);
  cmd.pipelineBarrier2(vk::DependencyInfo({}, to_host, {}, {}));
  t.copy = {false, slot, false};
}

bool Renderer::Impl::draw_frame(detail::TargetBackend& t, const config::ProjectorConfig& projector, const PoseReader& read_poses,
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
  std::size_t draws = 0;
  for (const DrawItem& item : items) draws += models[item.model].parts.size();
  ensure_draw_blocks(slot, draws);

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
  if (lens) record_canvas(cmd, t, slot);
  detail::transition(cmd, frame->color, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eUndefined,
                     vk::ImageLayout::eColorAttachmentOptimal, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                     vk::AccessFlagBits2::eNone, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                     vk::AccessFlagBits2::eColorAttachmentWrite);
  if (lens) {
    record_lens(cmd, t, frame->color_view);
  } else {
    transition_depth(cmd, *t.depth().image);
    begin_pass(cmd, frame->color_view, *t.depth().view, t.extent(),
               t.depth_output() ? std::array<float, 4>{0.0F, 0.0F, 0.0F, 0.0F} : background);
    // The projector image (width x height of the intrinsics) is stretched onto the target.
    record_draws(cmd, t.color_format(), projector, t.depth_output(), projector, slot, 0);
    cmd.endRendering();
  }
  const bool to_present = frame->color_final_layout == vk::ImageLayout::ePresentSrcKHR;
  detail::transition(cmd, frame->color, vk::ImageAspectFlagBits::eColor, vk::ImageLayout::eColorAttachmentOptimal,
                     frame->color_final_layout, vk::PipelineStageFlagBits2::eColorAttachmentOutput,
                     vk::AccessFlagBits2::eColorAttachmentWrite,
                     to_present ? vk::PipelineStageFlagBits2::eNone : vk::PipelineStageFlagBits2::eCopy,
                     to_present ? vk::AccessFlagBits2::eNone : vk::AccessFlagBits2::eTransferRead);
  if (t.copy.asked && !to_present) record_copy(cmd, t, frame->color, si);
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

RenderTarget::RenderTarget(std::unique_ptr<detail::TargetBackend> backend) : backend_(std::move(backend)) {}
RenderTarget::~RenderTarget() = default;
int RenderTarget::width() const { return static_cast<int>(backend_->extent().width); }
int RenderTarget::height() const { return static_cast<int>(backend_->extent().height); }
bool RenderTarget::poll_close() { return backend_->poll_close(); }
std::uint64_t RenderTarget::native_window() const { return backend_->native_window(); }
assets::Image RenderTarget::read_back() { return backend_->read_back(); }

bool RenderTarget::copy_next() {
  if (!backend_->copy_buffer()) return false;
  if (!backend_->copy.slot) backend_->copy.asked = true;  // one copy at a time
  return true;
}

std::optional<assets::Image> RenderTarget::take_copy() {
  detail::TargetBackend::CopyOfNext& c = backend_->copy;
  if (!c.slot || !c.done) return std::nullopt;
  c = {};
  return backend_->copied();
}
DepthMap RenderTarget::read_back_depth() { return backend_->read_back_depth(); }

Renderer::Renderer(const RendererOptions& options) : impl_(std::make_unique<Impl>(options)) {}
Renderer::~Renderer() = default;
const DeviceInfo& Renderer::device_info() const { return impl_->gpu->info; }
std::size_t Renderer::add_model(const assets::Model& model) { return impl_->add_model(model); }
void Renderer::replace_model(std::size_t model, const assets::Model& fresh) { impl_->replace_model(model, fresh); }
void Renderer::set_surface(std::size_t model, const assets::Image& reflectance) { impl_->set_surface(model, reflectance); }
void Renderer::set_background(const std::array<std::uint8_t, 3>& rgb) {
  for (std::size_t ch = 0; ch < 3; ++ch) impl_->background[ch] = static_cast<float>(rgb[ch]) / 255.0F;
}
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
