// OpenNI2 through the packaged drivers: the Dummy device (320x240 depth) live, recording it to .oni,
// and playing recordings back frame by frame through the packaged OniFile driver.
//
// Each test opens the Dummy device at most once: the packaged DummyDevice driver keeps a closed device's
// frame generator running, so a Dummy device reopened in the same process streams the frames of every
// earlier opening too (interleaved timestamp sequences: 33 363 66 396 ... ms), and a third opening
// can crash. ctest runs every test in its own process (gtest_discover_tests).

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <iterator>

#include "projbot/alignment/openni2_source.hpp"
#include "projbot/config/clock.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

TEST(OpenNi2Test, DummyDeviceStreamsDepth) {
  OpenNi2Source source({"Dummy", {}, 3000});
  EXPECT_FALSE(source.intrinsics().has_value());  // the Dummy device reports no field of view
  EXPECT_FALSE(source.has_colour());              // it has colour, but offers no registration to the depth
  EXPECT_EQ(source.recorded_frames(), -1);        // live
  double last = -1.0;
  for (int i = 0; i < 5; ++i) {
    const DepthImage d = source.next();
    ASSERT_EQ(d.width, 320);
    ASSERT_EQ(d.height, 240);
    EXPECT_GT(d.capture_time_s, last);  // timestamps advance
    last = d.capture_time_s;
    std::size_t valid = 0;
    for (float z : d.depth_m) {
      ASSERT_TRUE(std::isfinite(z));
      ASSERT_GE(z, 0.0F);
      valid += z > 0.0F ? 1 : 0;
    }
    EXPECT_GT(valid, 0U);
  }
}

// The Dummy device's colour, said to be registered (it has the depth's size): each depth frame comes with
// one, and both are stamped on the host's steady clock, no later than they were handed over.
TEST(OpenNi2Test, DummyDeviceDeliversColourOnTheHostClock) {
  OpenNi2Source source({"Dummy", {}, 3000, true});
  ASSERT_TRUE(source.has_colour());
  double last = -1.0;
  for (int i = 0; i < 5; ++i) {
    const RgbdFrame f = source.next_frame();
    const double now = projbot::config::steady_now_s();
    ASSERT_EQ(f.colour.width, 320);
    ASSERT_EQ(f.colour.height, 240);
    ASSERT_EQ(f.colour.rgba.size(), 320U * 240U * 4U);
    EXPECT_GT(f.colour.lit_pixels(), 0U);
    EXPECT_LE(f.depth.capture_time_s, now);
    EXPECT_GT(f.depth.capture_time_s, now - 0.5);
    EXPECT_GT(f.depth.capture_time_s, last);
    last = f.depth.capture_time_s;
  }
  // Its exposure cannot be held (the Dummy's colour has no camera controls), said and not thrown; frames go on.
  const projbot::alignment::ExposureHold hold = source.hold_colour_exposure();
  EXPECT_FALSE(hold.held);
  EXPECT_FALSE(hold.detail.empty());
  std::cout << "Dummy device: " << hold.detail << '\n';
  EXPECT_EQ(source.next_frame().colour.width, 320);
}

// The device's clock mapped to the host's: the fastest frame fixes the offset, a late one is stamped at
// its device time (earlier than its arrival), a device clock that restarts is mapped afresh.
TEST(DeviceClockTest, FastestFrameFixesTheOffset) {
  DeviceClock clock(0.0);
  // Device times every 33 ms from 5 s; the host's clock is 1000 s ahead, latencies 20, 8, 30, 8 ms.
  EXPECT_NEAR(clock.to_host(5.000, 1005.020), 1005.020, 1e-9);  // first: its arrival
  EXPECT_NEAR(clock.to_host(5.033, 1005.041), 1005.041, 1e-9);  // faster: the offset follows it
  EXPECT_NEAR(clock.to_host(5.066, 1005.096), 1005.074, 1e-9);  // 22 ms late: stamped 22 ms before arrival
  EXPECT_NEAR(clock.to_host(5.099, 1005.107), 1005.107, 1e-9);
  EXPECT_NEAR(clock.to_host(0.010, 2000.000), 2000.000, 1e-9);  // restarted (a reset, a replay from the start)
  DeviceClock drifting(1e-4);  // the offset may grow by 0.1 ms per device second: a slow device clock
  drifting.to_host(0.0, 100.0);
  EXPECT_NEAR(drifting.to_host(10.0, 110.5), 110.001, 1e-9);
}

namespace {

fs::path temp_oni(const std::string& tag) {
  return fs::temp_directory_path() / ("projbot_" + tag + "_" + std::to_string(::getpid()) + ".oni");
}

// Records `frames` live Dummy frames to `oni` and returns them.
std::vector<DepthImage> record_dummy(const fs::path& oni, int frames) {
  std::vector<DepthImage> live;
  OpenNi2Source source({"Dummy", oni, 3000});
  for (int i = 0; i < frames; ++i) live.push_back(source.next());
  return live;
}  // the recorder is finalised (and the cropping property added) when the source goes

std::size_t playback_count_and_check(const fs::path& oni, const std::vector<DepthImage>& live) {
  OpenNi2Source playback({oni.string(), {}, 3000, true});
  EXPECT_FALSE(playback.has_colour());  // a recording's colour is never paired with its depth
  const int n = playback.recorded_frames();
  // The recorder, attached after the stream started, may miss the first live frame.
  EXPECT_GE(n, static_cast<int>(live.size()) - 1);
  EXPECT_LE(n, static_cast<int>(live.size()));
  const std::size_t offset = live.size() - static_cast<std::size_t>(n);
  double first_time = 0.0;
  for (int k = 0; k < n; ++k) {
    const DepthImage frame = playback.next();  // stepped: called as fast as it likes, it gets every frame
    EXPECT_EQ(playback.frames_read(), k + 1);
    const DepthImage& original = live[offset + static_cast<std::size_t>(k)];
    EXPECT_EQ(frame.width, original.width);
    EXPECT_EQ(frame.height, original.height);
    EXPECT_EQ(frame.depth_m, original.depth_m) << "frame " << k << " decodes differently from what was recorded";
    if (k == 0) first_time = frame.capture_time_s;
    // Recorded times restart at 0 and keep the live spacing (the Dummy device: 33 ms).
    EXPECT_NEAR(frame.capture_time_s - first_time, original.capture_time_s - live[offset].capture_time_s, 1e-6);
  }
  try {
    playback.next();
    ADD_FAILURE() << "a frame after the end of the recording";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("end of the recording"), std::string::npos) << e.what();
  }
  return static_cast<std::size_t>(n);
}

}  // namespace

TEST(OpenNi2Test, RecordingPlaysBackFrameByFrame) {
  const fs::path oni = temp_oni("dummy");
  const std::vector<DepthImage> live = record_dummy(oni, 10);
  ASSERT_TRUE(fs::exists(oni));
  EXPECT_GT(fs::file_size(oni), 10000U);
  // The Dummy device's stream has no cropping, so OpenNI2's recorder left the property out and the
  // packaged player would drop every frame; the source added it when the recording was finalised.
  EXPECT_TRUE(oni_declares_cropping(oni));
  EXPECT_FALSE(add_oni_cropping_property(oni));  // nothing missing any more
  EXPECT_GE(playback_count_and_check(oni, live), 9U);
  fs::remove(oni);
}

TEST(OpenNi2Test, RecordingWithoutCroppingPlaysFromARepairedCopy) {
  const fs::path oni = temp_oni("uncropped");
  const std::vector<DepthImage> live = record_dummy(oni, 6);
  // Make it what OpenNI2's recorder writes for the Dummy device: no xnCropping property (renamed to a
  // name the player ignores, keeping every file position).
  std::string bytes;
  {
    std::ifstream in(oni, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::size_t at = bytes.find("xnCropping");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 9] = 'X';
  std::ofstream(oni, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_FALSE(oni_declares_cropping(oni));
  EXPECT_GE(playback_count_and_check(oni, live), 5U);
  EXPECT_FALSE(oni_declares_cropping(oni));  // the user's file is left as it was
  for (const auto& entry : fs::directory_iterator(fs::temp_directory_path()))
    EXPECT_EQ(entry.path().filename().string().rfind("projbot_playback_" + std::to_string(::getpid()) + "_", 0),
              std::string::npos)
        << "temporary copy left behind: " << entry.path();
  fs::remove(oni);
}

TEST(OpenNi2Test, MalformedRecordingsAreNamed) {
  const fs::path not_oni = temp_oni("not");
  std::ofstream(not_oni) << "this is not a recording";
  for (const auto& call :
       {+[](const fs::path& p) { oni_declares_cropping(p); }, +[](const fs::path& p) { add_oni_cropping_property(p); }}) {
    try {
      call(not_oni);
      ADD_FAILURE() << "no error";
    } catch (const AlignmentError& e) {
      EXPECT_NE(std::string(e.what()).find(not_oni.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("NI10"), std::string::npos) << e.what();
    }
  }
  // A recording cut short: named, with where it ends.
  const fs::path cut = temp_oni("cut");
  record_dummy(cut, 3);
  fs::resize_file(cut, fs::file_size(cut) / 2);
  try {
    OpenNi2Source({cut.string(), {}, 500});
    ADD_FAILURE() << "no error";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find(cut.string()), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("projbot_playback_"), std::string::npos) << "names our temporary copy: " << e.what();
  }
  fs::remove(not_oni);
  fs::remove(cut);
}

TEST(OpenNi2Test, BadUrisAreNamed) {
  try {
    OpenNi2Source({"/nonexistent/recording.oni", {}, 100});
    FAIL() << "no error";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/recording.oni"), std::string::npos) << e.what();
  }
  try {
    OpenNi2Source({"no-such-device://42", {}, 100});
    FAIL() << "no error";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-device://42"), std::string::npos) << e.what();
  }
}
