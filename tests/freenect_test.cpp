// The Kinect v1 driver (libfreenect) on the twin's frames, played by libfreenect's own fakenect
// (issue 12, item 5). ctest runs this suite with the fakenect library first on LD_LIBRARY_PATH, so the
// driver's calls go through the real libfreenect API into fakenect's player.

#include <dlfcn.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "device_fixtures.hpp"
#include "projbot/alignment/freenect_source.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/twin/world.hpp"

namespace {

namespace fs = std::filesystem;
using projbot::alignment::kinect_metres_to_raw;
using projbot::alignment::kinect_raw_to_metres;

// The library that answers libfreenect's calls in this process.
std::string freenect_library() {
  void* symbol = dlsym(RTLD_DEFAULT, "freenect_init");
  Dl_info info{};
  if (symbol == nullptr || dladdr(symbol, &info) == 0 || info.dli_fname == nullptr) return "";
  return info.dli_fname;
}

// The most a depth z moves when its disparity is rounded to the nearest raw step (half a step of
// 0.0030711016 in 1/z, the far side's half being the larger): the quantisation a Kinect v1 depth carries.
double half_step_m(double z) { return 0.5 * 0.0030711016 * z * z / (1.0 - 0.5 * 0.0030711016 * z); }

}  // namespace

TEST(KinectRaw, RoundTripsWithinHalfADisparityStep) {
  for (float z = 0.5F; z <= 4.5F; z += 0.01F) {
    const std::uint16_t raw = kinect_metres_to_raw(z);
    ASSERT_LT(raw, 2047) << z;
    EXPECT_NEAR(kinect_raw_to_metres(raw), z, half_step_m(z) + 1e-5) << z;
  }
  EXPECT_EQ(kinect_metres_to_raw(0.0F), 2047);
  EXPECT_EQ(kinect_metres_to_raw(std::nanf("")), 2047);
  EXPECT_EQ(kinect_metres_to_raw(0.1F), 2047);  // closer than the sensor sees
  EXPECT_EQ(kinect_raw_to_metres(2047), 0.0F);
  EXPECT_NEAR(kinect_raw_to_metres(0), 0.3002F, 1e-4F);  // the nearest depth the fit gives
  EXPECT_NEAR(kinect_raw_to_metres(kinect_metres_to_raw(1.0F)), 1.0F, 0.002F);
}

// Three of the twin's frames at the shop's Duck stop, written as a fakenect dump and read back through
// FreenectSource: the same depth within the sensor's disparity steps, the same colour, in order, then
// the end of the dump is an error naming the Kinect.
TEST(FreenectSource, PlaysTheTwinsFramesThroughFakenect) {
  ASSERT_NE(freenect_library().find("fakenect"), std::string::npos)
      << "run by ctest, which puts libfreenect's fakenect first; this process uses " << freenect_library();
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const auto arrival = twin.arrive(twin.target_index("duck"), 0);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const TwinFrames captured = twin_frames(twin, T_world_camera, 3, 11, 100.0);
  const auto& depths = captured.depths;
  const auto& colours = captured.colours;
  const auto frames = captured.frames();
  const fs::path dump = fs::temp_directory_path() / ("projbot_fakenect_" + std::to_string(::getpid()));
  fs::remove_all(dump);
  projbot::alignment::write_fakenect_dump(dump, frames);
  EXPECT_THROW(projbot::alignment::write_fakenect_dump(dump, frames), projbot::alignment::AlignmentError);  // not empty

  ::setenv("FAKENECT_PATH", dump.c_str(), 1);
  ::setenv("FAKENECT_LOOP", "0", 1);  // the end of the dump ends the stream
  // Registered depth from fakenect would abort inside it (it asserts raw 11-bit): refused first, named.
  try {
    projbot::alignment::FreenectSource registered({0, /*registered=*/true, 2000});
    ADD_FAILURE() << "registered depth from fakenect";
  } catch (const projbot::alignment::AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("is fakenect (playing a recorded dump), which plays raw depth only"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(projbot::alignment::FreenectSource::count_devices(), 1);
  projbot::alignment::FreenectSource source({0, /*registered=*/false, 2000});
  for (std::size_t k = 0; k < 3; ++k) {
    const auto frame = source.next();
    ASSERT_EQ(frame.depth.width, 640);
    ASSERT_EQ(frame.depth.height, 480);
    EXPECT_EQ(frame.depth_timestamp, k * 1000000U);
    std::size_t valid = 0, both = 0, worse = 0;
    for (std::size_t i = 0; i < frame.depth.depth_m.size(); ++i) {
      const float z = depths[k].depth_m[i];
      const bool in_range = z >= 0.3F && z <= 10.0F;
      valid += in_range ? 1 : 0;
      if (!in_range || frame.depth.depth_m[i] <= 0.0F) continue;
      ++both;
      worse += std::abs(frame.depth.depth_m[i] - z) > half_step_m(z) + 1e-4 ? 1 : 0;
    }
    EXPECT_GT(valid, 100000U);
    EXPECT_EQ(both, valid) << "frame " << k;  // every pixel the twin measured comes back measured
    EXPECT_EQ(worse, 0U) << "frame " << k;
    ASSERT_EQ(frame.colour.rgba.size(), colours[k].rgba.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < frame.colour.rgba.size(); i += 4)
      for (int c = 0; c < 3; ++c) differ += frame.colour.rgba[i + c] != colours[k].rgba[i + c] ? 1 : 0;
    EXPECT_EQ(differ, 0U) << "frame " << k;
  }
  EXPECT_EQ(source.frames_read(), 3);
  try {
    source.next();
    ADD_FAILURE() << "a fourth frame from a three-frame dump";
  } catch (const projbot::alignment::AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("Kinect v1 #0 (libfreenect): stopped delivering frames"), std::string::npos) << e.what();
  }
  fs::remove_all(dump);
}

// The replay's camera (issue 12): a dump read back without libfreenect gives depth as the Kinect driver
// converts it (exactly what kinect_quantised() makes of the original) and the colour byte for byte, stamped
// with the recorded gaps; its end and a malformed index are named.
TEST(FakenectDumpReader, ReadsBackWhatTheWriterWrote) {
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const auto arrival = twin.arrive(twin.target_index("duck"), 0);
  const TwinFrames captured = twin_frames(twin, arrival.truth.T_world_camera.matrix(), 2, 5, 10.0);
  const fs::path dump = fs::temp_directory_path() / ("projbot_dump_reader_" + std::to_string(::getpid()));
  fs::remove_all(dump);
  projbot::alignment::write_fakenect_dump(dump, captured.frames());
  projbot::alignment::FakenectDumpReader reader(dump, false);
  ASSERT_EQ(reader.frames(), 2);
  double first_s = 0.0;
  for (std::size_t k = 0; k < 2; ++k) {
    const auto f = reader.next();
    EXPECT_EQ(f.depth.depth_m, projbot::alignment::kinect_quantised(captured.depths[k]).depth_m) << "frame " << k;
    ASSERT_EQ(f.colour.rgba.size(), captured.colours[k].rgba.size());
    EXPECT_EQ(f.colour.rgba, captured.colours[k].rgba) << "frame " << k;  // the twin's alpha is 255, as read back
    if (k == 0) first_s = f.depth.capture_time_s;
    EXPECT_NEAR(f.depth.capture_time_s - first_s, static_cast<double>(k) / 30.0, 2e-6);
    EXPECT_EQ(f.depth_timestamp, static_cast<std::uint32_t>(k) * 1000000U);
  }
  try {
    reader.next();
    ADD_FAILURE() << "a frame after the end";
  } catch (const projbot::alignment::AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("the recording ends after 2 frames"), std::string::npos) << e.what();
  }
  std::ofstream(dump / "INDEX.txt", std::ios::app) << "d-garbage.pgm\n";
  try {
    projbot::alignment::FakenectDumpReader bad(dump, false);
    ADD_FAILURE() << "a malformed index read";
  } catch (const projbot::alignment::AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("INDEX.txt:5: 'd-garbage.pgm' is not a fakenect frame name"), std::string::npos)
        << e.what();
  }
  fs::remove_all(dump);
}
