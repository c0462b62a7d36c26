#include "projbot/twin/camera.hpp"

#include <thread>

#include "projbot/config/clock.hpp"

namespace projbot::twin {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

void TwinCamera::at_stop(std::size_t target, int target_visit, int visit, double since_s) {
  target_ = target;
  target_visit_ = target_visit;
  visit_ = visit;
  since_s_ = since_s;
  frame_ = 0;
  tick_ = Clock::now();
}

void TwinCamera::see_projector(engine::Renderer& renderer, UniformLight shown) {
  shown_ = std::move(shown);
  colour_camera_ = std::make_unique<SpectatorView>(renderer, twin_.scene().projector, twin_.camera_pinhole());
}

alignment::RgbdFrame TwinCamera::next() {
  if (frame_ > 0) {  // 30 Hz, like the Kinect; one that fell behind does not burst
    tick_ += std::chrono::microseconds(33333);
    std::this_thread::sleep_until(tick_);
    if (Clock::now() > tick_ + std::chrono::milliseconds(100)) tick_ = Clock::now();
  }
  const double captured = config::steady_now_s();
  twin_.targets().at(target_).T_world_target_true = twin_.scripted_pose(target_, target_visit_, captured - since_s_);
  const Eigen::Matrix4d T_world_camera = twin_.true_head().T_world_camera.matrix();
  alignment::RgbdFrame f;
  f.depth = twin_.capture(T_world_camera, static_cast<std::uint32_t>(seed_ * 7919 + frame_));
  const std::optional<std::array<std::uint8_t, 3>> uniform = shown_ ? shown_() : std::nullopt;
  if (uniform) {  // the scene under the projector's one colour, as the colour camera sees it
    f.colour = colour_camera_->draw(twin_, T_world_camera, twin_.true_head().T_world_projector.matrix(),
                                    uniform_frame(twin_.scene().projector, *uniform));
  } else if (frame_ == 0 || colour_every_frame_ || (colour_wanted_ && colour_wanted_())) {
    f.colour = twin_.capture_colour(T_world_camera, static_cast<std::uint32_t>(seed_ * 7919 + visit_ * 1009 + frame_));
  }
  f.depth.capture_time_s = captured;
  f.depth_timestamp = f.colour_timestamp = frame_++;
  last_capture_ms_ = 1000.0 * (config::steady_now_s() - captured);
  return f;
}

}  // namespace projbot::twin
