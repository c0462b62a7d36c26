// `projbot run --sim --fullscreen` under Xvfb: the live engine projects onto the twin's targets, and a
// screenshot of the screen shows them lit.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <string>
#include <thread>

#include "cli_fixture.hpp"
#include "projbot/alignment/freenect_source.hpp"
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

// A shell command run while the test takes screenshots: its exit code and output.
std::future<std::pair<int, std::string>> run_in_background(const std::string& cmd) {
  return std::async(std::launch::async, [cmd] {
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string out;
    std::array<char, 512> buf{};
    while (pipe != nullptr && fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
    const int status = pipe != nullptr ? pclose(pipe) : -1;
    return std::pair{WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
  });
}

TEST(RunWindowTest, FullscreenTwinRunLightsTheTargets) {
  projbot::testing::X11Display x11;
  ASSERT_TRUE(x11.ok()) << "no X display (run under xvfb-run)";
  const std::string cmd = std::string(PROJBOT_EXE) + " run --sim --fullscreen --visits 2 --dwell 4 --seconds 20 2>&1";
  auto run = run_in_background(cmd);
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

// `show` stopped by Ctrl-C two seconds after its window opened closes at the next frame, prints its
// summary and writes its per-frame profile, whole, with its output redirected: exit 130 within a second.
TEST(RunWindowTest, ShowInterruptedKeepsTheProfile) {
  projbot::testing::X11Display x11;
  ASSERT_TRUE(x11.ok()) << "no X display (run under xvfb-run)";
  const std::string csv = ::testing::TempDir() + "projbot_show_interrupted.csv";
  std::filesystem::remove(csv);
  cli_fixture::Background show({"show", "--profile", csv}, ::testing::TempDir() + "projbot_show_interrupted.log");
  ASSERT_GT(show.pid, 0);
  ASSERT_TRUE(show.wait_for_output("device: ", std::chrono::seconds(60))) << show.output();
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const auto [code, seconds] = show.signal_and_wait(SIGINT, std::chrono::seconds(30));
  const std::string output = show.output();
  EXPECT_EQ(code, 130) << output;
  EXPECT_LT(seconds, 1.0) << output;
  EXPECT_NE(output.find("frame time p50"), std::string::npos) << output;
  EXPECT_NE(output.find("per-frame profile written to " + csv), std::string::npos) << output;
  std::ifstream in(csv);
  int rows = -1;  // the header
  for (std::string line; std::getline(in, line);) ++rows;
  EXPECT_GT(rows, 5) << output;  // frames drawn over the seconds it was open
}

// A site whose camera is a Kinect v1 (libfreenect, played by fakenect from a dump of a grey wall: 600
// frames, 20 s at 30 Hz) and whose projector is a full-screen window: `dir`/site.yaml, the dump in
// `dir`/dump. The command line prefix that plays it.
std::string fakenect_site(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  fs::remove_all(dir);
  fs::create_directories(dir);
  projbot::alignment::DepthImage depth;
  depth.width = 640, depth.height = 480;
  depth.depth_m.assign(640 * 480, 1.5F);
  projbot::assets::Image colour;
  colour.width = 640, colour.height = 480;
  colour.rgba.assign(640 * 480 * 4, 128);
  projbot::alignment::write_fakenect_dump(dir / "dump", {{&depth, &colour, 10.0}, {&depth, &colour, 10.0 + 1.0 / 30.0}});
  std::string once;
  {
    std::ifstream in(dir / "dump" / "INDEX.txt");
    once.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  {
    std::ofstream out(dir / "dump" / "INDEX.txt");  // fakenect plays the list once
    for (int i = 0; i < 300; ++i) out << once;
  }
  std::ifstream shop(std::string(PROJBOT_ASSET_DIR) + "/scenes/shop.yaml");
  std::ostringstream text;
  text << shop.rdbuf();
  std::string yaml = text.str();
  for (std::size_t at = 0; (at = yaml.find("model: ../", at)) != std::string::npos; at += 7)
    yaml.insert(at + 7, std::string(PROJBOT_ASSET_DIR) + "/scenes/");
  std::ofstream(dir / "site.yaml") << yaml
                                   << "devices:\n  camera: {driver: freenect, registered: false}\n"
                                      "  projector: {monitor: 0, fullscreen: true}\n";
  return "env LD_LIBRARY_PATH=" PROJBOT_FAKENECT_DIR " FAKENECT_PATH=" + (dir / "dump").string() + " timeout 120 " +
         std::string(PROJBOT_EXE);
}

// `calibrate capture` on configured devices: a Kinect v1 (libfreenect, played by fakenect from a dump of a
// grey wall) and the projector window full screen on Xvfb. The person is asked to hold the board (Enter
// on stdin), the window shows the Gray-code patterns (a screenshot half white, half black: a stripe
// pattern), the camera's colour frames are taken, and the pose is refused on the spot (no board on a
// bare wall); q ends the session with nothing written.
TEST(RunWindowTest, CalibrateCaptureOnAKinectAndTheProjectorWindow) {
  namespace fs = std::filesystem;
  projbot::testing::X11Display x11;
  ASSERT_TRUE(x11.ok()) << "no X display (run under xvfb-run)";
  const fs::path dir = fs::temp_directory_path() / ("projbot_capture_window_" + std::to_string(::getpid()));
  const std::string projbot = fakenect_site(dir);
  std::ofstream(dir / "answers.txt") << "\nq\n";
  const std::string cmd = projbot + " calibrate capture --settle-ms 60 --config " + (dir / "site.yaml").string() + " --out " +
                          (dir / "cap").string() + " <" + (dir / "answers.txt").string() + " 2>&1";
  auto run = run_in_background(cmd);
  bool stripes = false;
  std::string shares;  // what the screenshots showed, for the message
  while (run.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
    if (!stripes) {
      const double share = lit_share(x11.screenshot(x11.root_window(), x11.screen_width(), x11.screen_height()));
      stripes = share > 0.3 && share < 0.7;
      shares += std::to_string(share).substr(0, 4) + " ";
    }
  const auto [code, output] = run.get();
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("opened camera: freenect #0"), std::string::npos) << output;
  EXPECT_NE(output.find("pose 1 of 10: hold the board in the projector's white light"), std::string::npos) << output;
  EXPECT_NE(output.find("pose 1 refused: no board found in the white image"), std::string::npos) << output;
  EXPECT_NE(output.find("no pose kept (1 refused); nothing written"), std::string::npos) << output;
  EXPECT_TRUE(stripes) << "no screenshot showed a stripe pattern; lit shares: " << shares;
  EXPECT_FALSE(fs::exists(dir / "cap"));
  fs::remove_all(dir);
}

// `calibrate photometric` on the same devices: the window shows black, then white full screen (a screenshot
// wholly lit), the camera's frames are taken after each, and since the dump's grey wall does not change
// with the projector's light the session stops there naming why; nothing is written.
TEST(RunWindowTest, CalibratePhotometricOnAKinectAndTheProjectorWindow) {
  namespace fs = std::filesystem;
  projbot::testing::X11Display x11;
  ASSERT_TRUE(x11.ok()) << "no X display (run under xvfb-run)";
  const fs::path dir = fs::temp_directory_path() / ("projbot_photometric_window_" + std::to_string(::getpid()));
  const std::string projbot = fakenect_site(dir);
  const std::string cmd = projbot + " calibrate photometric --settle-ms 300 --config " + (dir / "site.yaml").string() +
                          " --out " + (dir / "photo.yaml").string() + " 2>&1";
  auto run = run_in_background(cmd);
  double most = 0.0;
  while (run.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
    most = std::max(most, lit_share(x11.screenshot(x11.root_window(), x11.screen_width(), x11.screen_height())));
  const auto [code, output] = run.get();
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("opened camera: freenect #0"), std::string::npos) << output;
  EXPECT_NE(output.find("the camera's response is taken as gamma 2.20"), std::string::npos) << output;
  EXPECT_NE(output.find("camera: its exposure is not held (this libfreenect (fakenect?) cannot set the camera's flags)"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("the projector's light is not in the camera's view: under its white 0 pixels"), std::string::npos)
      << output;
  EXPECT_GT(most, 0.99) << "no screenshot showed the projector's white over the whole screen";
  EXPECT_FALSE(fs::exists(dir / "photo.yaml"));
  fs::remove_all(dir);
}

}  // namespace
