// Render targets: an offscreen RGBA8 image with readback, and a GLFW window with a swapchain.

#include <vulkan/vulkan_raii.hpp>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstring>
#include <iostream>

#include "gpu.hpp"

namespace projbot::engine::detail {

std::uint64_t x11_window_of(GLFWwindow* window);  // x11_window.cpp: X11's macros stay out of here

namespace {

void check_extent(std::uint32_t w, std::uint32_t h, const char* what) {
  if (w == 0 || h == 0 || w > 16384 || h > 16384)
    throw EngineError(std::string(what) + " size " + std::to_string(w) + "x" + std::to_string(h) + " must be 1..16384 each way");
}

Image make_depth(Gpu& gpu, vk::Extent2D extent) {
  return gpu.make_image(extent, kDepthFormat, vk::ImageUsageFlagBits::eDepthStencilAttachment, vk::ImageAspectFlagBits::eDepth);
}

class OffscreenBackend final : public TargetBackend {
 public:
  OffscreenBackend(std::shared_ptr<Gpu> shared, vk::Extent2D extent, bool depth_output)
      : TargetBackend(std::move(shared)),
        depth_output_(depth_output),
        format_(depth_output ? vk::Format::eR32Sfloat : vk::Format::eR8G8B8A8Unorm) {
    check_extent(extent.width, extent.height, "offscreen target");
    color_ = gpu->make_image(extent, format_, vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eTransferSrc,
                             vk::ImageAspectFlagBits::eColor);
    depth_ = make_depth(*gpu, extent);
    readback_ = gpu->make_buffer(vk::DeviceSize(extent.width) * extent.height * 4, vk::BufferUsageFlagBits::eTransferDst,
                                 vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
  }
  ~OffscreenBackend() override {
    gpu->device.waitIdle();
    slots.clear();
    timestamps.clear();
  }

  vk::Extent2D extent() const override { return color_.extent; }
  vk::Format color_format() const override { return format_; }
  bool depth_output() const override { return depth_output_; }
  const Image& depth() const override { return depth_; }

  std::optional<FrameImage> acquire(vk::Semaphore /*acquired*/) override {
    return FrameImage{*color_.image, *color_.view, vk::ImageLayout::eTransferSrcOptimal, nullptr, nullptr, 0};
  }
  void present(const FrameImage& /*frame*/) override { drawn_ = true; }  // a frame was submitted

  assets::Image read_back() override {
    if (depth_output_) throw EngineError("read_back: this target renders depth; use read_back_depth");
    copy_to_host();
    return copied();
  }

  vk::Buffer copy_buffer() override { return depth_output_ ? vk::Buffer{} : *readback_.buffer; }
  assets::Image copied() override {
    assets::Image out;
    out.width = static_cast<int>(color_.extent.width);
    out.height = static_cast<int>(color_.extent.height);
    const auto* bytes = static_cast<const std::uint8_t*>(readback_.mapped);
    out.rgba.assign(bytes, bytes + readback_.size);
    return out;
  }

  DepthMap read_back_depth() override {
    if (!depth_output_) throw EngineError("read_back_depth: this target renders colour; use read_back");
    DepthMap out;
    out.width = static_cast<int>(color_.extent.width);
    out.height = static_cast<int>(color_.extent.height);
    const auto* z = static_cast<const float*>(copy_to_host());
    out.z_m.assign(z, z + static_cast<std::size_t>(out.width) * out.height);
    return out;
  }

 private:
  // Waits for the last frame and copies its image into the host-visible readback buffer.
  const void* copy_to_host() {
    if (!drawn_) throw EngineError("read_back: nothing has been drawn into this target yet");
    gpu->queue.waitIdle();  // the last frame wrote the image
    const vk::Extent2D e = color_.extent;
    gpu->one_shot([&](vk::raii::CommandBuffer& cmd) {
      cmd.copyImageToBuffer(*color_.image, vk::ImageLayout::eTransferSrcOptimal, *readback_.buffer,
                            vk::BufferImageCopy(0, 0, 0, vk::ImageSubresourceLayers(vk::ImageAspectFlagBits::eColor, 0, 0, 1),
                                                {0, 0, 0}, vk::Extent3D(e, 1)));
    });
    return readback_.mapped;
  }

  bool depth_output_;
  vk::Format format_;
  Image color_;
  Image depth_;
  Buffer readback_;
  bool drawn_ = false;
};

vk::PresentModeKHR to_vk(PresentMode mode) {
  switch (mode) {
    case PresentMode::kMailbox:
      return vk::PresentModeKHR::eMailbox;
    case PresentMode::kImmediate:
      return vk::PresentModeKHR::eImmediate;
    default:
      return vk::PresentModeKHR::eFifo;
  }
}

// A GLFW window and its swapchain, rebuilt when the window is resized or the swapchain goes out of date.
class WindowBackend final : public TargetBackend {
 public:
  WindowBackend(std::shared_ptr<Gpu> shared, const WindowOptions& options) : TargetBackend(std::move(shared)), options_(options) {
    if (!gpu->windowing) throw EngineError("make_window: the renderer was created without windowing");
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    GLFWmonitor* monitor = nullptr;
    int w = options.width_px, h = options.height_px;
    if (options.fullscreen) {
      int count = 0;
      GLFWmonitor** monitors = glfwGetMonitors(&count);
      if (options.monitor < 0 || options.monitor >= count)
        throw EngineError("monitor " + std::to_string(options.monitor) + " requested, but " + std::to_string(count) +
                          " connected (use --monitor 0.." + std::to_string(std::max(count - 1, 0)) + ")");
      monitor = monitors[options.monitor];
      const GLFWvidmode* mode = glfwGetVideoMode(monitor);
      w = mode->width;
      h = mode->height;
    }
    check_extent(static_cast<std::uint32_t>(std::max(w, 0)), static_cast<std::uint32_t>(std::max(h, 0)), "window");
    window_ = glfwCreateWindow(w, h, options.title.c_str(), monitor, nullptr);
    if (window_ == nullptr)
      throw EngineError("GLFW could not create a " + std::to_string(w) + "x" + std::to_string(h) + " window");
    glfwSetWindowUserPointer(window_, this);
    // Esc closes the output; a projector shows no mouse cursor.
    glfwSetKeyCallback(window_, [](GLFWwindow* win, int key, int, int action, int) {
      if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(win, GLFW_TRUE);
    });
    if (options.fullscreen) glfwSetInputMode(window_, GLFW_CURSOR, GLFW_CURSOR_HIDDEN);
    glfwSetFramebufferSizeCallback(
        window_, [](GLFWwindow* win, int, int) { static_cast<WindowBackend*>(glfwGetWindowUserPointer(win))->resized_ = true; });
    VkSurfaceKHR raw_surface = VK_NULL_HANDLE;
    if (glfwCreateWindowSurface(*gpu->instance, window_, nullptr, &raw_surface) != VK_SUCCESS) {
      glfwDestroyWindow(window_);
      throw EngineError("GLFW could not create a Vulkan surface for the window");
    }
    surface_ = vk::raii::SurfaceKHR(gpu->instance, raw_surface);
    if (!gpu->physical.getSurfaceSupportKHR(gpu->queue_family, *surface_)) {
      surface_.clear();
      glfwDestroyWindow(window_);
      throw EngineError("the Vulkan device's graphics queue cannot present to this window");
    }
    format_ = choose_format();
    build_swapchain();
  }

  ~WindowBackend() override {
    gpu->device.waitIdle();
    slots.clear();
    timestamps.clear();
    render_done_.clear();
    views_.clear();
    swapchain_.clear();
    surface_.clear();
    glfwDestroyWindow(window_);
  }

  vk::Extent2D extent() const override { return extent_; }
  vk::Format color_format() const override { return format_; }
  const Image& depth() const override { return depth_; }
  bool poll_close() override {
    glfwPollEvents();
    return glfwWindowShouldClose(window_) == GLFW_TRUE;
  }
  std::uint64_t native_window() const override { return x11_window_of(window_); }
  assets::Image read_back() override { throw EngineError("read_back: a window's frames are read with a screenshot, not here"); }

  std::optional<FrameImage> acquire(vk::Semaphore acquired) override {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    if (fw == 0 || fh == 0) return std::nullopt;  // minimised
    if (resized_ || stale_) {
      build_swapchain();
      return std::nullopt;
    }
    std::uint32_t index = 0;
    try {
      const auto [result, i] = swapchain_.acquireNextImage(UINT64_MAX, acquired, nullptr);
      if (result == vk::Result::eSuboptimalKHR) stale_ = true;  // use this image, rebuild after presenting
      index = i;
    } catch (const vk::OutOfDateKHRError&) {
      build_swapchain();
      return std::nullopt;
    }
    return FrameImage{images_[index], *views_[index], vk::ImageLayout::ePresentSrcKHR, acquired, *render_done_[index], index};
  }

  void present(const FrameImage& frame) override {
    const vk::SwapchainKHR chain = *swapchain_;
    try {
      if (gpu->queue.presentKHR(vk::PresentInfoKHR(frame.signal, chain, frame.index)) == vk::Result::eSuboptimalKHR)
        stale_ = true;
    } catch (const vk::OutOfDateKHRError&) {
      stale_ = true;
    }
  }

 private:
  vk::Format choose_format() const {
    const auto formats = gpu->physical.getSurfaceFormatsKHR(*surface_);
    // UNORM so that texture values reach the screen as stored, like the offscreen target.
    for (vk::Format want : {vk::Format::eB8G8R8A8Unorm, vk::Format::eR8G8B8A8Unorm})
      for (const auto& f : formats)
        if (f.format == want) return want;
    if (formats.empty()) throw EngineError("the window surface offers no formats");
    std::cerr << "projbot: no UNORM swapchain format; colours may be converted by the display\n";
    return formats.front().format;
  }

  void build_swapchain() {
    gpu->device.waitIdle();
    resized_ = false;
    stale_ = false;
    const auto caps = gpu->physical.getSurfaceCapabilitiesKHR(*surface_);
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    extent_ =
        caps.currentExtent.width != UINT32_MAX
            ? caps.currentExtent
            : vk::Extent2D(std::clamp(static_cast<std::uint32_t>(fw), caps.minImageExtent.width, caps.maxImageExtent.width),
                           std::clamp(static_cast<std::uint32_t>(fh), caps.minImageExtent.height, caps.maxImageExtent.height));
    if (extent_.width == 0 || extent_.height == 0) return;
    const auto modes = gpu->physical.getSurfacePresentModesKHR(*surface_);
    vk::PresentModeKHR mode = to_vk(options_.present_mode);
    if (std::find(modes.begin(), modes.end(), mode) == modes.end()) {
      if (!warned_mode_) std::cerr << "projbot: present mode " << vk::to_string(mode) << " unsupported here, using FIFO\n";
      warned_mode_ = true;
      mode = vk::PresentModeKHR::eFifo;
    }
    std::uint32_t count = std::max(caps.minImageCount + 1, 2U);
    if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);
    vk::CompositeAlphaFlagBitsKHR alpha = vk::CompositeAlphaFlagBitsKHR::eOpaque;
    if (!(caps.supportedCompositeAlpha & alpha)) alpha = vk::CompositeAlphaFlagBitsKHR::eInherit;
    vk::SwapchainCreateInfoKHR info({}, *surface_, count, format_, vk::ColorSpaceKHR::eSrgbNonlinear, extent_, 1,
                                    vk::ImageUsageFlagBits::eColorAttachment | vk::ImageUsageFlagBits::eTransferSrc,
                                    vk::SharingMode::eExclusive, {}, caps.currentTransform, alpha, mode, VK_TRUE, *swapchain_);
    vk::raii::SwapchainKHR next(gpu->device, info);
    views_.clear();
    render_done_.clear();
    swapchain_ = std::move(next);
    images_ = swapchain_.getImages();
    for (vk::Image image : images_) {
      views_.emplace_back(gpu->device,
                          vk::ImageViewCreateInfo({}, image, vk::ImageViewType::e2D, format_, {},
                                                  vk::ImageSubresourceRange(vk::ImageAspectFlagBits::eColor, 0, 1, 0, 1)));
      render_done_.emplace_back(gpu->device, vk::SemaphoreCreateInfo());
    }
    depth_ = make_depth(*gpu, extent_);
  }

  WindowOptions options_;
  GLFWwindow* window_ = nullptr;
  vk::raii::SurfaceKHR surface_{nullptr};
  vk::raii::SwapchainKHR swapchain_{nullptr};
  std::vector<vk::Image> images_;
  std::vector<vk::raii::ImageView> views_;
  std::vector<vk::raii::Semaphore> render_done_;  // one per swapchain image: reused only after that image returns
  Image depth_;
  vk::Format format_ = vk::Format::eUndefined;
  vk::Extent2D extent_;
  bool resized_ = false;
  bool stale_ = false;
  bool warned_mode_ = false;
};

}  // namespace

std::unique_ptr<TargetBackend> make_offscreen_backend(std::shared_ptr<Gpu> gpu, vk::Extent2D extent, bool depth_output) {
  return std::make_unique<OffscreenBackend>(std::move(gpu), extent, depth_output);
}

std::unique_ptr<TargetBackend> make_window_backend(std::shared_ptr<Gpu> gpu, const WindowOptions& options) {
  return std::make_unique<WindowBackend>(std::move(gpu), options);
}

}  // namespace projbot::engine::detail

namespace projbot::engine {

std::vector<MonitorInfo> connected_monitors() {
  if (glfwInit() != GLFW_TRUE) throw EngineError("no display: GLFW cannot see any monitor (set DISPLAY, or run under xvfb-run)");
  std::vector<MonitorInfo> out;
  int count = 0;
  GLFWmonitor** monitors = glfwGetMonitors(&count);
  for (int i = 0; i < count; ++i) {
    MonitorInfo m;
    const char* name = glfwGetMonitorName(monitors[i]);
    m.name = name != nullptr ? name : "";
    if (const GLFWvidmode* mode = glfwGetVideoMode(monitors[i]); mode != nullptr) {
      m.width_px = mode->width;
      m.height_px = mode->height;
      m.refresh_hz = mode->refreshRate;
    }
    out.push_back(m);
  }
  glfwTerminate();
  return out;
}

}  // namespace projbot::engine
