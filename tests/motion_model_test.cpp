// The motion model (issue 14): constant velocity predicted exactly, noise bounded, a still target never
// extrapolated, a sudden stop overshot for two frames at most, and the prediction's bounds.

#include "projbot/alignment/motion_model.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "projbot/config/angles.hpp"

namespace projbot::alignment {
namespace {

constexpr double kDt = 1.0 / 30.0;  // the depth camera's frame interval
constexpr double kDeg = projbot::config::radians(1.0);

Eigen::Matrix4d pose(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  return T;
}

Eigen::Matrix3d rot(const Eigen::Vector3d& w) {
  return w.norm() < 1e-15 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

// Constant twist: origin at p0 + v t, orientation exp(w t) R0 (both in the camera frame).
struct Trajectory {
  Eigen::Vector3d p0{0.1, -0.05, 1.5}, v{0.5, 0.0, 0.0}, w{0.0, 90.0 * kDeg, 0.0};
  Eigen::Matrix3d R0 = rot({0.3, 0.2, -0.4});
  Eigen::Matrix4d at(double t) const { return pose(p0 + v * t, rot(w * t) * R0); }
};

double translation_mm(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return 1000.0 * (a.topRightCorner<3, 1>() - b.topRightCorner<3, 1>()).norm();
}
double angle_deg(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return Eigen::AngleAxisd(a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>()).angle() / kDeg;
}

// A measured pose: the truth with Gaussian noise of the tracker's size.
Eigen::Matrix4d noisy(const Eigen::Matrix4d& T, std::mt19937& rng, double sigma_m, double sigma_rad) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d dp(n(rng), n(rng), n(rng)), dr(n(rng), n(rng), n(rng));
  return pose(T.topRightCorner<3, 1>() + sigma_m * dp, rot(sigma_rad * dr) * T.topLeftCorner<3, 3>());
}

TEST(MotionModel, ConstantVelocityIsPredictedExactly) {
  const Trajectory traj;
  MotionFilter f;
  for (int k = 0; k < 12; ++k) f.update(traj.at(k * kDt), k * kDt);
  const double t = 11 * kDt;
  ASSERT_TRUE(f.state().moving());
  for (const double h : {0.0, 0.016, 0.05, 0.1}) {
    EXPECT_LT(translation_mm(f.predict(t + h), traj.at(t + h)), 1e-6) << "horizon " << h;
    EXPECT_LT(angle_deg(f.predict(t + h), traj.at(t + h)), 1e-6) << "horizon " << h;
  }
  EXPECT_EQ(f.maneuvers(), 0);
}

TEST(MotionModel, NoisyMotionIsPredictedWithinTheNoise) {
  Trajectory traj;
  MotionFilter f;
  std::mt19937 rng(7);
  double sq_mm = 0.0, sq_deg = 0.0, without_mm = 0.0;
  int n = 0;
  for (int k = 0; k < 90; ++k) {  // 3 s at 0.5 m/s and 90 deg/s, tracker noise 0.5 mm and 0.1 degrees
    const double t = k * kDt;
    f.update(noisy(traj.at(t), rng, 0.0005, 0.1 * kDeg), t);
    if (k < 10) continue;  // settled
    const Eigen::Matrix4d truth = traj.at(t + 0.05);
    sq_mm += std::pow(translation_mm(f.predict(t + 0.05), truth), 2);
    sq_deg += std::pow(angle_deg(f.predict(t + 0.05), truth), 2);
    without_mm += translation_mm(traj.at(t), truth);
    ++n;
  }
  // 50 ms ahead: without prediction 25 mm and 4.5 degrees behind; with it, within a few noise sigmas.
  EXPECT_NEAR(without_mm / n, 25.0, 0.01);
  EXPECT_LT(std::sqrt(sq_mm / n), 4.0);
  EXPECT_LT(std::sqrt(sq_deg / n), 0.8);
}

TEST(MotionModel, StillTargetIsNeverExtrapolated) {
  const Eigen::Matrix4d still = Trajectory{}.at(0.0);
  MotionFilter f;
  std::mt19937 rng(3);
  int moving = 0;
  for (int k = 0; k < 900; ++k) {  // 30 s of a still target, tracker noise 0.5 mm and 0.1 degrees
    const Eigen::Matrix4d measured = noisy(still, rng, 0.0005, 0.1 * kDeg);
    f.update(measured, k * kDt);
    if (f.state().moving()) {
      ++moving;
      continue;
    }
    // Drawn exactly where it was measured: prediction adds nothing.
    EXPECT_EQ(f.predict(k * kDt + 0.05), measured) << "frame " << k;
  }
  EXPECT_EQ(moving, 0);
}

// A depth camera whose error is smooth (KinectNoiseConfig::fitted(), as the real PrimeSense's) moves the
// tracked pose of a target at rest by millimetres from frame to frame. The filter measures that noise
// from the poses (3 mm and 0.5 degrees here, 4 times the configured), never takes it for motion, and
// draws the target at the mean of its stillness window: nearer the truth than any one frame. A steady
// motion, however fast, measures no noise at all.
TEST(MotionModel, ANoisierTrackerIsMeasuredAndAveragedNotExtrapolated) {
  const Eigen::Matrix4d still = Trajectory{}.at(0.0);
  MotionFilter f;
  std::mt19937 rng(11);
  int moving = 0, n = 0;
  double drawn_sq = 0.0, measured_sq = 0.0;
  for (int k = 0; k < 300; ++k) {
    const Eigen::Matrix4d measured = noisy(still, rng, 0.003, 0.5 * kDeg);
    f.update(measured, k * kDt);
    if (k < 20) continue;  // the noise measured
    moving += f.state().moving() ? 1 : 0;
    drawn_sq += std::pow(translation_mm(f.predict(k * kDt + 0.05), still), 2);
    measured_sq += std::pow(translation_mm(measured, still), 2);
    ++n;
    EXPECT_GT(f.position_noise_m(), 0.0018) << "frame " << k;
    EXPECT_LT(f.position_noise_m(), 0.0045) << "frame " << k;
    EXPECT_GT(f.rotation_noise_rad(), 0.3 * kDeg) << "frame " << k;
  }
  EXPECT_LE(moving, n / 100);
  EXPECT_LT(std::sqrt(drawn_sq / n), 0.6 * std::sqrt(measured_sq / n));

  const Trajectory traj;
  MotionFilter steady;
  for (int k = 0; k < 30; ++k) steady.update(traj.at(k * kDt), k * kDt);
  EXPECT_NEAR(steady.position_noise_m(), steady.config().position_noise_m, 1e-12);
  EXPECT_NEAR(steady.rotation_noise_rad(), steady.config().rotation_noise_rad, 1e-12);
  EXPECT_TRUE(steady.state().moving());
}

// Issue 87: the first poses of a stop, and of every restart after a gap, under a sensor ten times noisier
// than the configured (the shop figure at 2 m under the fitted depth model: millimetres from frame to
// frame), are drawn where they were measured until the noise is measured: nothing extrapolated, so no frame
// is drawn beyond the poses' own scatter. The tracker's start (state, predict) may extrapolate from
// min_poses on: it is refined.
TEST(MotionModel, NothingIsDrawnAheadBeforeTheNoiseIsMeasured) {
  const Eigen::Matrix4d still = Trajectory{}.at(0.0);
  std::mt19937 rng(3);
  int tracker_moving = 0;
  for (int trial = 0; trial < 50; ++trial) {
    MotionFilter f;
    for (const double t0 : {0.0, 1.0}) {  // a stop, then the poses again after a gap (a busy worker)
      for (int k = 0; k < MotionFilter::kNoisePoses - 1; ++k) {
        const Eigen::Matrix4d measured = noisy(still, rng, 0.007, 0.3 * kDeg);
        f.update(measured, t0 + k * kDt);
        const MotionState drawn = f.drawn_state();
        EXPECT_FALSE(drawn.moving()) << "trial " << trial << ", pose " << k;
        EXPECT_EQ(predict_pose(drawn, t0 + k * kDt + 0.1), measured) << "trial " << trial << ", pose " << k;
        tracker_moving += f.state().moving() ? 1 : 0;
      }
    }
  }
  EXPECT_GT(tracker_moving, 0);  // what was drawn before: the configured 0.7 mm took this scatter for motion
  // Once the noise is measured, the drawn state is the filter's.
  const Trajectory traj;
  MotionFilter steady;
  for (int k = 0; k < MotionFilter::kNoisePoses; ++k) steady.update(traj.at(k * kDt), k * kDt);
  EXPECT_TRUE(steady.drawn_state().moving());
  EXPECT_EQ(steady.drawn_state().velocity_m_s, steady.state().velocity_m_s);
}

// A sudden stop at 0.5 m/s: the prediction may run on past the stop for two frames at most, and never
// farther than the old speed carries it over the horizon. With the default (quick) filter its own gain
// stops it; with a sluggish one (little process noise) the maneuver gate does.
class SuddenStop : public ::testing::TestWithParam<double> {};

TEST_P(SuddenStop, OvershootsForTwoFramesAtMost) {
  Trajectory traj;
  traj.w.setZero();
  MotionModelConfig cfg;
  cfg.accel_noise = GetParam();
  MotionFilter f(cfg);
  const double stop_t = 1.0;
  const Eigen::Matrix4d stopped = traj.at(stop_t);
  int overshooting = 0;
  double worst_mm = 0.0;
  for (int k = 0; k < 60; ++k) {
    const double t = k * kDt;
    f.update(traj.at(std::min(t, stop_t)), t);
    if (t < stop_t) continue;
    const double over_mm = translation_mm(f.predict(t + 0.05), stopped);
    worst_mm = std::max(worst_mm, over_mm);
    overshooting += over_mm > 0.5 ? 1 : 0;
  }
  EXPECT_LE(overshooting, 2);
  EXPECT_LE(worst_mm, 25.0 + 1e-6);  // never past where the old speed would have carried it in 50 ms
  if (cfg.accel_noise < 0.5) {
    EXPECT_GE(f.maneuvers(), 1);
  }
  EXPECT_FALSE(f.state().moving());
}

INSTANTIATE_TEST_SUITE_P(MotionModel, SuddenStop, ::testing::Values(1.0, 0.2));

// A start and a stop are not confirmed by the pose that shows them (the follower blanks it): confirmed
// again once a pose agrees with the motion restarted from it, within three poses; a steady motion and a
// still target are confirmed throughout.
TEST(MotionModel, AStartOrAStopIsConfirmedOnlyByTheNextPoses) {
  Trajectory traj;
  const double start_t = 0.5, stop_t = 1.2;
  const auto truth = [&](double t) { return traj.at(std::clamp(t, start_t, stop_t) - start_t); };
  MotionFilter f;
  std::vector<int> unconfirmed;
  for (int k = 0; k < 60; ++k) {
    f.update(truth(k * kDt), k * kDt);
    if (!f.confirmed()) unconfirmed.push_back(k);
  }
  ASSERT_FALSE(unconfirmed.empty());
  const int start_k = static_cast<int>(std::ceil(start_t / kDt)), stop_k = static_cast<int>(std::ceil(stop_t / kDt));
  for (const int k : unconfirmed) {
    const bool near_start = k >= start_k && k <= start_k + 3, near_stop = k >= stop_k && k <= stop_k + 3;
    EXPECT_TRUE(near_start || near_stop) << "pose " << k << " unconfirmed away from the start and the stop";
  }
  EXPECT_TRUE(f.confirmed());
  EXPECT_FALSE(f.state().moving());
}

// A real sensor's noise (the fitted depth model's: about 1.7 mm and 0.8 degrees per pose, measured on
// the twin's display tour): a target at rest, 20 runs of 3 s. Extrapolated at all in under 1 % of the
// poses, and never by more than 10 mm over a 0.1 s horizon. With the window's test alone and a rate
// free to follow the noise (process noise 1) it was extrapolated by up to 20 mm (and the twin's poses,
// less Gaussian than these, were drawn up to 52 mm off).
TEST(MotionModel, ARealSensorsNoiseAtRestIsNotExtrapolated) {
  const Eigen::Matrix4d still = Trajectory{}.at(0.0);
  int moving = 0, n = 0;
  double worst_mm = 0.0;
  for (int run = 0; run < 20; ++run) {
    MotionFilter f;
    std::mt19937 rng(100 + run);
    for (int k = 0; k < 90; ++k) {
      f.update(noisy(still, rng, 0.0017, 0.8 * kDeg), k * kDt);
      const MotionState drawn = f.drawn_state();
      moving += drawn.moving() ? 1 : 0;
      ++n;
      worst_mm = std::max(worst_mm, 1000.0 * drawn.velocity_m_s.norm() * 0.1);
      worst_mm = std::max(worst_mm, 150.0 * drawn.angular_velocity_rad_s.norm() * 0.1);  // at 0.15 m from the origin
    }
  }
  EXPECT_LT(moving, n / 100) << moving << " of " << n;
  EXPECT_LT(worst_mm, 10.0);
}

TEST(MotionModel, PredictionIsBoundedInTimeAndSpeed) {
  Trajectory traj;
  traj.v = {3.0, 0.0, 0.0};  // faster than anyone carries a target: clamped to 2 m/s
  traj.w.setZero();
  MotionFilter f;
  for (int k = 0; k < 5; ++k) f.update(traj.at(k * kDt), k * kDt);
  const double t = 4 * kDt;
  EXPECT_NEAR(f.state().velocity_m_s.norm(), 2.0, 1e-9);
  // A second ahead is held at the 0.1 s horizon: 2 m/s x 0.1 s = 200 mm past the newest pose.
  EXPECT_NEAR(translation_mm(f.predict(t + 1.0), traj.at(t)), 200.0, 1e-6);
  // The past is not extrapolated backwards.
  EXPECT_EQ(f.predict(t - 0.5), f.state().T);
}

// A target lifted and put down 18 cm away within one frame interval (5.4 m/s: more than twice the
// speed anyone carries it at) jumped: drawn where it is measured, not extrapolated from the jump; a
// steady 3 m/s (above) is a motion, clamped.
TEST(MotionModel, AJumpStartsAgainFromTheNewPose) {
  const Trajectory traj;
  MotionFilter f;
  for (int k = 0; k < 6; ++k) f.update(traj.at(k * kDt), k * kDt);
  ASSERT_TRUE(f.state().moving());
  Eigen::Matrix4d put_down = traj.at(6 * kDt);
  put_down.topRightCorner<3, 1>() += Eigen::Vector3d(0.15, 0.1, 0.0);
  for (int k = 6; k < 10; ++k) {
    f.update(put_down, k * kDt);
    EXPECT_FALSE(f.state().moving()) << k;
    EXPECT_EQ(f.predict(k * kDt + 0.05), put_down) << k;
  }
  EXPECT_EQ(f.jumps(), 1);
  // A turn of 30 degrees in one frame interval (900 deg/s) is a jump as well.
  Eigen::Matrix4d turned = put_down;
  turned.topLeftCorner<3, 3>() = rot({0.0, 30.0 * kDeg, 0.0}) * put_down.topLeftCorner<3, 3>();
  f.update(turned, 10 * kDt);
  EXPECT_EQ(f.jumps(), 2);
  EXPECT_FALSE(f.state().moving());
}

TEST(MotionModel, GapsAndTimeGoingBackRestartTheFilter) {
  const Trajectory traj;
  MotionFilter f;
  for (int k = 0; k < 5; ++k) f.update(traj.at(k * kDt), k * kDt);
  ASSERT_TRUE(f.state().moving());
  f.update(traj.at(1.0), 1.0);  // 0.87 s without a pose: nothing known about the motion now
  EXPECT_FALSE(f.state().moving());
  EXPECT_EQ(f.state().T, traj.at(1.0));
  f.update(traj.at(1.0 + kDt), 1.0 + kDt);
  EXPECT_FALSE(f.state().moving());  // two poses after a restart are not yet a motion (min_poses)...
  f.update(traj.at(1.0 + 2 * kDt), 1.0 + 2 * kDt);
  EXPECT_TRUE(f.state().moving());  // ...three are
  f.update(traj.at(0.5), 0.5);      // a pose from before the newest: start again from it
  EXPECT_FALSE(f.state().moving());
  f.reset();
  EXPECT_EQ(f.state().T, Eigen::Matrix4d::Identity());
}

}  // namespace
}  // namespace projbot::alignment
