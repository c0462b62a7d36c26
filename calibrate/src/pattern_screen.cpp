#include "projbot/calibrate/pattern_screen.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "projbot/calibrate/procam.hpp"
#include "projbot/config/clock.hpp"

namespace projbot::calibrate {
namespace {

// A quad at 1 m whose corners are the projector image's outer pixel edges, textured with `image`
// (nearest sampling: a pattern's pixels are the panel's own).
assets::Model screen_quad(const config::ProjectorConfig& p, assets::Image image, const std::string& source) {
  assets::Model m;
  m.source = source;
  m.images.push_back(std::move(image));
  assets::Material mat;
  mat.base_color_image = 0;
  mat.double_sided = true;
  mat.sampler = {assets::Wrap::kClampToEdge, assets::Wrap::kClampToEdge, assets::Filter::kNearest, assets::Filter::kNearest};
  m.materials.push_back(mat);
  assets::Primitive q;
  const double u[2] = {-0.5, p.width_px - 0.5}, v[2] = {-0.5, p.height_px - 0.5};
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      assets::Vertex vx;
      const Eigen::Vector3d ray = p.back_project(u[i], v[j], 1.0);
      vx.position = {static_cast<float>(ray.x()), static_cast<float>(ray.y()), 1.0F};
      vx.uv = {static_cast<float>(i), static_cast<float>(j)};
      q.vertices.push_back(vx);
    }
  q.indices = {0, 1, 3, 0, 3, 2};
  m.primitives.push_back(std::move(q));
  return m;
}

assets::Model pattern_quad(const config::ProjectorConfig& p, const cv::Mat& pattern) {
  assets::Image img;
  img.width = pattern.cols;
  img.height = pattern.rows;
  img.rgba.resize(static_cast<std::size_t>(img.width) * img.height * 4);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      std::uint8_t* px = img.pixel(x, y);
      px[0] = px[1] = px[2] = pattern.at<std::uint8_t>(y, x);
      px[3] = 255;
    }
  return screen_quad(p, std::move(img), "gray-code pattern");
}

// Shows what `draw` draws into the projector's window until it is on screen: drawn twice, so that both
// swapchain images hold it.
void present(engine::Renderer& renderer, engine::RenderTarget& window, const std::function<void()>& draw) {
  for (int k = 0; k < 2; ++k) draw();
  renderer.finish(window);
  window.poll_close();
}

// The first colour frame `camera` took at least `lag_s` after `shown_s` (host steady clock); frames taken
// before the light changed are dropped.
assets::Image colour_after(alignment::RgbdCamera& camera, double shown_s, double lag_s, const std::string& command) {
  for (int tries = 0; tries < 100; ++tries) {
    alignment::RgbdFrame f = camera.next();
    if (f.colour.rgba.empty())
      throw CalibrationError("the configured camera delivers no colour image; " + command + " needs one");
    if (f.depth.capture_time_s >= shown_s + lag_s) return std::move(f.colour);
  }
  throw CalibrationError(
      "the camera delivered 100 frames all taken before the pattern was shown: are its "
      "timestamps on the host's steady clock?");
}

// Luma of an RGBA camera image (Rec. 601 weights, as OpenCV's RGB2GRAY).
cv::Mat grey_of(const assets::Image& colour) {
  cv::Mat out(colour.height, colour.width, CV_8UC1);
  for (int y = 0; y < colour.height; ++y)
    for (int x = 0; x < colour.width; ++x) {
      const std::uint8_t* c = colour.pixel(x, y);
      out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::lround(0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2]));
    }
  return out;
}

class DeviceRig final : public CaptureRig {
 public:
  DeviceRig(PatternScreen& screen, engine::Renderer& renderer, engine::RenderTarget& window, alignment::RgbdCamera& camera,
            double settle_ms, double lag_ms, std::istream& answers, std::ostream& prompt)
      : screen_(screen),
        renderer_(renderer),
        window_(window),
        camera_(camera),
        settle_s_(settle_ms / 1000.0),
        lag_s_(lag_ms / 1000.0),
        answers_(answers),
        prompt_(prompt) {}

  bool ready(int pose, int poses) override {
    show(screen_.white_index());
    prompt_ << "pose " << pose << " of " << poses
            << ": hold the board in the projector's white light, wholly in the camera's view, and press Enter (q and "
               "Enter: finish with the poses kept)"
            << std::endl;
    std::string line;
    if (!std::getline(answers_, line)) return false;
    return line != "q" && line != "Q";
  }

  cv::Mat show_and_capture(std::size_t index, const cv::Mat& /*pattern*/) override {
    show(index);
    const double shown = config::steady_now_s();
    std::this_thread::sleep_for(std::chrono::duration<double>(settle_s_ + lag_s_));
    return grey_of(colour_after(camera_, shown, lag_s_, "calibrate capture"));
  }

 private:
  void show(std::size_t index) {
    present(renderer_, window_, [&] { screen_.draw(window_, index); });
  }

  PatternScreen& screen_;
  engine::Renderer& renderer_;
  engine::RenderTarget& window_;
  alignment::RgbdCamera& camera_;
  double settle_s_, lag_s_;
  std::istream& answers_;
  std::ostream& prompt_;
};

// The photometric rig on the projector window and the configured camera (make_device_photometric_rig).
class DevicePhotometricRig final : public PhotometricRig {
 public:
  DevicePhotometricRig(ColourScreen& screen, engine::Renderer& renderer, engine::RenderTarget& window,
                       alignment::RgbdCamera& camera, double settle_ms, double lag_ms, std::function<bool()> stop)
      : screen_(screen),
        renderer_(renderer),
        window_(window),
        camera_(camera),
        settle_s_(settle_ms / 1000.0),
        lag_s_(lag_ms / 1000.0),
        stop_(std::move(stop)) {}

  bool brackets() const override { return false; }

  Eigen::Vector3d show_and_measure(const Eigen::Vector3d& input, double /*exposure*/) override {
    if (patch_.empty()) locate();
    const assets::Image image = take(input);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const std::size_t i : patch_)
      for (int ch = 0; ch < 3; ++ch) sum[ch] += image.rgba[4 * i + ch];
    return sum / static_cast<double>(patch_.size());
  }

 private:
  // The camera's image once `input` has been on the projector for the settling time.
  assets::Image take(const Eigen::Vector3d& input) {
    std::array<std::uint8_t, 3> rgb{};
    for (int ch = 0; ch < 3; ++ch) rgb[ch] = static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(input[ch], 0.0, 1.0)));
    present(renderer_, window_, [&] { screen_.draw(window_, rgb); });
    const double shown = config::steady_now_s();
    for (double left = settle_s_ + lag_s_; left > 0.0; left -= 0.05) {  // settling, stopped within 50 ms
      if (stop_ && stop_()) throw SessionStopped("while measuring the projector's colours");
      std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, 0.05)));
    }
    if (stop_ && stop_()) throw SessionStopped("while measuring the projector's colours");
    assets::Image image = colour_after(camera_, shown, lag_s_, "calibrate photometric");
    if (size_ != 0 && image.rgba.size() != size_)
      throw CalibrationError("the camera's colour images changed size during the session");
    size_ = image.rgba.size();
    return image;
  }

  // The pixels the projector lights: under white at least half as much brighter than under black as the
  // most lit ones (their 99th percentile).
  void locate() {
    const assets::Image black = take(Eigen::Vector3d::Zero()), white = take(Eigen::Vector3d::Ones());
    std::vector<double> rise(black.rgba.size() / 4);
    for (std::size_t i = 0; i < rise.size(); ++i)
      for (int ch = 0; ch < 3; ++ch) rise[i] += (static_cast<double>(white.rgba[4 * i + ch]) - black.rgba[4 * i + ch]) / 3.0;
    std::vector<double> sorted = rise;
    const auto p99 = sorted.begin() + static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), p99, sorted.end());
    const double threshold = std::max(0.5 * *p99, 10.0);
    for (std::size_t i = 0; i < rise.size(); ++i)
      if (rise[i] >= threshold) patch_.push_back(i);
    if (patch_.size() < kMinPixels) {
      char text[240];
      std::snprintf(text, sizeof text,
                    "the projector's light is not in the camera's view: under its white %zu pixels were at least %.0f "
                    "levels brighter than under its black (the most lit 1 %% rose %.0f; %zu needed)",
                    patch_.size(), threshold, *p99, kMinPixels);
      patch_.clear();
      throw CalibrationError(text);
    }
  }

  static constexpr std::size_t kMinPixels = 100;
  ColourScreen& screen_;
  engine::Renderer& renderer_;
  engine::RenderTarget& window_;
  alignment::RgbdCamera& camera_;
  double settle_s_, lag_s_;
  std::function<bool()> stop_;
  std::vector<std::size_t> patch_;  // indices of the pixels the projector lights
  std::size_t size_ = 0;
};

}  // namespace

PatternScreen::PatternScreen(engine::Renderer& renderer, const config::ProjectorConfig& projector)
    : renderer_(renderer), pinhole_(projector) {
  pinhole_.distortion = {};
  pinhole_.near_m = 0.1;
  pinhole_.far_m = 10.0;
  for (const cv::Mat& pattern : gray_code_images(projector.width_px, projector.height_px))
    models_.push_back(renderer_.add_model(pattern_quad(pinhole_, pattern)));
}

void PatternScreen::draw(engine::RenderTarget& target, std::size_t index) {
  const std::vector<engine::DrawItem> items{{models_.at(index), Eigen::Matrix4d::Identity()}};
  renderer_.draw_frame(target, pinhole_, items);
}

cv::Mat PatternScreen::render(std::size_t index) {
  if (!offscreen_) offscreen_ = renderer_.make_offscreen(pinhole_.width_px, pinhole_.height_px);
  draw(*offscreen_, index);
  const assets::Image img = offscreen_->read_back();
  cv::Mat out(img.height, img.width, CV_8UC1);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) out.at<std::uint8_t>(y, x) = img.pixel(x, y)[0];
  return out;
}

PatternDisplay engine_display(PatternScreen& screen) {
  return [&screen](std::size_t index, const cv::Mat& pattern) {
    cv::Mat shown = screen.render(index);
    const int differ = cv::countNonZero(shown != pattern);
    if (differ != 0)
      throw CalibrationError("the engine drew pattern " + std::to_string(index) + " with " + std::to_string(differ) +
                             " pixels unlike the pattern's");
    return shown;
  };
}

std::unique_ptr<CaptureRig> make_device_rig(PatternScreen& screen, engine::Renderer& renderer, engine::RenderTarget& window,
                                            alignment::RgbdCamera& camera, double settle_ms, double input_lag_ms,
                                            std::istream& answers, std::ostream& prompt) {
  return std::make_unique<DeviceRig>(screen, renderer, window, camera, settle_ms, input_lag_ms, answers, prompt);
}

ColourScreen::ColourScreen(engine::Renderer& renderer, const config::ProjectorConfig& projector)
    : renderer_(renderer), pinhole_(projector) {
  pinhole_.distortion = {};
  pinhole_.near_m = 0.1;
  pinhole_.far_m = 10.0;
}

void ColourScreen::draw(engine::RenderTarget& target, const std::array<std::uint8_t, 3>& rgb) {
  auto it = models_.find(rgb);
  if (it == models_.end()) {
    assets::Image texel;
    texel.width = texel.height = 1;
    texel.rgba = {rgb[0], rgb[1], rgb[2], 255};
    it = models_.emplace(rgb, renderer_.add_model(screen_quad(pinhole_, std::move(texel), "photometric colour"))).first;
  }
  const std::vector<engine::DrawItem> items{{it->second, Eigen::Matrix4d::Identity()}};
  renderer_.draw_frame(target, pinhole_, items);
}

std::unique_ptr<PhotometricRig> make_device_photometric_rig(ColourScreen& screen, engine::Renderer& renderer,
                                                            engine::RenderTarget& window, alignment::RgbdCamera& camera,
                                                            double settle_ms, double input_lag_ms, std::function<bool()> stop) {
  return std::make_unique<DevicePhotometricRig>(screen, renderer, window, camera, settle_ms, input_lag_ms, std::move(stop));
}

}  // namespace projbot::calibrate
