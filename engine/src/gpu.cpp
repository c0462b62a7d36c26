#include "gpu.hpp"

#include <GLFW/glfw3.h>

#include <cstring>
#include <iostream>

namespace projbot::engine::detail {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* gpu = static_cast<Gpu*>(user);
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++gpu->validation_errors;
    std::cerr << "vulkan validation error: " << data->pMessage << '\n';
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    ++gpu->validation_warnings;
    std::cerr << "vulkan validation warning: " << data->pMessage << '\n';
  }
  return VK_FALSE;
}

int device_rank(vk::PhysicalDeviceType type) {
  switch (type) {
    case vk::PhysicalDeviceType::eDiscreteGpu:
      return 4;
    case vk::PhysicalDeviceType::eIntegratedGpu:
      return 3;
    case vk::PhysicalDeviceType::eVirtualGpu:
      return 2;
    case vk::PhysicalDeviceType::eCpu:
      return 1;
    default:
      return 0;
  }
}

}  // namespace

Gpu::Gpu(const RendererOptions& options) : windowing(options.windowing) {
  if (windowing) {
    if (glfwInit() != GLFW_TRUE)
      throw EngineError("cannot open a window: GLFW found no display (set DISPLAY, or run under xvfb-run)");
    if (glfwVulkanSupported() != GLFW_TRUE) {
      glfwTerminate();
      throw EngineError("GLFW finds no Vulkan loader; install libvulkan1 and a driver (mesa-vulkan-drivers)");
    }
  }
  try {
    create_instance(options);
    choose_device(options.device_index);
    create_device();
  } catch (const vk::SystemError& e) {
    if (windowing) glfwTerminate();
    throw EngineError(std::string("Vulkan start-up failed: ") + e.what());
  } catch (...) {
    if (windowing) glfwTerminate();
    throw;
  }
}

void Gpu::create_instance(const RendererOptions& options) {
  std::vector<const char*> extensions;
  std::vector<const char*> layers;
  if (windowing) {
    std::uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    extensions.assign(names, names + count);
  }
  if (options.validation) {
    bool found = false;
    for (const auto& layer : context.enumerateInstanceLayerProperties())
      found = found || std::strcmp(layer.layerName, kValidationLayer) == 0;
    if (!found)
      throw EngineError(
          "validation requested but VK_LAYER_KHRONOS_validation is not installed (apt-get install vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  if (context.enumerateInstanceVersion() < VK_API_VERSION_1_3)
    throw EngineError("the Vulkan loader is older than 1.3; Projbot needs Vulkan 1.3");
  vk::ApplicationInfo app("projbot", 1, "projbot", 1, VK_API_VERSION_1_3);
  vk::DebugUtilsMessengerCreateInfoEXT messenger_info(
      {}, vk::DebugUtilsMessageSeverityFlagBitsEXT::eWarning | vk::DebugUtilsMessageSeverityFlagBitsEXT::eError,
      vk::DebugUtilsMessageTypeFlagBitsEXT::eGeneral | vk::DebugUtilsMessageTypeFlagBitsEXT::eValidation |
          vk::DebugUtilsMessageTypeFlagBitsEXT::ePerformance,
      &on_validation_message, this);
  vk::InstanceCreateInfo instance_info({}, &app, layers, extensions);
  if (options.validation) instance_info.pNext = &messenger_info;  // also covers instance creation itself
  instance = vk::raii::Instance(context, instance_info);
  if (options.validation) messenger = vk::raii::DebugUtilsMessengerEXT(instance, messenger_info);
}

void Gpu::choose_device(int device_index) {
  vk::raii::PhysicalDevices devices(instance);
  if (devices.empty()) throw EngineError("no Vulkan device found (install mesa-vulkan-drivers for the CPU renderer lavapipe)");
  std::size_t chosen = devices.size();
  if (device_index >= 0) {
    if (static_cast<std::size_t>(device_index) >= devices.size())
      throw EngineError("Vulkan device " + std::to_string(device_index) + " requested, but only " +
                        std::to_string(devices.size()) + " found");
    chosen = static_cast<std::size_t>(device_index);
  } else {
    int best = -1;
    for (std::size_t i = 0; i < devices.size(); ++i) {
      const auto props = devices[i].getProperties();
      const int rank = props.apiVersion >= VK_API_VERSION_1_3 ? device_rank(props.deviceType) : -1;
      if (rank > best) best = rank, chosen = i;
    }
    if (best < 0) throw EngineError("no Vulkan 1.3 device found");
  }
  physical = std::move(devices[chosen]);
  const auto props2 = physical.getProperties2<vk::PhysicalDeviceProperties2, vk::PhysicalDeviceDriverProperties>();
  const auto& props = props2.get<vk::PhysicalDeviceProperties2>().properties;
  const auto& driver = props2.get<vk::PhysicalDeviceDriverProperties>();
  if (props.apiVersion < VK_API_VERSION_1_3)
    throw EngineError(std::string("Vulkan device '") + props.deviceName.data() + "' supports only Vulkan " +
                      std::to_string(VK_API_VERSION_MAJOR(props.apiVersion)) + "." +
                      std::to_string(VK_API_VERSION_MINOR(props.apiVersion)) + "; Projbot needs 1.3");
  info.name = props.deviceName.data();
  info.driver = std::string(driver.driverName.data()) + " " + driver.driverInfo.data();
  info.api_version = props.apiVersion;

  const auto families = physical.getQueueFamilyProperties();
  bool found = false;
  for (std::uint32_t i = 0; i < families.size(); ++i)
    if (families[i].queueFlags & vk::QueueFlagBits::eGraphics) {
      queue_family = i;
      found = true;
      break;
    }
  if (!found) throw EngineError(std::string("Vulkan device '") + info.name + "' has no graphics queue");
  info.gpu_timestamps = families[queue_family].timestampValidBits > 0 && props.limits.timestampPeriod > 0.0F;
  timestamp_period_ns = props.limits.timestampPeriod;

  const auto features = physical.getFeatures2<vk::PhysicalDeviceFeatures2, vk::PhysicalDeviceVulkan13Features>();
  const auto& f13 = features.get<vk::PhysicalDeviceVulkan13Features>();
  if (!f13.dynamicRendering || !f13.synchronization2)
    throw EngineError("Vulkan device '" + info.name + "' lacks dynamicRendering or synchronization2");
}

void Gpu::create_device() {
  const float priority = 1.0F;
  vk::DeviceQueueCreateInfo queue_info({}, queue_family, 1, &priority);
  std::vector<const char*> device_extensions;
  if (windowing) device_extensions.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  vk::StructureChain<vk::DeviceCreateInfo, vk::PhysicalDeviceVulkan13Features> device_info(
      vk::DeviceCreateInfo({}, queue_info, {}, device_extensions), vk::PhysicalDeviceVulkan13Features());
  device_info.get<vk::PhysicalDeviceVulkan13Features>().setDynamicRendering(VK_TRUE).setSynchronization2(VK_TRUE);
  device = vk::raii::Device(physical, device_info.get<vk::DeviceCreateInfo>());
  queue = vk::raii::Queue(device, queue_family, 0);
  command_pool = vk::raii::CommandPool(device, {vk::CommandPoolCreateFlagBits::eResetCommandBuffer, queue_family});
}

Gpu::~Gpu() {
  if (*device) device.waitIdle();
  command_pool.clear();
  queue.clear();
  device.clear();
  messenger.clear();
  instance.clear();
  if (windowing) glfwTerminate();
}

std::uint32_t Gpu::memory_type(std::uint32_t type_bits, vk::MemoryPropertyFlags props) const {
  const auto mem = physical.getMemoryProperties();
  for (std::uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if ((type_bits & (1U << i)) && (mem.memoryTypes[i].propertyFlags & props) == props) return i;
  throw EngineError("no Vulkan memory type with the needed properties");
}

Buffer Gpu::make_buffer(vk::DeviceSize size, vk::BufferUsageFlags usage, vk::MemoryPropertyFlags props) {
  Buffer b;
  b.size = size;
  b.buffer = vk::raii::Buffer(device, vk::BufferCreateInfo({}, size, usage, vk::SharingMode::eExclusive));
  const auto req = b.buffer.getMemoryRequirements();
  b.memory = vk::raii::DeviceMemory(device, vk::MemoryAllocateInfo(req.size, memory_type(req.memoryTypeBits, props)));
  b.buffer.bindMemory(*b.memory, 0);
  if (props & vk::MemoryPropertyFlagBits::eHostVisible) b.mapped = b.memory.mapMemory(0, size);
  return b;
}

Buffer Gpu::upload_buffer(const void* data, vk::DeviceSize size, vk::BufferUsageFlags usage) {
  Buffer staging = make_buffer(size, vk::BufferUsageFlagBits::eTransferSrc,
                               vk::MemoryPropertyFlagBits::eHostVisible | vk::MemoryPropertyFlagBits::eHostCoherent);
  std::memcpy(staging.mapped, data, size);
  Buffer out = make_buffer(size, usage | vk::BufferUsageFlagBits::eTransferDst, vk::MemoryPropertyFlagBits::eDeviceLocal);
  one_shot([&](vk::raii::CommandBuffer& cmd) { cmd.copyBuffer(*staging.buffer, *out.buffer, vk::BufferCopy(0, 0, size)); });
  return out;
}

Image Gpu::make_image(vk::Extent2D extent, vk::Format format, vk::ImageUsageFlags usage, vk::ImageAspectFlags aspect) {
  Image img;
  img.format = format;
  img.extent = extent;
  img.image = vk::raii::Image(device, vk::ImageCreateInfo({}, vk::ImageType::e2D, format, vk::Extent3D(extent, 1), 1, 1,
                                                          vk::SampleCountFlagBits::e1, vk::ImageTiling::eOptimal, usage));
  const auto req = img.image.getMemoryRequirements();
  img.memory = vk::raii::DeviceMemory(
      device, vk::MemoryAllocateInfo(req.size, memory_type(req.memoryTypeBits, vk::MemoryPropertyFlagBits::eDeviceLocal)));
  img.image.bindMemory(*img.memory, 0);
  img.view = vk::raii::ImageView(device, vk::ImageViewCreateInfo({}, *img.image, vk::ImageViewType::e2D, format, {},
                                                                 vk::ImageSubresourceRange(aspect, 0, 1, 0, 1)));
  return img;
}

void Gpu::one_shot(const std::function<void(vk::raii::CommandBuffer&)>& record) {
  vk::raii::CommandBuffers cmds(device, vk::CommandBufferAllocateInfo(*command_pool, vk::CommandBufferLevel::ePrimary, 1));
  vk::raii::CommandBuffer& cmd = cmds[0];
  cmd.begin(vk::CommandBufferBeginInfo(vk::CommandBufferUsageFlagBits::eOneTimeSubmit));
  record(cmd);
  cmd.end();
  vk::raii::Fence fence(device, vk::FenceCreateInfo());
  const vk::CommandBuffer raw = *cmd;
  queue.submit(vk::SubmitInfo({}, {}, raw), *fence);
  if (device.waitForFences(*fence, VK_TRUE, UINT64_MAX) != vk::Result::eSuccess)
    throw EngineError("one-shot GPU command did not finish");
}

void transition(const vk::raii::CommandBuffer& cmd, vk::Image image, vk::ImageAspectFlags aspect, vk::ImageLayout from,
                vk::ImageLayout to, vk::PipelineStageFlags2 src_stage, vk::AccessFlags2 src_access,
                vk::PipelineStageFlags2 dst_stage, vk::AccessFlags2 dst_access) {
  vk::ImageMemoryBarrier2 barrier(src_stage, src_access, dst_stage, dst_access, from, to, VK_QUEUE_FAMILY_IGNORED,
                                  VK_QUEUE_FAMILY_IGNORED, image, vk::ImageSubresourceRange(aspect, 0, 1, 0, 1));
  cmd.pipelineBarrier2(vk::DependencyInfo({}, {}, {}, barrier));
}

}  // namespace projbot::engine::detail
