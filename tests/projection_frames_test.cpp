// Each projector frame's decision (live::ProjectionFrames) on a scripted pose source and a fake
// clock: what is drawn, where (Eq. 2, at the display time), and what is blanked.

#include "projbot/live/projection_frames.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <map>

using namespace projbot;

namespace {

// Poses by target, as a tracker worker would publish them.
struct ScriptedPoses {
  std::map<int, alignment::PoseSample> newest;
  live::PoseSource source() {
    return [this](int target, alignment::PoseSample& out) {
      const auto it = newest.find(target);
      if (it == newest.end()) return false;
      out = it->second;
      return true;
    };
  }
  void publish(int target, const Eigen::Matrix4d& T, double capture_s, bool lost = false) {
    alignment::PoseSample s;
    s.T_camera_target = T;
    s.capture_time_s = capture_s;
    s.lost = lost;
    s.motion.T = T;
    s.motion.time_s = capture_s;
    newest[target] = s;
  }
};

Eigen::Matrix4d at(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
  return T;
}

live::ProjectionConfig config_60hz() {
  live::ProjectionConfig c;
  c.T_projector_camera = at(0.1, 0.0, 0.0);  // the projector 10 cm beside the camera
  c.refresh_hz = 60.0;
  c.input_lag_ms = 20.0;
  return c;
}

}  // namespace

TEST(ProjectionFrames, DrawsEachFoundTargetThroughEq2AndBlanksTheRest) {
  // Three lit targets: one found, one lost, one never found; a fourth found but not lit at this stop.
  ScriptedPoses poses;
  poses.publish(0, at(0.0, 0.0, 1.0), 10.00);
  poses.publish(1, at(0.2, 0.0, 1.0), 10.00, true);
  poses.publish(3, at(0.4, 0.0, 1.0), 10.00);
  live::ProjectionFrames frames(config_60hz());
  const auto drawn = frames.compose(10.05, {{0, 1, 2}, 9.0, 10.04}, poses.source());
  ASSERT_EQ(drawn.size(), 1u);
  EXPECT_EQ(drawn[0].target, 0);
  EXPECT_DOUBLE_EQ(drawn[0].capture_s, 10.00);
  // Displayed one period (the configured 1/60 s until frames have run) plus the 20 ms lag later.
  EXPECT_NEAR(drawn[0].display_s, 10.05 + 1.0 / 60.0 + 0.020, 1e-12);
  // Eq. 2: the target 1 m ahead of the camera lies 10 cm beside it in the projector's frame.
  EXPECT_TRUE(drawn[0].T_projector_target.isApprox(at(0.1, 0.0, 1.0), 1e-12));
  EXPECT_EQ(frames.silent_frames(), 0u);
}

TEST(ProjectionFrames, PosesFromBeforeTheStopAreNotDrawn) {
  ScriptedPoses poses;
  poses.publish(0, at(0.0, 0.0, 1.0), 4.99);  // the last stop's
  live::ProjectionFrames frames(config_60hz());
  EXPECT_TRUE(frames.compose(5.02, {{0}, 5.0, 5.01}, poses.source()).empty());
  poses.publish(0, at(0.0, 0.0, 1.0), 5.01);
  EXPECT_EQ(frames.compose(5.03, {{0}, 5.0, 5.02}, poses.source()).size(), 1u);
}

TEST(ProjectionFrames, AMovingTargetIsDrawnWhereItWillBeAtDisplayTime) {
  // A target seen moving at 0.5 m/s along x: drawn where it will be when the frame is lit, not where
  // the camera saw it; with prediction off, where it was seen.
  ScriptedPoses poses;
  poses.publish(0, at(0.0, 0.0, 1.0), 1.000);
  poses.newest[0].motion.velocity_m_s = Eigen::Vector3d(0.5, 0.0, 0.0);
  live::ProjectionFrames frames(config_60hz());
  const auto drawn = frames.compose(1.030, {{0}, 0.0, 1.02}, poses.source());
  ASSERT_EQ(drawn.size(), 1u);
  const double ahead_s = drawn[0].display_s - 1.000;  // 30 ms + 1/60 s + 20 ms: within the 0.1 s horizon
  ASSERT_LT(ahead_s, 0.1);
  EXPECT_NEAR(drawn[0].T_camera_target(0, 3), 0.5 * ahead_s, 1e-9);
  EXPECT_NEAR(drawn[0].T_projector_target(0, 3), 0.1 + 0.5 * ahead_s, 1e-9);
  live::ProjectionConfig still = config_60hz();
  still.predict = false;
  live::ProjectionFrames as_seen(still);
  EXPECT_NEAR(as_seen.compose(1.030, {{0}, 0.0, 1.02}, poses.source()).at(0).T_camera_target(0, 3), 0.0, 1e-12);
}

TEST(ProjectionFrames, TheMeasuredFramePeriodSetsTheDisplayTime) {
  // A 60 Hz projector whose frames come every 20 ms (50 Hz, as measured): after ten frames the display
  // time is 20 ms ahead, not 16.7.
  ScriptedPoses poses;
  live::ProjectionConfig c = config_60hz();
  c.input_lag_ms = 0.0;
  live::ProjectionFrames frames(c);
  double t = 1.0;
  for (int i = 0; i < 11; ++i, t += 0.020) frames.frame_started(t);
  poses.publish(0, at(0.0, 0.0, 1.0), t - 0.03);
  EXPECT_NEAR(frames.period_s(), 0.020, 1e-12);
  EXPECT_NEAR(frames.compose(t, {{0}, 0.0, t}, poses.source()).at(0).display_s, t + 0.020, 1e-12);
}

TEST(ProjectionFrames, ASilentCameraBlanksEverythingUntilItSeesAgain) {
  // The camera hands over nothing for more than 100 ms: every target is blanked, and once frames come
  // again only poses captured after the silence are drawn. A replay (not watched) draws on.
  ScriptedPoses poses;
  poses.publish(0, at(0.0, 0.0, 1.0), 2.00);
  live::ProjectionFrames frames(config_60hz());
  EXPECT_EQ(frames.compose(2.05, {{0}, 1.0, 2.00}, poses.source()).size(), 1u);
  EXPECT_TRUE(frames.compose(2.15, {{0}, 1.0, 2.00}, poses.source()).empty());
  EXPECT_EQ(frames.silent_frames(), 1u);
  EXPECT_TRUE(frames.compose(2.20, {{0}, 1.0, 2.19}, poses.source()).empty());  // back, but the pose is from before
  poses.publish(0, at(0.0, 0.0, 1.0), 2.19);
  EXPECT_EQ(frames.compose(2.21, {{0}, 1.0, 2.19}, poses.source()).size(), 1u);
  EXPECT_EQ(frames.silent_frames(), 1u);
  live::ProjectionConfig replay = config_60hz();
  replay.silent_camera_s = 0.0;
  live::ProjectionFrames lockstep(replay);
  EXPECT_EQ(lockstep.compose(9.0, {{0}, 1.0, 2.00}, poses.source()).size(), 1u);
  // Nothing lit (driving): nothing to blank for silence either.
  EXPECT_TRUE(frames.compose(9.0, {{}, 1.0, 2.00}, poses.source()).empty());
  EXPECT_EQ(frames.silent_frames(), 1u);
}

TEST(ProjectionFrames, APoseNoNewerFrameConfirmedIsBlankedAfterThreeFrames) {
  // Issue 87: the camera goes on handing frames over while the tracker is busy (a rescue, a search): its
  // newest pose is drawn while it is at most 100 ms older than the newest frame, then blanked, each target
  // on its own, until a pose from a newer frame comes. With no camera watched, the frame's start is the
  // newest frame.
  ScriptedPoses poses;
  poses.publish(0, at(0.0, 0.0, 1.0), 3.00);
  poses.publish(1, at(0.2, 0.0, 1.0), 3.09);
  live::ProjectionFrames frames(config_60hz());
  EXPECT_EQ(frames.compose(3.10, {{0, 1}, 1.0, 3.095}, poses.source()).size(), 2u);
  const auto drawn = frames.compose(3.14, {{0, 1}, 1.0, 3.133}, poses.source());
  ASSERT_EQ(drawn.size(), 1u);
  EXPECT_EQ(drawn[0].target, 1);
  EXPECT_EQ(frames.unconfirmed_blanks(), 1u);
  poses.publish(0, at(0.0, 0.0, 1.0), 3.133);
  EXPECT_EQ(frames.compose(3.16, {{0, 1}, 1.0, 3.133}, poses.source()).size(), 2u);
  live::ProjectionConfig unwatched = config_60hz();
  unwatched.max_unconfirmed_s = 0.0;
  live::ProjectionFrames all(unwatched);
  EXPECT_EQ(all.compose(9.0, {{0, 1}, 1.0, 9.0}, poses.source()).size(), 2u);
  EXPECT_EQ(all.unconfirmed_blanks(), 0u);
}
