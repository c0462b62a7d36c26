// `projbot run --sim --fullscreen` under Xvfb: the live engine projects onto the twin's targets, and a
// screenshot of the screen shows them lit.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <future>
#include <string>
#include <thread>

#include "x11_screenshot.hpp"

namespace {

double lit_share(const projbot::assets::Image& image) {
  if (image.width == 0) return 0.0;
  std::size_t lit = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const auto* p = image.pixel(x, y);
      lit += p[0] + p[1] + p[2] > 60 ? 1 : 0;
    }
  return static_cast<double>(lit) / (static_cast<double>(image.width) * image.height);
}

TEST(RunWindowTest, FullscreenTwinRunLightsTheTargets) {
  projbot::testing::X11Display x11;
  ASSERT_TRUE(x11.ok()) << "no X display (run under xvfb-run)";
  const std::string cmd = std::string(PROJBOT_EXE) + " run --sim --fullscreen --visits 2 --dwell 4 --seconds 20 2>&1";
  auto run = std::async(std::launch::async, [&] {
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string out;
    std::array<char, 512> buf{};
    while (pipe != nullptr && fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
    const int status = pipe != nullptr ? pclose(pipe) : -1;
    return std::pair{WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  });
  // Screenshots every 100 ms while it runs: before the first stop the screen is black, then a target is lit.
  double best = 0.0;
  projbot::assets::Image best_image;
  while (run.wait_for(std::chrono::milliseconds(100)) != std::future_status::ready) {
    const auto shot = x11.screenshot(x11.root_window(), x11.screen_width(), x11.screen_height());
    const double share = lit_share(shot);
    if (share > best) best = share, best_image = shot;
  }
  const auto [code, output] = run.get();
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("pose age at display"), std::string::npos) << output;
  EXPECT_NE(output.find("robot: 2 visit(s)"), std::string::npos) << output;
  // A lit target covers a few percent of the 1600x1200 screen, never all of it.
  EXPECT_GT(best, 0.005) << output;
  EXPECT_LT(best, 0.6);
  if (best_image.width > 0) projbot::assets::write_png(::testing::TempDir() + "run_window.png", best_image);
}

}  // namespace
