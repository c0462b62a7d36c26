#pragma once
// The Vulkan device every engine object shares: instance, optional validation messenger, device,
// one graphics queue and helpers for buffers, images and one-shot commands. Render thread only.

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>
#include <vulkan/vulkan_raii.hpp>

#include "projbot/engine/projection.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::engine::detail {

struct Buffer {
  vk::raii::Buffer buffer{nullptr};
  vk::raii::DeviceMemory memory{nullptr};
  vk::DeviceSize size = 0;
  void* mapped = nullptr;  ///< persistently mapped when host visible
};

struct Image {
  vk::raii::Image image{nullptr};
  vk::raii::DeviceMemory memory{nullptr};
  vk::raii::ImageView view{nullptr};
  vk::Format format = vk::Format::eUndefined;
  vk::Extent2D extent;
};

class Gpu {
 public:
  explicit Gpu(const RendererOptions& options);
  ~Gpu();

  vk::raii::Context context;
  vk::raii::Instance instance{nullptr};
  vk::raii::DebugUtilsMessengerEXT messenger{nullptr};
  vk::raii::PhysicalDevice physical{nullptr};
  vk::raii::Device device{nullptr};
  vk::raii::Queue queue{nullptr};
  std::uint32_t queue_family = 0;
  vk::raii::CommandPool command_pool{nullptr};
  DeviceInfo info;
  double timestamp_period_ns = 0.0;
  bool windowing = false;

  std::atomic<std::size_t> validation_warnings{0};
  std::atomic<std::size_t> validation_errors{0};

  Buffer make_buffer(vk::DeviceSize size, vk::BufferUsageFlags usage, vk::MemoryPropertyFlags props);
  /// A device-local buffer filled from host memory through a staging buffer.
  Buffer upload_buffer(const void* data, vk::DeviceSize size, vk::BufferUsageFlags usage);
  Image make_image(vk::Extent2D extent, vk::Format format, vk::ImageUsageFlags usage, vk::ImageAspectFlags aspect);
  /// Records with `record`, submits and waits (uploads, readbacks).
  void one_shot(const std::function<void(vk::raii::CommandBuffer&)>& record);

 private:
  std::uint32_t memory_type(std::uint32_t type_bits, vk::MemoryPropertyFlags props) const;
  // Start-up, in this order: the instance (GLFW's extensions; the validation layer and its messenger
  // when asked); the physical device (the one asked for, else the best Vulkan 1.3 one: info, the graphics
  // queue family, timestamps; dynamic rendering and synchronization2 required); the logical device, its
  // queue and command pool.
  void create_instance(const RendererOptions& options);
  void choose_device(int device_index);
  void create_device();
};

/// An image layout transition with synchronization2, for the whole image.
void transition(const vk::raii::CommandBuffer& cmd, vk::Image image, vk::ImageAspectFlags aspect, vk::ImageLayout from,
                vk::ImageLayout to, vk::PipelineStageFlags2 src_stage, vk::AccessFlags2 src_access,
                vk::PipelineStageFlags2 dst_stage, vk::AccessFlags2 dst_access);

/// What a frame renders into, provided by a target backend.
struct FrameImage {
  vk::Image color;
  vk::ImageView color_view;
  vk::ImageLayout color_final_layout;  ///< layout the backend wants at the end of the frame
  vk::Semaphore wait;                  ///< signalled when the image may be written (swapchain), or null
  vk::Semaphore signal;                ///< to signal when rendering is done (swapchain), or null
  std::uint32_t index = 0;
};

/// One frame in flight: its commands, fence, acquire semaphore and the timing waiting for its fence.
struct FrameSlot {
  vk::raii::CommandBuffer cmd{nullptr};
  Buffer photometry;  ///< the projector's response for mesh.frag (set 1), written before this slot's frame
  vk::raii::DescriptorPool pool{nullptr};
  vk::raii::DescriptorSet set{nullptr};
  Buffer draws;                   ///< each draw's material block (set 1 binding 1, dynamic offsets), host visible
  std::size_t draw_capacity = 0;  ///< how many blocks `draws` holds
  vk::raii::Fence fence{nullptr};
  vk::raii::Semaphore acquired{nullptr};
  std::vector<std::shared_ptr<const void>> held;  ///< what this slot's frame reads from host memory (video frames)
  bool pending = false;                           ///< a submitted frame whose timing is not yet handed to its profiler
  FrameRecord record;
  FrameProfiler* profiler = nullptr;
};

/// The lens pass's undistorted canvas (renderer.cpp): made on a target's first frame for a projector
/// with distortion, remade when the target's size or the projector changes.
struct LensCanvasImages {
  Image color;  ///< the target's format, drawn then sampled
  Image depth;
  Image warp;                         ///< engine::lens_warp at the target's size: the canvas position per pixel
  config::ProjectorConfig projector;  ///< the projector (lens) it was made for
  LensCanvas lens;                    ///< lens_canvas(projector): the canvas's pinhole and margins
  vk::raii::DescriptorPool pool{nullptr};
  vk::raii::DescriptorSet set{nullptr};
};

/// An offscreen image or a swapchain. Created and used by the render thread.
class TargetBackend {
 public:
  explicit TargetBackend(std::shared_ptr<Gpu> shared) : gpu(std::move(shared)) {}
  virtual ~TargetBackend() = default;

  std::shared_ptr<Gpu> gpu;  ///< declared first: outlives every Vulkan object below and in subclasses

  // Frames in flight, owned here so they live exactly as long as the images they render into;
  // the Renderer fills them on first use.
  std::vector<FrameSlot> slots;
  std::size_t next_slot = 0;
  vk::raii::QueryPool timestamps{nullptr};
  std::optional<LensCanvasImages> canvas;

  virtual vk::Extent2D extent() const = 0;
  virtual vk::Format color_format() const = 0;
  virtual const Image& depth() const = 0;
  /// Gets the image to render into. `acquired` is signalled when it may be written. Empty when the
  /// frame must be skipped (window minimised, swapchain rebuilt).
  virtual std::optional<FrameImage> acquire(vk::Semaphore acquired) = 0;
  /// Presents (swapchain); no-op offscreen.
  virtual void present(const FrameImage& frame) = 0;
  virtual bool poll_close() { return false; }
  virtual std::uint64_t native_window() const { return 0; }
  virtual assets::Image read_back() = 0;
  /// Where a frame's copy is recorded (CopyOfNext); null for a target whose frames are not copied (a window,
  /// a depth camera).
  virtual vk::Buffer copy_buffer() { return nullptr; }
  /// The copy's bytes, once its frame is done: the image as read_back gives it.
  virtual assets::Image copied() { throw EngineError("this target's frames are not copied"); }

  /// A copy of the next frame, recorded into its own commands (nothing waits for it): asked for, then the
  /// slot whose frame holds it, then done once that slot is retired.
  struct CopyOfNext {
    bool asked = false;
    std::optional<std::size_t> slot;
    bool done = false;
  } copy;
  /// True for a depth camera target: R32 float colour holding camera-frame depth, 0 where no surface.
  virtual bool depth_output() const { return false; }
  virtual DepthMap read_back_depth() { throw EngineError("read_back_depth: this target renders colour, not depth"); }
};

std::unique_ptr<TargetBackend> make_offscreen_backend(std::shared_ptr<Gpu> gpu, vk::Extent2D extent, bool depth_output);
std::unique_ptr<TargetBackend> make_window_backend(std::shared_ptr<Gpu> gpu, const WindowOptions& options);

constexpr vk::Format kDepthFormat = vk::Format::eD32Sfloat;

}  // namespace projbot::engine::detail
