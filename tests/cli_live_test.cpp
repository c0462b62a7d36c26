// Live runs of the projbot executable whose figures follow their own latency. They run alone
// (RUN_SERIAL): beside another run on 2 cores, the moving box's error at display measured 26-52 mm
// (pose age doubled), 3-5 mm alone.

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"

// run --sim measures each frame against the twin's truth at its display time: the box carried at
// 0.5 m/s (visit 2 of the motion scene) stays within a few mm of where it is drawn.
TEST(CliLiveTest, RunMeasuresTheErrorAtDisplayTime) {
  const CliRun r = run_projbot("run --headless --config " + std::string(PROJBOT_ASSET_DIR) +
                               "/scenes/motion.yaml --visits 2 --dwell 2.5 --depth-model kinect");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string key = "error at display (markers drawn vs true, twin): while moving mean ";
  const auto at = r.output.find(key);
  ASSERT_NE(at, std::string::npos) << r.output;
  const double moving_mm = std::stod(r.output.substr(at + key.size()));
  EXPECT_GT(moving_mm, 0.0);
  // A live run's error while moving follows its latency, which follows the machine's load: 3-5 mm alone,
  // 8-52 mm beside another test on 2 cores (pose age p50 110 ms there), hence RUN_SERIAL. The goal
  // itself is measured where latency is fixed (bench motion --processing-ms, BenchMotionComparesPrediction-
  // OffAndOn); here the figures must be there and plausible: a truth taken at the wrong instant or frame
  // puts the box tens of centimetres off.
  EXPECT_LT(moving_mm, 25.0) << r.output;
  EXPECT_LT(number_after(r.output, "still mean ", at), 2.0) << r.output;
}

// bench content (issue 44): the shipped content scene's 1080p H.264 clip on both targets, drawn at 60 Hz for
// 3 s; the report's figures there and in their goals' range. Alone (RUN_SERIAL): the decoder's lead follows
// the machine's load.
TEST(CliLiveTest, BenchContentKeepsTheVideoOnTheDisplayClock) {
  const std::string report = ::testing::TempDir() + "projbot_bench_content.json";
  const CliRun r = run_projbot("bench content --seconds 3 --report " + report);
  ASSERT_EQ(r.code, 0) << r.output;
  // Made by the build into the build tree (issue 71), and found there by the shipped scene.
  EXPECT_NE(r.output.find(std::string(PROJBOT_GENERATED_ASSET_DIR) + "/videos/countdown.mp4, 1920x1080 h264 at 30.00 fps"),
            std::string::npos)
      << r.output;
  std::ifstream in(report);
  const auto json = nlohmann::json::parse(in);
  const auto frames = json.at("frames").get<double>();
  // 180 at 60 Hz; lavapipe on a machine busy with a build beside it drew 97 once: this checks the loop
  // drew all along (the frame rate is bench content's figure, not a test's).
  EXPECT_GE(frames, 45.0) << json.dump(1);
  // Content time less the shown frame's time: one video frame is 33.3 ms.
  EXPECT_GE(json.at("content_offset_ms_p50").get<double>(), 0.0) << json.dump(1);
  EXPECT_LT(json.at("content_offset_ms_p50").get<double>(), 33.4) << json.dump(1);
  EXPECT_GE(json.at("content_within_one_frame").get<double>(), 0.9) << json.dump(1);
  EXPECT_LE(json.at("renderer_waits").get<double>(), 0.01 * frames) << json.dump(1);
  EXPECT_GT(json.at("upload_ms_p50").get<double>(), 0.0) << json.dump(1);
  EXPECT_LT(json.at("targets_in_step_ms_max").get<double>(), 34.0) << json.dump(1);
  EXPECT_GT(json.at("rss_mb_end").get<double>(), 0.0);
  std::remove(report.c_str());
}
