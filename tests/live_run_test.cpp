// The live engine as a library (live::run): the twin's robot thread and the render loop together, drawn
// offscreen, each frame measured against the twin's truth.

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>

#include "projbot/live/reflectance_probe.hpp"
#include "projbot/live/run.hpp"
#include "projbot/twin/twin_rig.hpp"

namespace {

projbot::live::RunSources twin_sources(projbot::live::Devices& devices, const projbot::config::Scene& scene, std::ostream& log,
                                       std::ostream& errors) {
  projbot::live::RunSources s;
  s.devices = &devices;
  s.open_rig = projbot::twin::rig_opener({});  // no base, no recording: the twin, seed 1, the fitted depth model
  s.open_output = [&scene](projbot::engine::Renderer& r) {
    return r.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  };
  s.log = &log;
  s.errors = &errors;
  return s;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 1e9 : v[v.size() / 2];
}

// One visit of the demo tour: the robot drives to the Duck, the worker finds it, and the frames drawn
// while it is lit land within the goal's 3 mm of the twin's markers; driving, the projector is blank.
TEST(LiveRun, ATwinVisitIsDrawnTrackedAndMeasured) {
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml");
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  projbot::live::Devices devices;  // none: the twin serves every device
  std::ostringstream log, errors;
  projbot::live::RunOptions o;
  o.visits = 1;
  o.dwell_s = 2.0;  // long enough for a loaded machine, which paces fewer than 60 frames a second
  o.headless = true;
  const projbot::live::RunResult r = projbot::live::run(renderer, scene, o, twin_sources(devices, scene, log, errors));
  EXPECT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_TRUE(r.measured);
  EXPECT_EQ(r.visits, 1);
  EXPECT_NE(log.str().find("visit 1: duck"), std::string::npos) << log.str();
  EXPECT_GT(r.figures.rows.size(), 30U);     // paced at 60 Hz over the drive and the dwell
  EXPECT_GT(r.figures.blank, 0U);            // driving and acquiring: nothing drawn
  ASSERT_GE(r.figures.still_mm.size(), 5U);  // enough for the median to say something; the rate is load's
  EXPECT_LT(median(r.figures.still_mm), 3.0);
  EXPECT_GT(r.tracked, 5U);
  EXPECT_EQ(r.handoff_from_capture_ms.size(), r.handoff_in_session_ms.size());
  EXPECT_TRUE(errors.str().empty()) << errors.str();
}

// With `seconds`, the loop ends after that long on its clock, the robot thread stopped wherever it was.
TEST(LiveRun, ARunEndsAfterItsSeconds) {
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml");
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  projbot::live::Devices devices;
  std::ostringstream log, errors;
  projbot::live::RunOptions o;
  o.headless = true;
  o.seconds = 1.0;
  const projbot::live::RunResult r = projbot::live::run(renderer, scene, o, twin_sources(devices, scene, log, errors));
  EXPECT_TRUE(r.failure.empty()) << r.failure;
  EXPECT_GT(r.figures.rows.size(), 30U);  // 60 Hz for 1 s, on a loaded machine at least half of that
  EXPECT_LE(r.figures.rows.size(), 62U);
  EXPECT_LE(r.visits, 1);
}

// What run requires is refused by name, before anything is drawn.
TEST(LiveRun, MissingSourcesAreRefused) {
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml");
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  projbot::live::RunSources none;
  EXPECT_THROW(projbot::live::run(renderer, scene, {}, none), std::invalid_argument);
}

}  // namespace

// The reflectance probe's steps at a stop (run --learn-reflectance; the measurement itself through the
// executable: CliTest.RunLearnsEachTargetsReflectanceAtItsStop): nothing until the visited target's pose
// is accepted at this stop, then black until a frame taken `settle` later, then grey; a stop left midway
// shows the targets again, and a camera whose frames carry no colour is said.
TEST(ReflectanceProbe, StepsThroughBlackAndGreyOnceThePoseIsAccepted) {
  const auto scene = projbot::config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml");
  projbot::live::ReflectanceProbe probe(scene, std::vector<const projbot::assets::Model*>(scene.targets.size(), nullptr), 0.1);
  projbot::live::Stop stop;
  stop.target = 0;
  projbot::alignment::PoseSample pose;
  pose.lost = false;
  pose.capture_time_s = 9.9;  // the last stop's
  const projbot::live::PoseSource poses = [&](int, projbot::alignment::PoseSample& out) { return (out = pose), true; };
  const auto frame = [](double captured_s, bool colour) {
    projbot::alignment::RgbdFrame f;
    f.depth.capture_time_s = captured_s;
    if (colour) f.colour.width = 4, f.colour.height = 3, f.colour.rgba.assign(48, 9);
    return f;
  };
  EXPECT_FALSE(probe.showing());  // no stop yet
  probe.lit(stop, 10.0);
  EXPECT_EQ(probe.frame(frame(10.0, true), 10.0, poses), "");
  EXPECT_FALSE(probe.showing());  // a pose from before the stop
  pose.capture_time_s = 10.05;
  EXPECT_EQ(probe.frame(frame(10.06, true), 10.06, poses), "");
  ASSERT_TRUE(probe.showing());
  EXPECT_EQ((*probe.showing())[0], 0);  // black
  EXPECT_EQ(probe.frame(frame(10.10, true), 10.10, poses), "");
  EXPECT_EQ((*probe.showing())[0], 0);  // taken before black was surely shown
  EXPECT_EQ(probe.frame(frame(10.17, true), 10.17, poses), "");
  EXPECT_EQ((*probe.showing())[0], 128);  // grey
  probe.left();
  EXPECT_FALSE(probe.showing());  // the targets again
  probe.lit(stop, 11.0);
  pose.capture_time_s = 11.1;
  probe.frame(frame(11.1, false), 11.1, poses);
  EXPECT_EQ((*probe.showing())[0], 0);
  const std::string said = probe.frame(frame(11.3, false), 11.3, poses);
  EXPECT_NE(said.find("the camera's frames carry no colour"), std::string::npos) << said;
  EXPECT_FALSE(probe.showing());
  // Moved between the two images (a visitor picks it up): the two do not show the same points.
  const auto measured = [&](double lit_s, const Eigen::Vector3d& moved) {
    probe.lit(stop, lit_s);
    pose.capture_time_s = lit_s + 0.05;
    pose.T_camera_target = Eigen::Matrix4d::Identity();
    probe.frame(frame(lit_s + 0.06, true), lit_s + 0.06, poses);
    probe.frame(frame(lit_s + 0.2, true), lit_s + 0.2, poses);
    EXPECT_EQ((*probe.showing())[0], 128);
    pose.T_camera_target.topRightCorner<3, 1>() = moved;
    return probe.frame(frame(lit_s + 0.4, true), lit_s + 0.4, poses);
  };
  EXPECT_NE(measured(12.0, {0.01, 0.0, 0.0}).find("it moved between the black and the grey image"), std::string::npos);
  // Still, but colour of another size than the depth camera's: not registered to it, so not read.
  EXPECT_NE(measured(13.0, {0.001, 0.0, 0.0}).find("its colour images are 4x3, not the depth camera's 640x480"),
            std::string::npos);
  EXPECT_FALSE(probe.showing());
  EXPECT_TRUE(probe.take_learnt().empty());
}
