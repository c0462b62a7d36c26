// A session from a recording, at the library: poses.csv written by PoseLog and checked by PoseCheck (a
// replay's poses against the recording's, and malformed files refused naming file and line), and the
// recording's devices (ReplayRig) answering what was recorded or refusing a stop it does not hold.

#include "projbot/live/replay.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>

#include "projbot/config/angles.hpp"

using namespace projbot;

namespace {

config::Scene two_targets() {
  config::Scene scene;
  scene.targets.resize(2);
  scene.targets[0].name = "duck";
  scene.targets[1].name = "box";
  return scene;
}

live::Stop stop_lighting_both(int visit) {
  live::Stop stop;
  stop.visit = visit;
  stop.target = 0;
  stop.lit.resize(2);
  stop.lit[0].target = 0;
  stop.lit[1].target = 1;
  return stop;
}

alignment::PoseSample pose_at(double x_m) {
  alignment::PoseSample s;
  s.T_camera_target(0, 3) = x_m;
  s.T_camera_target(2, 3) = 1.0;
  s.lost = false;
  return s;
}

class ReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("projbot_replay_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path write(const std::string& text) {
    const auto path = dir_ / "poses.csv";
    std::ofstream(path) << text;
    return path;
  }
  // The message of the ConfigError that reading `text` as poses.csv throws.
  std::string refusal(const std::string& text) {
    try {
      live::PoseCheck check(write(text));
    } catch (const config::ConfigError& e) {
      return e.what();
    }
    return "(accepted)";
  }
  std::filesystem::path dir_;
};

TEST_F(ReplayTest, APoseLogReadBackComparesItsOwnPosesExactlyAndMeasuresADifference) {
  const config::Scene scene = two_targets();
  live::PoseLog log;
  log.add(scene, stop_lighting_both(0), 1, {pose_at(0.1), std::nullopt});
  log.add(scene, stop_lighting_both(0), 2, {pose_at(0.2), pose_at(-0.3)});
  live::PoseCheck same(write(log.text()));
  same.compare(scene, stop_lighting_both(0), 1, {pose_at(0.1), std::nullopt});
  same.compare(scene, stop_lighting_both(0), 2, {pose_at(0.2), pose_at(-0.3)});
  EXPECT_EQ(same.compared, 3);  // the box's missing pose of frame 1 agrees, but there is nothing to compare
  EXPECT_EQ(same.mismatched, 0);
  EXPECT_EQ(same.max_mm, 0.0);
  EXPECT_EQ(same.unreached(), 0);

  live::PoseCheck moved(write(log.text()));
  moved.compare(scene, stop_lighting_both(0), 2, {pose_at(0.2015), std::nullopt});  // 1.5 mm off; the box lost
  EXPECT_NEAR(moved.max_mm, 1.5, 1e-6);
  EXPECT_EQ(moved.compared, 1);
  EXPECT_EQ(moved.mismatched, 1);
  EXPECT_EQ(moved.unreached(), 2);  // frame 1's two rows
  // Rotations: the same pose a float's rounding left 1e-7 off orthonormal compares as 0 degrees; a turn of
  // 2 degrees about z as 2.
  alignment::PoseSample rounded = pose_at(0.1);
  rounded.T_camera_target.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() * (1.0 + 1e-7);
  live::PoseLog turned_log;
  turned_log.add(scene, stop_lighting_both(0), 1, {rounded, std::nullopt});
  live::PoseCheck turned(write(turned_log.text()));
  turned.compare(scene, stop_lighting_both(0), 1, {rounded, std::nullopt});
  EXPECT_EQ(turned.max_deg, 0.0);
  alignment::PoseSample two = rounded;
  two.T_camera_target.topLeftCorner<3, 3>() =
      rounded.T_camera_target.topLeftCorner<3, 3>() *
      Eigen::AngleAxisd(projbot::config::radians(2.0), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turned.compare(scene, stop_lighting_both(0), 1, {two, std::nullopt});
  EXPECT_NEAR(turned.max_deg, 2.0, 1e-4);
}

TEST_F(ReplayTest, AMalformedPoseFileIsRefusedNamingItsLine) {
  const std::string header = std::string(live::PoseLog::kHeader) + "\n";
  const std::string row = "0,1,duck,1,0,1,0,0,0.1,0,1,0,0,0,0,1,1\n";
  EXPECT_NE(refusal("visit,frame\n" + row).find("poses.csv:1: not the poses of a recording"), std::string::npos);
  EXPECT_NE(refusal(header + "0,1,duck,1,0,1,0\n").find("poses.csv:2: expected visit, frame, target and 14 numbers"),
            std::string::npos);
  EXPECT_NE(refusal(header + "0,1,duck,1,0,nan,0,0,0.1,0,1,0,0,0,0,1,1\n").find(":2: a value is not a finite number"),
            std::string::npos);
  EXPECT_NE(refusal(header + row + row).find(":3: a second row for visit 0, frame 1, target duck"), std::string::npos);
  EXPECT_NE(refusal(header + "0,1,duck,1,0,2,0,0,0.1,0,1,0,0,0,0,1,1\n").find(":2: pose"), std::string::npos);
  EXPECT_EQ(refusal(header + row), "(accepted)");
}

TEST_F(ReplayTest, TheRecordingsDevicesAnswerWhatWasRecordedAndRefuseAStopItDoesNotHold) {
  config::Recording recording;
  recording.source = dir_ / "recording.yaml";
  config::RecordedStop s;
  s.target = "duck";
  s.goal = {1.0, 2.0, 0.5};
  s.believed = {1.01, 1.98, 0.49};
  s.pan_rad = 0.2;
  s.tilt_rad = -0.1;
  s.drive_s = 7.5;
  s.arrived = true;
  recording.stops.push_back(s);
  // The session it serves: the demo tour's scene, its targets with a stand-in model cloud.
  const config::Scene scene = config::load_scene(std::filesystem::path(PROJBOT_ASSET_DIR) / "scenes" / "tour.yaml");
  alignment::ModelCloud cloud;
  std::vector<live::Target> targets;
  for (int i = 0; i < static_cast<int>(scene.targets.size()); ++i) targets.push_back({i, &cloud, Eigen::Vector3d::Zero()});
  live::ReplayClock clock;
  clock.close();  // no projector: the robot does not wait for one
  const config::Clock robot = clock.robot();
  live::ReplayRig replay(scene, recording, targets, robot);
  const robot::StopReport r = replay.drive_to({1.0, 2.0, 0.5}, 0);
  EXPECT_DOUBLE_EQ(robot.now_s(), 7.5);  // the drive took its recorded time on the replay's clock
  EXPECT_TRUE(r.arrived);
  EXPECT_DOUBLE_EQ(r.drive_seconds, 7.5);
  EXPECT_DOUBLE_EQ(replay.believed_pose().x_m, 1.01);
  robot::PanTiltAngles angles;
  replay.position(angles);
  EXPECT_DOUBLE_EQ(angles.pan_rad, 0.2);
  EXPECT_DOUBLE_EQ(angles.tilt_rad, -0.1);
  try {
    replay.drive_to({1.0, 2.0, 0.5}, 1);
    FAIL() << "a stop the recording does not hold was driven to";
  } catch (const live::SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("asked for stop 2 but the recording holds 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(replay.drive_to({3.0, 2.0, 0.5}, 0), live::SessionError);  // another stop than recorded
}

// What `record` learnt of the targets' reflectance travels in recording.yaml (`reflectance:`, a PNG per
// target inside the folder) and replaces the scene's `surface:` in a replay; a map of a target the scene
// lacks, a file outside the folder or gone is refused, naming it.
TEST_F(ReplayTest, ARecordingsLearntReflectanceReplacesTheScenesSurfaceAndIsRefusedWhenNotThere) {
  config::Recording recording;
  config::RecordedStop s;
  s.target = "duck";
  s.frames = "stop01";
  s.frame_count = 3;
  recording.stops.push_back(s);
  recording.reflectance["duck"].texture = "reflectance/duck.png";
  recording.reflectance["box"].albedo = {0.5, 0.4, 0.25};  // a model without texture coordinates
  std::filesystem::create_directories(dir_ / "reflectance");
  std::ofstream(dir_ / "reflectance" / "duck.png") << "png";
  std::ofstream(dir_ / "recording.yaml") << config::recording_yaml(recording);
  const config::Recording read = config::load_recording(dir_);
  ASSERT_EQ(read.reflectance.size(), 2U);
  EXPECT_EQ(read.reflectance.at("duck").texture, "reflectance/duck.png");
  EXPECT_TRUE(read.reflectance.at("box").texture.empty());
  EXPECT_EQ(read.reflectance.at("box").albedo, Eigen::Vector3d(0.5, 0.4, 0.25));
  config::Scene scene = two_targets();
  config::use_learnt_reflectance(scene, read);
  EXPECT_EQ(scene.targets[0].surface.texture, dir_ / "reflectance" / "duck.png");
  EXPECT_TRUE(scene.targets[1].surface.texture.empty());
  EXPECT_EQ(scene.targets[1].surface.albedo, Eigen::Vector3d(0.5, 0.4, 0.25));

  const auto refusal = [&](const std::function<void()>& f) {
    try {
      f();
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  config::Recording cat = read;
  cat.reflectance = {{"cat", config::TargetSurface{}}};
  EXPECT_NE(refusal([&] { config::use_learnt_reflectance(scene, cat); }).find("reflectance.cat: "), std::string::npos);
  recording.reflectance["duck"].texture = "../duck.png";
  std::ofstream(dir_ / "recording.yaml") << config::recording_yaml(recording);
  EXPECT_NE(refusal([&] { config::load_recording(dir_); }).find("reflectance.duck: must name a PNG file inside the recording"),
            std::string::npos);
  recording.reflectance["duck"].texture = "reflectance/gone.png";
  std::ofstream(dir_ / "recording.yaml") << config::recording_yaml(recording);
  EXPECT_NE(refusal([&] { config::load_recording(dir_); }).find("reflectance.duck: no such file: "), std::string::npos);
  recording.reflectance["duck"].texture = "reflectance/duck.png";
  recording.reflectance["box"].albedo = {0.5, 1.5, 0.25};
  std::ofstream(dir_ / "recording.yaml") << config::recording_yaml(recording);
  EXPECT_NE(refusal([&] { config::load_recording(dir_); }).find("reflectance.box: an albedo is 0..1 per channel"),
            std::string::npos);
}

// A replay's clock keeps the projector's frames and the session in step: the frame of time T is drawn
// once the robot has done everything it did up to T and before anything after, whether the robot is quick
// or slow; once the robot has finished the frames go on unheld, and close() releases a robot that waits.
TEST(ReplayClock, EachProjectorFrameSeesWhatTheRobotDidUpToItsTimeAndNothingAfter) {
  const std::vector<double> events = {0.0, 0.01, 0.05, 0.05, 0.1, 0.3335, 0.5};
  for (const bool slow_robot : {false, true}) {
    live::ReplayClock clock;
    std::atomic<int> done{0};
    std::jthread robot([&] {
      const config::Clock c = clock.robot();
      for (const double t : events) {
        c.sleep_until(t);
        EXPECT_DOUBLE_EQ(c.now_s(), t);
        if (slow_robot) std::this_thread::sleep_for(std::chrono::milliseconds(3));  // tracking a frame
        done.fetch_add(1);
      }
      clock.robot_finished();
    });
    const config::Clock projector = clock.projector();
    for (int n = 1; n <= 45; ++n) {
      const double T = n / 60.0;
      projector.sleep_until(T);
      EXPECT_DOUBLE_EQ(projector.now_s(), T);
      const auto expected = std::count_if(events.begin(), events.end(), [&](double t) { return t <= T; });
      EXPECT_EQ(done.load(), expected) << "frame at " << T << " s, slow robot " << slow_robot;
    }
  }
  live::ReplayClock clock;
  std::atomic<bool> released{false};
  std::jthread robot([&] {
    clock.robot().sleep_until(10.0);  // the projector never gets there: the run ends first
    released = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(released);
  clock.close();
  robot.join();
  EXPECT_TRUE(released);
}

}  // namespace
