#include "projbot/engine/frame_profiler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

using projbot::engine::FrameProfiler;
using projbot::engine::FrameRecord;

TEST(PercentileTest, InterpolatesLinearlyAndSkipsNan) {
  EXPECT_DOUBLE_EQ(projbot::engine::percentile({1, 2, 3, 4, 5}, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(projbot::engine::percentile({1, 2, 3, 4}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(projbot::engine::percentile({5, 1, std::nan(""), 3}, 1.0), 5.0);
  EXPECT_TRUE(std::isnan(projbot::engine::percentile({}, 0.5)));
}

TEST(FrameProfilerTest, SummaryUsesStartToStartFrameTimes) {
  FrameProfiler prof;
  // Ten frames 10 ms apart, the fifth one 30 ms long; the last completes 10 ms after it starts.
  double t = 0;
  for (std::uint64_t i = 0; i < 10; ++i) {
    FrameRecord r;
    r.index = i;
    r.start_ms = t;
    r.pose_read_ms = t + 1;
    r.recorded_ms = t + 1.5;
    r.completed_ms = t + 10;
    r.gpu_ms = 2.0;
    prof.add(r);
    t += (i == 4) ? 30 : 10;
  }
  const auto s = prof.summary();
  EXPECT_EQ(s.frames, 10U);
  EXPECT_DOUBLE_EQ(s.p50_ms, 10.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 30.0);
  EXPECT_NEAR(s.fps, 10 * 1000.0 / 120.0, 1e-9);
  EXPECT_DOUBLE_EQ(s.gpu_p50_ms, 2.0);
  EXPECT_DOUBLE_EQ(s.cpu_record_p50_ms, 0.5);

  const auto csv = std::filesystem::temp_directory_path() / "projbot_profile_test.csv";
  prof.write_csv(csv);
  std::ifstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("frame,start_ms", 0), 0U);
  int rows = 0;
  while (std::getline(in, line)) ++rows;
  EXPECT_EQ(rows, 10);
  std::filesystem::remove(csv);
  EXPECT_THROW(prof.write_csv("/nonexistent-dir/p.csv"), std::runtime_error);
}

TEST(FrameProfilerTest, UploadPercentilesOverTheFramesThatUploaded) {
  FrameProfiler prof;
  const double uploads[] = {0.0, 0.5, 0.0, 1.5, 1.0};  // 0: the frame streamed nothing
  for (std::uint64_t i = 0; i < 5; ++i) {
    FrameRecord r;
    r.index = i;
    r.start_ms = 10.0 * static_cast<double>(i);
    r.completed_ms = r.start_ms + 5.0;
    r.upload_ms = uploads[i];
    prof.add(r);
  }
  const auto s = prof.summary();
  EXPECT_EQ(s.uploads, 3U);
  EXPECT_DOUBLE_EQ(s.upload_p50_ms, 1.0);
  EXPECT_NEAR(s.upload_p99_ms, 1.49, 1e-9);
  FrameProfiler none;
  FrameRecord r;
  r.completed_ms = 5.0;
  none.add(r);
  EXPECT_EQ(none.summary().uploads, 0U);
  EXPECT_TRUE(std::isnan(none.summary().upload_p50_ms));
}
