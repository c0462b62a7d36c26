// OpenNI2 through the packaged drivers: the Dummy device (320x240 depth) live, recording it to .oni,
// and what the packaged OniFile driver does when that recording is played back.

#include <gtest/gtest.h>

#include "projbot/alignment/openni2_source.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

TEST(OpenNi2Test, DummyDeviceStreamsDepth) {
  OpenNi2Source source({"Dummy", {}, 3000});
  EXPECT_FALSE(source.intrinsics().has_value());  // the Dummy device reports no field of view
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

TEST(OpenNi2Test, RecordingAndWhatPlaybackDoes) {
  const fs::path oni = fs::temp_directory_path() / ("projbot_dummy_" + std::to_string(::getpid()) + ".oni");
  {
    OpenNi2Source live({"Dummy", oni, 3000});
    for (int i = 0; i < 10; ++i) live.next();
  }  // the recorder is finalised here
  ASSERT_TRUE(fs::exists(oni));
  EXPECT_GT(fs::file_size(oni), 10000U);
  OpenNi2Source playback({oni.string(), {}, 1500});
  // The file holds the frames (the recorder, attached after the stream started, may miss the first)...
  EXPECT_GE(playback.recorded_frames(), 9);
  // ...but the packaged OniFile driver (2.2.0.33) delivers none of them: waitForAnyStream times out. This
  // pins that behaviour; when it changes, replace this with a frame-by-frame playback test.
  try {
    playback.next();
    ADD_FAILURE() << "playback delivered a frame: the packaged OpenNI2 now plays this recording";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("playback of this recording delivers no frames"), std::string::npos) << e.what();
  }
  fs::remove(oni);
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
