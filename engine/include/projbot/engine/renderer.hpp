#pragma once
// The projector renderer: draws textured target models through the projector intrinsics (Eq. 3)
// into an offscreen image or a GLFW window. Owns every Vulkan object; one thread (the render thread)
// creates it and calls every member.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "projbot/assets/model.hpp"
#include "projbot/assets/video.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/photometry.hpp"

namespace projbot::engine {

/// An expected engine failure: no Vulkan device, no display, no requested layer. The message says
/// what is missing and what to do about it.
class EngineError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct RendererOptions {
  bool validation = false;  ///< enable VK_LAYER_KHRONOS_validation; fails if the layer is missing
  bool windowing = false;   ///< initialise GLFW so windows can be made; fails without a display
  int device_index = -1;    ///< physical device to use; -1 picks discrete > integrated > CPU
};

/// What was chosen at start-up.
struct DeviceInfo {
  std::string name;    ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string driver;  ///< driver name and info
  std::uint32_t api_version = 0;
  bool gpu_timestamps = false;
};

enum class PresentMode { kFifo, kMailbox, kImmediate };

/// A GLFW window: the projector output (fullscreen) or a preview (windowed).
struct WindowOptions {
  std::string title = "projbot";
  int width_px = 1280;  ///< windowed size; ignored fullscreen (the monitor's mode is used)
  int height_px = 800;
  bool fullscreen = false;
  int monitor = 0;                                ///< index into the connected monitors, for fullscreen
  PresentMode present_mode = PresentMode::kFifo;  ///< falls back to FIFO where unsupported
};

/// A connected monitor as GLFW reports it (the projector is one).
struct MonitorInfo {
  std::string name;
  int width_px = 0;
  int height_px = 0;
  int refresh_hz = 0;
};
/// The connected monitors in GLFW's order (the index --monitor and `devices.projector.monitor` take).
/// Throws EngineError when there is no display. Starts and stops GLFW: call it while no windowing
/// Renderer exists.
std::vector<MonitorInfo> connected_monitors();

/// A simulated depth camera's image: camera-frame depth Z of the nearest surface, metres, row-major,
/// top row first; 0 where no surface was hit (as a Kinect reports missing depth).
struct DepthMap {
  int width = 0;
  int height = 0;
  std::vector<float> z_m;
};

/// One target to draw: which uploaded model, and T_projector_target (model frame -> projector frame).
struct DrawItem {
  DrawItem() = default;
  DrawItem(std::size_t model_id, const Eigen::Matrix4d& T, const Compensation& comp = {})
      : model(model_id), T_projector_target(T), compensation(comp) {}
  std::size_t model = 0;
  Eigen::Matrix4d T_projector_target = Eigen::Matrix4d::Identity();
  Compensation compensation;  ///< off: the content as stored; on: what makes its surface show it (issue 43)
  /// Materials drawn other than as loaded (issue 44: a content timeline, the model's own animations): each a
  /// material index of the model and its state in this draw (base colour factor, emission, texture placements).
  std::vector<std::pair<int, assets::MaterialState>> materials;
};

/// Called once per frame, as late as possible, to fill the poses to draw (the newest ones).
using PoseReader = std::function<void(std::vector<DrawItem>& items)>;

namespace detail {
class TargetBackend;
}

/// Where frames go: an offscreen image or a window. Made by a Renderer; it shares ownership of the
/// device, so it may outlive the Renderer object.
class RenderTarget {
 public:
  explicit RenderTarget(std::unique_ptr<detail::TargetBackend> backend);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  int width() const;  ///< current size in pixels
  int height() const;
  /// Windows: handles events, true once the user closed it. Offscreen: always false.
  bool poll_close();
  /// X11 window id of a window target (for screenshots), 0 otherwise.
  std::uint64_t native_window() const;
  /// Offscreen: the last drawn frame as RGBA8 (waits for it). Windows and depth cameras: throws EngineError.
  assets::Image read_back();
  /// Offscreen colour: a copy of the next frame drawn, recorded into that frame's own commands, so that
  /// nothing waits for it (read_back waits for the GPU); take_copy gives it once that frame is done. One
  /// copy at a time: asking again before it is taken changes nothing. False for a target whose frames are
  /// not copied (a window, a depth camera).
  bool copy_next();
  /// The copy asked for by copy_next, once its frame is done (never waits); nullopt before.
  std::optional<assets::Image> take_copy();
  /// Depth cameras: the last drawn frame's depth (waits for it). Other targets: throws EngineError.
  DepthMap read_back_depth();

  detail::TargetBackend& backend() { return *backend_; }

 private:
  std::unique_ptr<detail::TargetBackend> backend_;
};

class Renderer {
 public:
  /// Creates the Vulkan instance and device. Throws EngineError naming what is missing.
  explicit Renderer(const RendererOptions& options);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  const DeviceInfo& device_info() const;

  /// Uploads a model's meshes and textures; returns its id for DrawItem::model.
  std::size_t add_model(const assets::Model& model);
  /// Model `model` drawn from `fresh` from the next frame: its vertices, materials and textures (a texture
  /// or material changed on disk, issue 44). Its surface and the streamed textures bound to its materials
  /// stay. `fresh` must have as many materials; its shape is the caller's to check (the trackers keep the
  /// old one). Waits for the frames in flight. Throws EngineError, leaving the old one drawn.
  void replace_model(std::size_t model, const assets::Model& fresh);
  /// The physical surface of model `model`'s target (issue 43, `surface.texture`): its reflectance over the
  /// model's UVs (RGBA8, sRGB-coded), which compensation divides the content by, per fragment, besides the
  /// Compensation's per-channel scale (give the target an albedo of 1 there). Until set, every model's is
  /// white. Waits for the frames in flight. Throws EngineError for a model that is not there or an empty image.
  void set_surface(std::size_t model, const assets::Image& reflectance);
  /// A texture whose texels change while it is drawn (a video on a material, issue 44): made black at
  /// width x height px, it becomes material `material`'s base colour texture of model `model` (the material's
  /// sampler, base colour factor and the vertex colours still apply). Waits for the frames in flight.
  /// Returns its id for stream_frame. Throws EngineError for a model or material that is not there.
  std::size_t add_streamed_texture(std::size_t model, int material, int width_px, int height_px);
  /// Makes streamed texture `texture` also material `material`'s base colour of model `model` (one video on
  /// several targets: decoded and uploaded once). Waits for the frames in flight.
  void bind_streamed_texture(std::size_t texture, std::size_t model, int material);
  /// Texels (RGBA8, the texture's size) for streamed texture `texture`: the next draw_frame copies them into
  /// its frame's staging memory (the render thread's whole share, FrameRecord::upload_ms) and the GPU uploads
  /// them before it draws. Until then the image is held. May be called from a PoseReader.
  void stream_frame(std::size_t texture, std::shared_ptr<const assets::Image> image);
  /// Host memory the GPU copies streamed textures from: a video player decodes into it (its PixelAllocator),
  /// and stream_pixels then costs the render thread no copy at all. Thread-safe (the decoder thread calls it);
  /// the memory lives while PixelMemory::owner does. Throws EngineError.
  assets::PixelMemory frame_memory(std::size_t bytes);
  /// As stream_frame, from texels (the texture's size, RGBA8) in this renderer's frame_memory: the next
  /// draw_frame's GPU copy reads them there, and `keep` (what keeps them unchanged, the video frame) is held
  /// until that frame is done.
  void stream_pixels(std::size_t texture, const assets::PixelMemory& pixels, std::shared_ptr<const void> keep);

  /// An offscreen RGBA8 target of the given size.
  std::unique_ptr<RenderTarget> make_offscreen(int width_px, int height_px);
  /// A depth camera of the given size: draw_frame() through the camera (its config::Camera) and T_camera_target poses renders the
  /// depth of every surface, whatever its material.
  std::unique_ptr<RenderTarget> make_depth_camera(int width_px, int height_px);
  /// A window with a swapchain. Needs RendererOptions::windowing.
  std::unique_ptr<RenderTarget> make_window(const WindowOptions& options);

  /// The background of the frames drawn from now on, 8-bit levels per channel as the target stores them
  /// (black until set): what a projector shows where no model is, and over its whole image with none
  /// (a reflectance measurement's uniform grey). Depth cameras' frames are unaffected.
  void set_background(const std::array<std::uint8_t, 3>& rgb);

  /// Draws one frame: the background (black unless set), depth-tested, unlit textured models placed by their poses and
  /// projected through `projector` (whose size is stretched onto the target; its photometry sets the
  /// white gain). Returns false if the frame was skipped (window minimised or swapchain rebuilt). Records
  /// timing into `profiler` if given.
  bool draw_frame(RenderTarget& target, const config::ProjectorConfig& projector, const PoseReader& read_poses,
                  FrameProfiler* profiler = nullptr);
  bool draw_frame(RenderTarget& target, const config::ProjectorConfig& projector, std::span<const DrawItem> items,
                  FrameProfiler* profiler = nullptr);
  /// The same through a camera (a depth or colour camera's view: no projector photometry, white as stored).
  bool draw_frame(RenderTarget& target, const config::Camera& camera, std::span<const DrawItem> items,
                  FrameProfiler* profiler = nullptr) {
    return draw_frame(target, config::ProjectorConfig(camera), items, profiler);
  }

  /// Waits for every frame submitted to `target` and hands their pending timings to their profilers.
  void finish(RenderTarget& target);

  /// Validation-layer messages seen so far (warnings and errors), when validation is on.
  std::size_t validation_warnings() const;
  std::size_t validation_errors() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::engine
