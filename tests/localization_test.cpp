// Rawlogs, MRPT ICP-SLAM on the real and the simulated datasets, scan-to-map localisation and
// the simulated tour.
#include "projbot/robot/localization.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "projbot/robot/ptu_d46.hpp"
#include "projbot/robot/sim_tour.hpp"

namespace {

using namespace projbot::robot;
namespace fs = std::filesystem;
const fs::path kData = fs::path(PROJBOT_SHARED_DATA) / "mrpt";
[[maybe_unused]] double deg(double d) { return d * std::numbers::pi / 180.0; }

fs::path temp_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("projbot_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(Rawlog, ReadsTheRealDataset) {
  const auto steps = read_rawlog(kData / "2006-01ENE-21-SENA_Telecom_Faculty_one_loop_only.rawlog");
  EXPECT_EQ(steps.size(), 225u);
  int with_odometry = 0;
  for (const auto& s : steps) with_odometry += s.odometry_increment.has_value();
  EXPECT_GE(with_odometry, 224);
  EXPECT_GT(steps[0].scan.ranges_m.size(), 100u);
  EXPECT_GT(steps.back().timestamp_s, steps.front().timestamp_s);
}

TEST(Rawlog, BadFilesAreNamed) {
  EXPECT_THROW(read_rawlog(kData / "no-such.rawlog"), RobotError);
  const fs::path dir = temp_dir("badrawlog");
  { std::ofstream(dir / "junk.rawlog") << "this is not a rawlog\n"; }
  try {
    read_rawlog(dir / "junk.rawlog");
    FAIL();
  } catch (const RobotError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.rawlog"), std::string::npos) << e.what();
  }
  // Truncated: the first half of a real (gzip) rawlog.
  {
    std::ifstream in(kData / "localization_demo.rawlog", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(dir / "cut.rawlog", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  // A cut file either yields the scans before the cut or a named error, never a crash.
  try {
    const auto steps = read_rawlog(dir / "cut.rawlog");
    EXPECT_LT(steps.size(), 37u);
  } catch (const RobotError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.rawlog"), std::string::npos);
  }
  fs::remove_all(dir);
}

TEST(Trajectory, RoundTripAndBadLines) {
  const fs::path dir = temp_dir("traj");
  write_trajectory(dir / "t.txt", {{1.5, {1, 2, 0.5}}, {2.5, {-1, 0.25, -3}}});
  const auto back = read_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_DOUBLE_EQ(back[1].pose.y_m, 0.25);
  EXPECT_DOUBLE_EQ(back[1].timestamp_s, 2.5);
  std::ofstream(dir / "bad.txt") << "1 2 3 4\n5 6 seven 8\n";
  try {
    read_trajectory(dir / "bad.txt");
    FAIL();
  } catch (const RobotError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
