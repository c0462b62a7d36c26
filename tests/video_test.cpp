// Video content (issue 44): clips written at test time with FFmpeg's libraries, whose frames show their
// own number; the decoder, the player against a content clock, and bad files.
#include "projbot/assets/video.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include "temp_dir.hpp"

namespace fs = std::filesystem;
using namespace projbot::assets;

namespace {

// One folder for the whole process: a test's clips stay while it runs.
const fs::path& temp_dir() {
  static const fs::path dir = test_support::temp_dir("video_test");
  return dir;
}

fs::path write_clip(const std::string& name, int frames, int width = 320, int height = 240, int fps = 30,
                    const std::string& codec = "libx264") {
  const fs::path path = temp_dir() / name;
  VideoWriter writer(path, width, height, fps, codec);
  for (int i = 0; i < frames; ++i) writer.write(frame_code_image(i, width, height));
  writer.finish();
  return path;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const AssetError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(FrameCode, ReadsBackWhatItDrew) {
  for (std::int64_t i : {0, 1, 77, 512, 1023}) {
    const Image img = frame_code_image(i, 200, 100);
    EXPECT_EQ(read_frame_code(img, 0, 0, 200, 100), i);
  }
  Image grey = frame_code_image(5, 200, 100);
  for (auto& b : grey.rgba) b = 128;
  EXPECT_EQ(read_frame_code(grey, 0, 0, 200, 100), -1);
}

TEST(VideoDecoder, H264ClipDecodesEveryFrameInOrderWithItsTime) {
  const fs::path clip = write_clip("count.mp4", 45);
  VideoDecoder d(clip);
  EXPECT_EQ(d.info().width, 320);
  EXPECT_EQ(d.info().height, 240);
  EXPECT_NEAR(d.info().fps, 30.0, 1e-6);
  EXPECT_EQ(d.info().codec, "h264");
  VideoFrame f;
  for (int i = 0; i < 45; ++i) {
    ASSERT_TRUE(d.next(f)) << i;
    EXPECT_EQ(f.index, i);
    EXPECT_NEAR(f.pts_s, i / 30.0, 1e-3);
    EXPECT_NEAR(f.duration_s, 1 / 30.0, 1e-3);
    EXPECT_EQ(read_frame_code(f.image, 0, 0, 320, 240), i);
  }
  EXPECT_FALSE(d.next(f));
  d.rewind();
  ASSERT_TRUE(d.next(f));
  EXPECT_EQ(read_frame_code(f.image, 0, 0, 320, 240), 0);
  EXPECT_NEAR(f.pts_s, 0.0, 1e-6);
}

// MPEG-TS (issue 72): its timestamp seek back to the first frame landed on the next key frame, one second
// in, so content time 0 drew nothing; it now goes back by byte and decodes up to a seek's time.
TEST(VideoDecoder, MpegTsClipStartsAtItsFirstFrameAfterARewindAndASeek) {
  const fs::path clip = write_clip("count.ts", 45);
  VideoDecoder d(clip);
  VideoFrame f;
  for (int pass = 0; pass < 2; ++pass) {
    ASSERT_TRUE(d.next(f)) << pass;
    EXPECT_EQ(read_frame_code(f.image, 0, 0, 320, 240), 0) << pass;
    EXPECT_NEAR(f.pts_s, 0.0, 1e-6) << pass;
    d.rewind();
  }
  d.seek(1.2);
  ASSERT_TRUE(d.next(f));
  EXPECT_EQ(read_frame_code(f.image, 0, 0, 320, 240), 36);
  EXPECT_NEAR(f.pts_s, 1.2, 1e-3);
}

// A stream whose frame size changes (two TS clips joined) is refused at the same frame every time, naming both
// sizes: never drawn at one size one run and another the next.
TEST(VideoDecoder, AFrameSizeChangeMidStreamIsRefusedAtTheSameFrameEveryTime) {
  const fs::path big = write_clip("big.ts", 20), small = write_clip("small.ts", 10, 160, 120);
  const fs::path joined = temp_dir() / "joined.ts";
  {
    std::ofstream out(joined, std::ios::binary);
    out << std::ifstream(big, std::ios::binary).rdbuf() << std::ifstream(small, std::ios::binary).rdbuf();
  }
  for (int run = 0; run < 2; ++run) {
    VideoDecoder d(joined);
    VideoFrame f;
    int shown = 0;
    const std::string e = error_of([&] {
      while (d.next(f)) ++shown;
    });
    EXPECT_EQ(shown, 20) << run;
    EXPECT_NE(e.find("joined.ts: its frames change size mid-stream (320x240 to 160x120)"), std::string::npos) << e;
  }
}

TEST(VideoDecoder, LosslessClipIsExact) {
  const fs::path clip = write_clip("count.mkv", 3, 64, 48, 25, "ffv1");
  VideoDecoder d(clip);
  VideoFrame f;
  ASSERT_TRUE(d.next(f));
  ASSERT_TRUE(d.next(f));
  EXPECT_EQ(f.image.rgba, frame_code_image(1, 64, 48).rgba);
}

TEST(VideoDecoder, BadFilesAreOneLineNamingTheFile) {
  const fs::path good = write_clip("good.mp4", 30);
  const fs::path missing = temp_dir() / "missing.mp4";
  EXPECT_NE(error_of([&] { VideoDecoder d(missing); }).find("missing.mp4: does not exist"), std::string::npos);
  EXPECT_NE(error_of([&] { VideoDecoder d(temp_dir()); }).find("not a regular file"), std::string::npos);

  const fs::path text = temp_dir() / "text.mp4";
  std::ofstream(text) << "this is not a video\n";
  EXPECT_NE(error_of([&] { VideoDecoder d(text); }).find("text.mp4: not a video FFmpeg can read"), std::string::npos);

  std::ifstream in(good, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const fs::path truncated = temp_dir() / "truncated.mp4";  // mp4 keeps its index last: cut, it has none
  std::ofstream(truncated, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  const std::string e = error_of([&] { VideoDecoder d(truncated); });
  EXPECT_NE(e.find("truncated.mp4: "), std::string::npos) << e;

  const fs::path y4m = temp_dir() / "huge.y4m";  // FFmpeg refuses it with EBUSY's words; its log says why
  std::ofstream(y4m, std::ios::binary) << "YUV4MPEG2 W20000 H20000 F30:1 Ip A1:1 C420jpeg\nFRAME\n" << std::string(1000, '\0');
  EXPECT_NE(error_of([&] { VideoDecoder d(y4m); })
                .find("huge.y4m: not a video FFmpeg can read (Picture size 20000x20000 is invalid; this player takes at most "
                      "8192 px a side"),
            std::string::npos)
      << error_of([&] { VideoDecoder d(y4m); });
  const fs::path huge = write_clip("huge.mkv", 1, 8200, 16, 25, "ffv1");
  EXPECT_NE(error_of([&] { VideoDecoder d(huge); }).find("is 8200x16, more than"), std::string::npos);
  const fs::path empty = temp_dir() / "empty.mkv";
  {
    VideoWriter w(empty, 64, 48, 25, "ffv1");
    w.finish();
  }
  EXPECT_NE(error_of([&] { VideoDecoder d(empty); }).find("empty.mkv: "), std::string::npos);
}

TEST(VideoDecoder, FromMemoryAsFromAFile) {
  const fs::path clip = write_clip("memory.mp4", 10);
  std::ifstream in(clip, std::ios::binary);
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  VideoDecoder d(bytes, "memory.mp4");
  VideoFrame f;
  for (int i = 0; i < 10; ++i) {
    ASSERT_TRUE(d.next(f));
    EXPECT_EQ(read_frame_code(f.image, 0, 0, 320, 240), i);
  }
  EXPECT_NE(error_of([] { VideoDecoder noise(std::vector<std::uint8_t>(100, 7), "noise"); }).find("noise: "), std::string::npos);
}

TEST(VideoWriter, AbandonedWriteLeavesNoFile) {
  const fs::path path = temp_dir() / "abandoned.mp4";
  {
    VideoWriter w(path, 64, 48, 30);
    w.write(frame_code_image(0, 64, 48));
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(temp_dir() / "abandoned.mp4.partial"));
  VideoWriter w(path, 64, 48, 30);
  EXPECT_NE(error_of([&] { w.write(frame_code_image(0, 32, 48)); }).find("a frame of 32x48 in a 64x48 video"), std::string::npos);
}

namespace {
// Waits (the test's thread, not a renderer) until the player has frames queued for `t`.
VideoPlayer::Shown settle(VideoPlayer& p, double t) {
  VideoPlayer::Shown s;
  for (int i = 0; i < 500; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    if (p.stats().decoded >= 4) break;
  }
  s = p.frame_at(t);
  return s;
}
}  // namespace

TEST(VideoPlayer, ShowsTheFrameOfTheContentTime) {
  const fs::path clip = write_clip("player.mp4", 30);
  VideoPlayer p(std::make_unique<VideoDecoder>(clip), false, 4);
  auto s = settle(p, 0.0);
  ASSERT_TRUE(s.frame);
  EXPECT_TRUE(s.fresh);
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 0);
  // A 60 Hz display: every video frame shown twice, the second time not fresh; nothing skipped or repeated.
  for (int k = 1; k < 50; ++k) {
    const double t = k / 60.0;
    for (int i = 0; i < 200 && p.stats().decoded < std::min<std::size_t>(30, k / 2 + 4); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s = p.frame_at(t);
    ASSERT_TRUE(s.frame);
    const int expected = static_cast<int>(std::floor(t * 30.0 + 1e-9));
    EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), expected) << t;
    EXPECT_EQ(s.fresh, k % 2 == 0) << k;
  }
  EXPECT_EQ(p.stats().skipped, 0U);
  EXPECT_EQ(p.stats().repeated, 0U);
  EXPECT_EQ(p.stats().waits, 0U);
  // Past the end without looping: the last frame stays, not counted as repeated once the stream has ended.
  for (int i = 0; i < 500 && read_frame_code(s.frame->image, 0, 0, 320, 240) != 29; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    s = p.frame_at(5.0);
  }
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 29);
  const std::size_t repeated = p.stats().repeated;
  s = p.frame_at(5.1);
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 29);
  EXPECT_EQ(p.stats().repeated, repeated);
  EXPECT_TRUE(p.take_error().empty());
}

TEST(VideoPlayer, LateAsksSkipFramesAndLoopsGoOn) {
  const fs::path clip = write_clip("loop.mp4", 10);  // 1/3 s
  VideoPlayer p(std::make_unique<VideoDecoder>(clip), true, 3);
  auto s = settle(p, 0.0);
  ASSERT_TRUE(s.frame);
  // Asked at frame 2's time with frames 0..2 queued: 1 skipped, 2 shown.
  s = p.frame_at(2.0 / 30.0);
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 2);
  EXPECT_GE(p.stats().skipped, 1U);
  // Looping: content time 0.5 s is frame 15 of an endless clip, i.e. frame 5 of the second pass.
  for (int k = 3; k <= 15; ++k) {
    for (int i = 0; i < 500; ++i) {
      s = p.frame_at(k / 30.0);
      if (s.frame && std::abs(s.frame->pts_s - k / 30.0) < 1e-3) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), k % 10) << k;
    EXPECT_NEAR(s.frame->pts_s, k / 30.0, 1e-3);
  }
  EXPECT_GE(p.stats().loops, 1U);
  // Back in time: the content began again, and its first frame comes back.
  p.frame_at(0.0);
  for (int i = 0; i < 500; ++i) {
    s = p.frame_at(0.0);
    if (s.fresh) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 0);
}

TEST(VideoPlayer, ADecoderBehindRepeatsTheLastFrameAndCountsIt) {
  const fs::path clip = write_clip("behind.mp4", 30);
  VideoPlayer p(std::make_unique<VideoDecoder>(clip), false, 2);
  auto s = settle(p, 0.0);
  ASSERT_TRUE(s.frame);
  // The decoder keeps at most 2 frames ahead of the one shown: asked at once for 0.9 s (frame 27), the
  // newest it has (at most frame 3) goes up and the ask counts as repeated; then it catches up, skipping.
  s = p.frame_at(0.9);
  const std::int64_t first = read_frame_code(s.frame->image, 0, 0, 320, 240);
  EXPECT_GE(first, 1);
  EXPECT_LE(first, 3);
  EXPECT_GE(p.stats().repeated, 1U);
  for (int i = 0; i < 1000 && read_frame_code(s.frame->image, 0, 0, 320, 240) != 27; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    s = p.frame_at(0.9);
  }
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 320, 240), 27);
  // Every frame up to 27 went up or was passed over, none twice.
  EXPECT_EQ(p.stats().shown + p.stats().skipped, 28U);
  EXPECT_GE(p.stats().skipped, 1U);
}

TEST(VideoPlayer, ContentFarAheadIsJumpedToNotDecodedThrough) {
  // A target not drawn for a while, its content's time going on: asked 7.5 s in, a looping 3 s clip jumps
  // (from the key frame before) to frame 45 of its third pass instead of decoding 225 frames.
  const fs::path clip = write_clip("seek.mp4", 90, 64, 48);
  VideoPlayer p(std::make_unique<VideoDecoder>(clip), true, 4);
  auto s = settle(p, 0.0);
  ASSERT_TRUE(s.frame);
  for (int i = 0; i < 1000; ++i) {
    s = p.frame_at(7.5);
    if (s.frame && std::abs(s.frame->pts_s - 7.5) < 1e-3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_NEAR(s.frame->pts_s, 7.5, 1e-3);
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 64, 48), 45);
  EXPECT_EQ(p.stats().seeks, 1U);
  EXPECT_LT(p.stats().decoded, 20U);  // the frames around the jump, not the 225 before it
  // Not looping: past the end, a jump lands on the last frame.
  VideoPlayer once(std::make_unique<VideoDecoder>(clip), false, 4);
  s = settle(once, 0.0);
  for (int i = 0; i < 1000; ++i) {
    s = once.frame_at(60.0);
    if (s.frame && read_frame_code(s.frame->image, 0, 0, 64, 48) == 89) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(read_frame_code(s.frame->image, 0, 0, 64, 48), 89);
}

// A replay's player (frame_due): every ask, straight after opening, across a loop, a jump far ahead and
// back to the start, gets the frame due at its time without the test waiting for the decoder; nothing
// is repeated, and the same asks give the same frames again.
TEST(VideoPlayer, FrameDueWaitsForTheFrameOfItsTimeEveryTime) {
  const fs::path clip = write_clip("due.mp4", 20, 64, 48);  // 2/3 s, looping
  const std::vector<double> asks = {0.0, 1 / 60.0, 0.1, 0.1 + 1 / 60.0, 0.5, 0.66, 0.7, 1.3, 6.1, 6.15, 0.05, 0.4};
  std::vector<std::int64_t> first;
  for (int pass = 0; pass < 2; ++pass) {
    VideoPlayer p(std::make_unique<VideoDecoder>(clip), true, 2);
    std::vector<std::int64_t> codes;
    for (const double t : asks) {
      const VideoPlayer::Shown s = p.frame_due(t);
      ASSERT_TRUE(s.frame) << t;
      const auto due = static_cast<std::int64_t>(std::floor(t * 30.0 + 1e-9));
      EXPECT_NEAR(s.frame->pts_s, static_cast<double>(due) / 30.0, 1e-3) << t;  // loops add on
      codes.push_back(read_frame_code(s.frame->image, 0, 0, 64, 48));
      EXPECT_EQ(codes.back(), due % 20) << t;
    }
    EXPECT_EQ(p.stats().repeated, 0U);
    EXPECT_GE(p.stats().loops, 1U);
    EXPECT_EQ(p.stats().seeks, 1U);  // 1.3 s to 6.1 s: jumped to
    if (pass == 0) first = codes;
    EXPECT_EQ(codes, first);
  }
  // Not looping: past the end, the last frame, at once.
  VideoPlayer once(std::make_unique<VideoDecoder>(clip), false, 2);
  EXPECT_EQ(read_frame_code(once.frame_due(0.2).frame->image, 0, 0, 64, 48), 6);
  EXPECT_EQ(read_frame_code(once.frame_due(30.0).frame->image, 0, 0, 64, 48), 19);
}
