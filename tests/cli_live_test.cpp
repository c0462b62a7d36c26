// Live runs of the projbot executable whose figures follow their own latency. They run alone
// (RUN_SERIAL): beside another run on 2 cores, the moving box's error at display measured 26-52 mm
// (pose age doubled), 3-5 mm alone.

#include <gtest/gtest.h>

#include <string>

#include "cli_run.hpp"

// run --sim measures each frame against the twin's truth at its display time: the box carried at
// 0.5 m/s (visit 2 of the motion scene) stays within a few mm of where it is drawn.
TEST(CliLiveTest, RunMeasuresTheErrorAtDisplayTime) {
  const CliRun r =
      run_projbot("run --headless --config " + std::string(PROJBOT_ASSET_DIR) + "/scenes/motion.yaml --visits 2 --dwell 2.5");
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
