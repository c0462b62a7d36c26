// The GLFW swapchain path, under Xvfb (ctest runs this suite through xvfb-run): what the X server shows
// in the window must be the offscreen image, before and after a resize.

#include <gtest/gtest.h>

#include "projbot/assets/model.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "x11_screenshot.hpp"

namespace fs = std::filesystem;
using projbot::assets::Image;

namespace {

const fs::path kData = fs::path(PROJBOT_SHARED_DATA) / "gltf";

// Pixels whose colour differs by more than 1 in any channel.
std::size_t differing(const Image& a, const Image& b) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.rgba.size(); i += 4)
    for (std::size_t c = 0; c < 3; ++c)
      if (std::abs(int(a.rgba[i + c]) - int(b.rgba[i + c])) > 1) {
        ++n;
        break;
      }
  return n;
}

}  // namespace

TEST(WindowTest, ScreenshotEqualsOffscreenImageBeforeAndAfterResize) {
  projbot::testing::X11Display display;
  ASSERT_TRUE(display.ok()) << "no X display: run this test under xvfb-run";

  projbot::engine::RendererOptions ro;
  ro.validation = true;
  ro.windowing = true;
  projbot::engine::Renderer renderer(ro);
  auto duck = projbot::assets::load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  projbot::assets::scale_and_recenter(duck, 0.25, true);
  auto box = projbot::assets::load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf");
  projbot::assets::scale_and_recenter(box, 0.15, true);
  const std::vector<projbot::engine::DrawItem> items{
      {renderer.add_model(duck), projbot::config::pose_from_xyz_rpy({-0.08, 0, 0.9}, {180, 0, 20})},
      {renderer.add_model(box), projbot::config::pose_from_xyz_rpy({0.15, 0.05, 0.8}, {200, 35, 0})}};
  projbot::config::ProjectorConfig p;
  p.width_px = 400, p.height_px = 300, p.fx_px = 420, p.fy_px = 400, p.cx_px = 190.5, p.cy_px = 160.0;

  projbot::engine::WindowOptions wo;
  wo.width_px = p.width_px;
  wo.height_px = p.height_px;
  auto window = renderer.make_window(wo);
  ASSERT_NE(window->native_window(), 0U);
  auto offscreen = renderer.make_offscreen(p.width_px, p.height_px);
  renderer.draw_frame(*offscreen, p, items);
  const Image expected = offscreen->read_back();

  for (int i = 0; i < 5; ++i) {
    window->poll_close();
    renderer.draw_frame(*window, p, items);
  }
  renderer.finish(*window);
  ASSERT_EQ(window->width(), p.width_px);
  const Image shot = display.screenshot(window->native_window(), p.width_px, p.height_px);
  ASSERT_EQ(shot.width, p.width_px);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < shot.rgba.size(); i += 4) lit += shot.rgba[i] ? 1 : 0;
  EXPECT_GT(lit, 5000U) << "the window shows the targets";
  EXPECT_LE(differing(shot, expected), 10U);

  // Resize from outside, as a window manager would: the swapchain is rebuilt and the projector image
  // stretched onto the new size, exactly as an offscreen target of that size shows it.
  display.resize(window->native_window(), 300, 200);
  bool skipped = false;
  for (int i = 0; i < 40 && window->width() != 300; ++i) {
    window->poll_close();
    skipped = !renderer.draw_frame(*window, p, items) || skipped;
  }
  ASSERT_EQ(window->width(), 300);
  ASSERT_EQ(window->height(), 200);
  EXPECT_TRUE(skipped) << "the frame during the rebuild is skipped";
  for (int i = 0; i < 5; ++i) {
    window->poll_close();
    EXPECT_TRUE(renderer.draw_frame(*window, p, items));
  }
  renderer.finish(*window);
  auto small = renderer.make_offscreen(300, 200);
  renderer.draw_frame(*small, p, items);
  EXPECT_LE(differing(display.screenshot(window->native_window(), 300, 200), small->read_back()), 10U);

  window.reset();
  EXPECT_EQ(renderer.validation_errors(), 0U);
  EXPECT_EQ(renderer.validation_warnings(), 0U);
}
