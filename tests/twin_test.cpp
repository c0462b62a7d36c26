// The digital twin: the projection-error measurement on hand-computed cases, scene checks, and a short
// deterministic tour on the shipped demo scene.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/session/session.hpp"
#include "projbot/twin/appearance.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/raycast.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/tour.hpp"
#include "projbot/twin/world.hpp"

namespace {

using projbot::twin::MeshRaycaster;
using projbot::twin::PlacedMesh;

Eigen::Matrix4d translation(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
  return T;
}

// A 1000x1000 projector with f = 1000 px and the principal point on a pixel centre, and a 1 m square
// slab whose near face (model z = 0) stands 1 m in front of it.
class MarkerErrorTest : public ::testing::Test {
 protected:
  projbot::config::ProjectorConfig k_{{1000, 1000, 1000.0, 1000.0, 500.0, 500.0}, 0.1, 10.0};
  MeshRaycaster slab_{projbot::assets::make_box({-0.5, -0.5, 0.0}, {0.5, 0.5, 0.02}, {1, 1, 1, 1})};
  Eigen::Matrix4d T_true_ = translation(0, 0, 1.0);
  Eigen::Vector3d marker_{0.1, 0.0, 0.0};
  std::vector<PlacedMesh> scene_{{&slab_, T_true_}};

  projbot::twin::MarkerError measure(const Eigen::Matrix4d& T_est) const {
    return projbot::twin::measure_marker(k_, k_, T_est, T_true_, marker_, scene_);
  }
};

// A calibration that put the principal point 4 px right of the truth: the content is drawn 4 px right of
// where the lens sends the marker's ray, so at 1 m with f = 1000 px it lands 4 mm off.
TEST_F(MarkerErrorTest, MiscalibratedPrincipalPointShiftsTheLight) {
  projbot::config::ProjectorConfig believed = k_;
  believed.cx_px += 4.0;
  const auto e = projbot::twin::measure_marker(believed, k_, T_true_, T_true_, marker_, scene_);
  EXPECT_DOUBLE_EQ(e.pixel.x(), 604.0);
  EXPECT_TRUE(e.landed);
  EXPECT_NEAR(e.error_mm, 4.0, 1e-6);
}

// A projector with a barrel lens (k1 -0.2): drawn through the same lens (the renderer's pre-distortion),
// the marker's light lands within the pixel's rounding; drawn as a pinhole, the lens throws it 2-3 cm off
// near the image's corner (the marker 0.5 m off the axis at 1 m: the lens pulls its ray in by 5 %).
TEST_F(MarkerErrorTest, TheProjectorsLensMustBeDrawnToLandOnTheMarker) {
  projbot::config::ProjectorConfig lens = k_;
  lens.distortion = {-0.2, 0.0, 0.0, 0.0, 0.0};
  const Eigen::Vector3d corner(0.4, 0.3, 0.0);
  const auto drawn = projbot::twin::measure_marker(lens, lens, T_true_, T_true_, corner, scene_);
  EXPECT_TRUE(drawn.landed);
  EXPECT_LT(drawn.error_mm, 0.75);  // half a pixel's diagonal at 1 m, f = 1000 px
  const Eigen::Vector2d expected = lens.project_lit((T_true_ * corner.homogeneous()).head<3>());
  EXPECT_LE((drawn.pixel - expected).cwiseAbs().maxCoeff(), 0.5);
  const auto pinhole = projbot::twin::measure_marker(k_, lens, T_true_, T_true_, corner, scene_);
  EXPECT_TRUE(pinhole.landed);
  EXPECT_GT(pinhole.error_mm, 20.0);
  EXPECT_LT(pinhole.error_mm, 30.0);
}

// The slab seen from the projector: its face-on centre and a point well inside are measurable; the
// same face turned 85 degrees away from the projector's ray, or a point 1 mm from the slab's edge (a
// ray 3 mm beside it passes the slab), are edge-on; turned 60 degrees it is still measurable.
TEST_F(MarkerErrorTest, MarkersTheProjectorSeesEdgeOnAreNotMeasured) {
  using projbot::twin::seen_edge_on;
  EXPECT_FALSE(seen_edge_on(scene_, {0.0, 0.0, 1.0}));
  EXPECT_FALSE(seen_edge_on(scene_, {0.1, -0.2, 1.0}));
  EXPECT_TRUE(seen_edge_on(scene_, {0.499, 0.0, 1.0}));
  const auto turned = [&](double deg) {  // the slab turned about its vertical axis through its centre
    Eigen::Matrix4d T = T_true_;
    T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    return std::vector<PlacedMesh>{{&slab_, T}};
  };
  EXPECT_FALSE(seen_edge_on(turned(60.0), {0.0, 0.0, 1.0}));
  EXPECT_TRUE(seen_edge_on(turned(85.0), {0.0, 0.0, 1.0}));
  EXPECT_TRUE(seen_edge_on({}, {0.0, 0.0, 1.0}));  // nothing there at all
}

TEST_F(MarkerErrorTest, ExactPoseLandsOnTheMarker) {
  const auto e = measure(T_true_);
  EXPECT_TRUE(e.in_image);
  EXPECT_TRUE(e.landed);
  EXPECT_DOUBLE_EQ(e.pixel.x(), 600.0);  // u = 1000 * 0.1 / 1 + 500
  EXPECT_DOUBLE_EQ(e.pixel.y(), 500.0);
  EXPECT_NEAR(e.error_mm, 0.0, 1e-9);
}

TEST_F(MarkerErrorTest, Sideways5mmIs5mm) {
  const auto e = measure(translation(0.005, 0, 1.0));
  EXPECT_DOUBLE_EQ(e.pixel.x(), 605.0);
  EXPECT_NEAR(e.error_mm, 5.0, 1e-6);
}

TEST_F(MarkerErrorTest, DepthErrorShowsAsTheRaysShift) {
  // Estimated 10 cm too far: the content is drawn at u = 1000 * 0.1 / 1.1 + 500 = 590.9, shown by pixel
  // 591, whose ray meets the true surface at x = 0.091 m: 9 mm from the marker.
  const auto e = measure(translation(0, 0, 1.1));
  EXPECT_DOUBLE_EQ(e.pixel.x(), 591.0);
  EXPECT_TRUE(e.landed);
  EXPECT_NEAR(e.error_mm, 9.0, 1e-6);
}

TEST_F(MarkerErrorTest, PixelOutsideTheImageMeasuresTheMissToTheRay) {
  // Drawn at (1.1, 0, 1): u = 1600, off the image. Distance from (0.1, 0, 1) to the ray through (1.1, 0, 1).
  const auto e = measure(translation(1.0, 0, 1.0));
  EXPECT_FALSE(e.in_image);
  EXPECT_FALSE(e.landed);
  const Eigen::Vector3d d = Eigen::Vector3d(1.1, 0, 1).normalized(), t(0.1, 0, 1);
  EXPECT_NEAR(e.error_mm, 1000.0 * (t - t.dot(d) * d).norm(), 1e-6);
  EXPECT_NEAR(e.error_mm, 672.7, 0.1);
}

TEST_F(MarkerErrorTest, AnOccluderCatchesTheLight) {
  // A small box halfway along the marker's ray: the light lands on it, 0.5 m short of the marker.
  const MeshRaycaster blocker(projbot::assets::make_box({-0.02, -0.02, 0.0}, {0.02, 0.02, 0.02}, {1, 1, 1, 1}));
  scene_.push_back({&blocker, translation(0.05, 0.0, 0.5)});
  const auto e = measure(T_true_);
  EXPECT_TRUE(e.landed);
  EXPECT_NEAR(e.error_mm, 1000.0 * std::sqrt(0.05 * 0.05 + 0.5 * 0.5), 1e-6);
}

TEST(MeshRaycasterTest, NearestSurfacePointAndRays) {
  const MeshRaycaster box(projbot::assets::make_box({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}, {1, 1, 1, 1}));
  // Vertices are floats: 1e-7 m tolerances.
  EXPECT_LT((box.closest_point({0.0, 0.0, -0.3}) - Eigen::Vector3d(0, 0, -0.1)).norm(), 1e-7);
  EXPECT_LT((box.closest_point({0.3, 0.3, 0.0}) - Eigen::Vector3d(0.1, 0.1, 0.0)).norm(), 1e-7);
  const auto hit = box.cast({0, 0, -1}, {0, 0, 1});
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(*hit, 0.9, 1e-7);
  EXPECT_FALSE(box.cast({0, 0, -1}, {0, 1, 0}).has_value());
  EXPECT_FALSE(box.cast({0, 0, -1}, {0, 0, -1}).has_value());  // behind the origin
}

const std::string kAssets = PROJBOT_ASSET_DIR;

std::string demo_tour_text() {
  std::ifstream in(kAssets + "/scenes/tour.yaml");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

projbot::config::Scene demo_with(const std::string& from, const std::string& to) {
  std::string text = demo_tour_text();
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("test: '" + from + "' not in the demo tour");
  text.replace(at, from.size(), to);
  return projbot::config::parse_scene(text, kAssets + "/scenes/tour.yaml");
}

std::string twin_error(const projbot::config::Scene& scene) {
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  try {
    projbot::twin::Twin twin(scene, {}, renderer);
  } catch (const projbot::twin::TwinError& e) {
    return e.what();
  }
  return "";
}

TEST(TwinSceneTest, BadToursAreNamed) {
  using projbot::config::ConfigError;
  const auto config_error = [](const std::string& from, const std::string& to) {
    try {
      demo_with(from, to);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(config_error("visits: [duck, box", "visits: [duck, cat").find("tour.visits[1]: no target named 'cat'"),
            std::string::npos);
  EXPECT_NE(config_error("stop: [3.0, 1.8, 90]", "stop: [3.0, 1.8]").find("targets[0].stop: expected a list of 3 numbers"),
            std::string::npos);
  EXPECT_NE(config_error("motion: {visit: 2,", "motion: {visit: 0,").find("targets[1].motion.visit: must be >= 1"),
            std::string::npos);
  EXPECT_NE(config_error("slip_scale: 0.01", "slip_scale: -0.01").find("robot.drift.slip_scale: must be 0..0.5"),
            std::string::npos);
  EXPECT_NE(
      config_error("stays: true}", "stays: true, removed: true}").find("targets[1].motion: a removed target cannot also stay"),
      std::string::npos);
  EXPECT_NE(config_error("stays: true}", "stays: maybe}").find("targets[1].motion.stays"), std::string::npos);
  EXPECT_NE(config_error("stays: true}", "stays: true, profile: jerky}")
                .find("targets[1].motion.profile: must be smooth, constant or accelerate, not 'jerky'"),
            std::string::npos);
  EXPECT_NE(
      config_error("motion: {visit: 2, start_s: 0.5, duration_s: 2.0, translation: [0.08, -0.06, 0.0], rpy_deg: [0, 0, 15], "
                   "stays: true}",
                   "motion: [{visit: 1}, {visit: 1}]")
          .find("targets[1].motion[1]: visit 1 already has a motion"),
      std::string::npos);
  EXPECT_NE(config_error("far: 10}", "far: 10, refresh_hz: 0}").find("projector.refresh_hz: must be 1..1000 Hz"),
            std::string::npos);
  EXPECT_NE(config_error("far: 10}", "far: 10, input_lag_ms: -1}").find("projector.input_lag_ms: must be 0..1000 ms"),
            std::string::npos);
  EXPECT_EQ(demo_with("rpy_deg: [0, 0, 15], stays: true}", "rpy_deg: [0, 0, 15], profile: accelerate}")
                .targets[1]
                .motions.at(0)
                .profile,
            projbot::config::MotionProfile::accelerate);
  EXPECT_NE(config_error("    scale: 0.3\n", "    scale: 0.3\n    present: 2\n").find("targets[1].present"), std::string::npos);
  EXPECT_FALSE(demo_with("    scale: 0.3\n", "    scale: 0.3\n    present: false\n").targets[1].present);
  // Where the robot can stand, and what a target needs.
  EXPECT_NE(config_error("stop: [3.0, 1.8, 90]", "stop: [9.0, 1.8, 90]")
                .find("targets[0].stop: the robot's stop for 'duck' lies outside the room"),
            std::string::npos);
  EXPECT_NE(config_error("stop: [3.0, 1.8, 90]", "stop: [0.3, 3.0, 90]")
                .find("the robot's stop for 'duck' lies inside room.obstacles[2]"),
            std::string::npos);
  EXPECT_NE(config_error("start: [1.0, 1.0, 0]", "start: [7.0, 0.5, 0]")
                .find("robot.start: the robot's start lies inside room.obstacles[1]"),
            std::string::npos);
  EXPECT_NE(config_error("    scale: 0.3\n", "    scale: 1e30\n").find("targets[1].scale: must be 0.0001..10000"),
            std::string::npos);
  EXPECT_NE(config_error("    world_pose: {translation: [3.0, 3.2, 0.9], rpy_deg: [90, 0, -20]}\n", "")
                .find("targets[0]: needs a pose (where it stands in the projector frame) or a world_pose"),
            std::string::npos);
  EXPECT_NE(config_error("  width: 8\n", "  width: 0\n").find("room: width and depth must be 0.5..200 m"), std::string::npos);
  // A marker 5 cm off the Duck's surface: the twin names it and where the surface is.
  const std::string off = twin_error(demo_with("[-0.0024, -0.0389, 0.1421]", "[-0.0024, -0.0389, 0.1921]"));
  EXPECT_NE(off.find("target 'duck' marker 0 lies"), std::string::npos) << off;
  EXPECT_NE(off.find("the nearest surface point is"), std::string::npos) << off;
  const std::string no_tour = twin_error(demo_with("tour:\n  visits: [duck, box, duck, box, duck, box]", ""));
  EXPECT_NE(no_tour.find("needs a 'tour: {visits: [...]}' section"), std::string::npos) << no_tour;
}

// The demo tour's first visits (the box is moved on its second and left there), seed 3.
projbot::twin::TourReport short_demo_tour(projbot::twin::TourMode mode, int visits) {
  projbot::twin::TourOptions o;
  o.mode = mode;
  o.visits = visits;
  o.seed = 3;
  o.dwell_s = 3.0;
  return projbot::twin::run_tour(projbot::config::load_scene(kAssets + "/scenes/tour.yaml"), o);
}

// Localisation keeps every visit within the 3 mm, also the box's third, found 10 cm and
// 15 degrees away from its surveyed pose.
TEST(TourTest, ShortLocalizedTourStaysWithin3mm) {
  const auto report = short_demo_tour(projbot::twin::TourMode::localized, 6);
  ASSERT_EQ(report.visits.size(), 6U);
  for (const auto& v : report.visits) {
    SCOPED_TRACE(v.target + " visit " + std::to_string(v.target_visit));
    EXPECT_TRUE(v.projected);
    EXPECT_EQ(v.markers.size(), v.target == "duck" ? 5U : 6U);
    for (const auto& m : v.markers) EXPECT_TRUE(m.landed);
    EXPECT_LT(v.mean_mm, 3.0);
    EXPECT_LT(v.max_mm, 5.0);
    EXPECT_LT(v.base_error_cm, 2.0);  // the robot issue's bound on localisation
    if (v.visit == 6) {
      EXPECT_GT(v.guess_error_cm, 8.0);  // the box was left moved
    } else {
      EXPECT_LT(v.guess_error_cm, 2.0);
    }
    // The report's true pose is the twin's: markers under it land within a pixel's rounding.
    EXPECT_LT(projbot::alignment::translation_norm_m(projbot::alignment::rigid_inverse(v.T_projector_target_true) *
                                                     v.T_projector_target_estimated),
              0.005);
  }
  EXPECT_EQ(report.visits[3].target, "box");
  EXPECT_EQ(report.visits[5].target, "box");
  EXPECT_TRUE(report.visits[3].moved);
  // Aligned once, the moved box is not followed: its content stays where the box was.
  EXPECT_LT(report.visits[3].reconverge_s, 0.0);
  EXPECT_GT(report.visits[3].max_mm_moving, 50.0);
}

// The paper's experiment as it was (assets/scenes/paper.yaml: nothing moved, half the demo's drift) in
// the paper's set-up: odometry alone and one plain point-to-point ICP per stop. Seed 1, three visits per
// target. The errors are the paper's order (mm to cm, theirs 4-19 mm) and grow with the drift.
TEST(TourTest, OdometryModeReproducesThePapersGrowth) {
  projbot::twin::TourOptions o;
  o.mode = projbot::twin::TourMode::odometry;
  o.seed = 1;
  const auto report = projbot::twin::run_tour(projbot::config::load_scene(kAssets + "/scenes/paper.yaml"), o);
  ASSERT_EQ(report.visits.size(), 6U);
  for (const auto& v : report.visits) {
    SCOPED_TRACE(v.target + " visit " + std::to_string(v.target_visit));
    EXPECT_TRUE(v.projected);   // the paper projected whatever ICP gave
    EXPECT_GT(v.mean_mm, 3.0);  // above what localisation and our acquisition keep (< 3 mm, test above)
    EXPECT_LT(v.mean_mm, 100.0);
    EXPECT_FALSE(v.moved);
  }
  for (const std::string target : {"duck", "box"}) {
    SCOPED_TRACE(target);
    std::vector<const projbot::twin::VisitReport*> visits;
    for (const auto& v : report.visits)
      if (v.target == target) visits.push_back(&v);
    ASSERT_EQ(visits.size(), 3U);
    // Odometry drifts: the robot believes itself further off at each visit, so ICP starts worse...
    EXPECT_GT(visits[2]->odometry_error_cm, visits[0]->odometry_error_cm);
    EXPECT_GT(visits[2]->guess_error_cm, visits[0]->guess_error_cm + 1.0);
    // ...and ends worse: the third projection is the worst of the three, as in the paper's Table 1.
    EXPECT_GT(visits[2]->mean_mm, visits[0]->mean_mm);
    EXPECT_GT(visits[2]->mean_mm, visits[1]->mean_mm);
  }
}

// The tracker follows the box while it is moved 10 cm and 15 degrees, back within 3 mm within 0.5 s.
TEST(TourTest, TrackingFollowsTheMovedTarget) {
  const auto report = short_demo_tour(projbot::twin::TourMode::tracking, 4);
  const auto& moved = report.visits[3];
  ASSERT_TRUE(moved.moved);
  EXPECT_EQ(moved.timeline.size(), 180U);  // 3 s of projector frames at 60 Hz
  EXPECT_GE(moved.reconverge_s, 0.0);
  EXPECT_LE(moved.reconverge_s, 0.5);
  EXPECT_LT(moved.max_mm_moving, 15.0);
  EXPECT_LT(moved.timeline.back().mean_mm, 3.0);
  for (const auto& s : moved.timeline) EXPECT_TRUE(s.shown);
}

// Tracking tours on a fixed simulated processing time (capture to pose, 20 ms), so what they measure
// does not depend on how busy the machine running the tests is.
projbot::twin::TourReport tracking_tour(const projbot::config::Scene& scene, int visits, double dwell_s, bool predict = true) {
  projbot::twin::TourOptions o;
  o.mode = projbot::twin::TourMode::tracking;
  o.visits = visits;
  o.dwell_s = dwell_s;
  o.predict = predict;
  o.processing_ms = 20.0;
  return projbot::twin::run_tour(scene, o);
}

// Targets moved at human speed (assets/scenes/motion.yaml): the duck still, the box carried at 0.5 m/s,
// the duck carried at 0.5 m/s while turned at 90 deg/s, the box at 1 m/s. Each projector frame's error
// is measured at its display time (about 50 ms after the capture its pose came from).
TEST(TourTest, PredictionKeepsMovingTargetsWithinTheGoal) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/motion.yaml");
  const auto off = tracking_tour(scene, 4, 2.0, false);
  const auto on = tracking_tour(scene, 4, 2.0, true);
  ASSERT_EQ(off.visits.size(), 4U);
  ASSERT_EQ(on.visits.size(), 4U);
  // Still: prediction adds nothing (the goal: at most 0.1 mm).
  EXPECT_FALSE(on.visits[0].moved);
  EXPECT_NEAR(on.visits[0].still_mean_mm, off.visits[0].still_mean_mm, 0.1);
  for (const int i : {1, 2}) {
    SCOPED_TRACE(on.visits[i].target);
    ASSERT_TRUE(on.visits[i].moved);
    EXPECT_GT(off.visits[i].moving_mean_mm, 10.0);  // without prediction the content trails the target
    EXPECT_LT(on.visits[i].moving_mean_mm, 5.0);    // the goal at 0.5 m/s and 90 deg/s
    EXPECT_EQ(on.visits[i].moving_blank_frames, 0);
    EXPECT_LT(on.visits[i].timeline.back().mean_mm, 3.0);
    EXPECT_NEAR(on.visits[i].age_p50_ms, 50.0, 1.0);  // 20 ms processing, the next frame, one refresh
  }
  EXPECT_LT(on.visits[1].moving_p95_mm, 10.0);
  // 1 m/s, 3.3 cm between camera frames: followed without a blank frame (the tracker starts from the
  // prediction). The start is sudden: for the first frames the newest pose is from before it, and the
  // light of the edge markers falls past the box onto the wall (about 200 mm on two frames), which
  // weighs on the mean; the median frame is on the object.
  EXPECT_EQ(on.visits[3].target, "box");
  EXPECT_EQ(on.visits[3].moving_blank_frames, 0);
  // ...and within the tracker's first pass (its coarsest level reaches 10 cm): with 4 cm there the
  // start's frame needed the wider second pass, twice the time.
  EXPECT_EQ(on.visits[3].second_pass_frames, 0);
  EXPECT_EQ(off.visits[3].second_pass_frames, 0);
  EXPECT_LT(on.visits[3].moving_mean_mm, 20.0);
  std::vector<double> moving;
  for (const auto& x : on.visits[3].timeline)
    if (x.moving) moving.push_back(x.mean_mm);
  ASSERT_GT(moving.size(), 30U);
  std::nth_element(moving.begin(), moving.begin() + moving.size() / 2, moving.end());
  EXPECT_LT(moving[moving.size() / 2], 3.0);
  EXPECT_LT(on.visits[3].timeline.back().mean_mm, 3.0);
}

// `scene` (motion.yaml) cut to one visit of the duck, with `motion` (moved to that visit) its only one.
projbot::config::Scene duck_alone(projbot::config::Scene scene, projbot::config::TargetMotion motion) {
  motion.visit = 1;
  scene.targets.at(static_cast<std::size_t>(scene.target_index("duck"))).motions = {motion};
  scene.visits = {"duck"};
  return scene;
}

// The duck's fourth visit in motion.yaml: turned and slid from rest at constant acceleration to 1 m/s
// and 180 deg/s (3.3 cm and 6 degrees between camera frames at the end), then let go. Run alone (the
// scene's tour cut to that visit): followed on every frame within the tracker's first pass, and with
// prediction within 8 mm mean (20 ms processing; the 0.5 m/s goal is 5).
TEST(TourTest, ATargetTurnedAt180DegreesPerSecondIsFollowed) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/motion.yaml");
  const auto* fast = scene.targets.at(static_cast<std::size_t>(scene.target_index("duck"))).motion_on(4);
  ASSERT_NE(fast, nullptr);
  const auto on = tracking_tour(duck_alone(scene, *fast), 1, 2.0, true);
  ASSERT_EQ(on.visits.size(), 1U);
  const auto& v = on.visits[0];
  ASSERT_TRUE(v.moved);
  EXPECT_EQ(v.moving_blank_frames, 0);
  EXPECT_EQ(v.second_pass_frames, 0);
  EXPECT_LT(v.moving_mean_mm, 8.0);
  EXPECT_LT(v.moving_p95_mm, 15.0);
  EXPECT_LT(v.timeline.back().mean_mm, 3.0);
}

// Faster than tracking follows (issue 14: recovery within 0.5 s): the duck lifted and put down 18 cm
// away and turned 30 degrees within 40 ms. The worker finds it again on the same or the next frames
// (the wider pass, then one ICP), the motion filter starts again from where it is instead of
// extrapolating the jump, and the error is back under 3 mm for good within half a second.
TEST(TourTest, ATargetMovedFasterThanTrackingFollowsIsFoundAgainWithinHalfASecond) {
  projbot::config::TargetMotion jump;
  jump.start_s = 0.5;
  jump.duration_s = 0.04;
  jump.translation_m = {0.15, 0.1, 0.0};
  jump.rpy_deg = {0.0, 0.0, 30.0};
  jump.profile = projbot::config::MotionProfile::constant;
  const auto on = tracking_tour(duck_alone(projbot::config::load_scene(kAssets + "/scenes/motion.yaml"), jump), 1, 2.0, true);
  ASSERT_EQ(on.visits.size(), 1U);
  const auto& v = on.visits[0];
  ASSERT_TRUE(v.moved);
  EXPECT_GT(v.reconverge_s, 0.0);  // the jump itself is not followed: the error left 3 mm...
  EXPECT_LT(v.reconverge_s, 0.5);  // ...and was back within half a second
  EXPECT_TRUE(v.timeline.back().shown);
  EXPECT_LT(v.timeline.back().mean_mm, 1.5);
}

// A target that is not there (present: false) is searched for within the follower's budget and never
// lit; the target before it is tracked on every frame of its dwell (counted in simulated time).
TEST(TourTest, AnAbsentTargetIsNeverLitAndSearchedWithinItsBudget) {
  const auto scene = demo_with("    model: ../models/BoxTextured/BoxTextured.gltf\n",
                               "    model: ../models/BoxTextured/BoxTextured.gltf\n    present: false\n");
  const auto report = tracking_tour(scene, 2, 1.0);
  ASSERT_EQ(report.visits.size(), 2U);
  const auto& duck = report.visits[0];
  const auto& box = report.visits[1];
  EXPECT_TRUE(duck.target_present);
  EXPECT_EQ(duck.lit_frames, 61);  // arrival + 60 projector frames: tracked on every one
  EXPECT_DOUBLE_EQ(duck.first_light_s, 0.0);
  EXPECT_FALSE(box.target_present);
  EXPECT_EQ(box.lit_frames, 0);
  EXPECT_LT(box.first_light_s, 0.0);
  for (const auto& t : box.timeline) EXPECT_FALSE(t.shown);
  // The spacing {0, 3, 9, 15, 30} allows attempts at arrival and on frames 1, 5 and 15 of 30 at most;
  // the duty cycle (a quarter of the worker's time) may space them further. Every frame the worker
  // took is either an attempt or a wait; those that came while it was busy were dropped.
  EXPECT_GE(box.search.attempts, 1);
  EXPECT_LE(box.search.attempts, 4);
  EXPECT_EQ(box.search.attempts + box.search.frames_waited, box.tracked_frames + 1);
  EXPECT_EQ(box.tracked_frames + box.dropped_frames, 30);
}

// Someone carries the box away mid-visit: the light goes out within 100 ms of the first depth frame
// that shows it gone, and its next visit finds it absent and never lights it.
TEST(TourTest, ARemovedTargetIsBlankedWithin100ms) {
  const auto scene = demo_with(
      "motion: {visit: 2, start_s: 0.5, duration_s: 2.0, translation: [0.08, -0.06, 0.0], rpy_deg: [0, 0, 15], stays: true}",
      "motion: {visit: 1, start_s: 0.5, duration_s: 0.2, removed: true}");
  const auto report = tracking_tour(scene, 4, 1.5);
  ASSERT_EQ(report.visits.size(), 4U);
  const auto& removed = report.visits[1];
  ASSERT_EQ(removed.target, "box");
  EXPECT_TRUE(removed.projected);
  EXPECT_GE(removed.blank_after_removal_s, 0.0);
  EXPECT_LE(removed.blank_after_removal_s, 0.1);
  // Lit at arrival and on the projector frames shown until the blank shows (0.7 s plus at most 0.1 s,
  // at 60 Hz: 42 to 48 frames).
  EXPECT_GE(removed.lit_frames, 42);
  EXPECT_LE(removed.lit_frames, 49);
  EXPECT_FALSE(report.visits[3].target_present);
  EXPECT_EQ(report.visits[3].lit_frames, 0);
}

}  // namespace

namespace {

// The twin's clock on a hand-computed case: a still duck, 20 ms from capture to pose, a 60 Hz projector
// with 30 ms of input lag. Projector frame j starts at j/60 s and is lit at j/60 + 1/60 + 0.030 s; it
// draws the newest pose ready by its start, from the capture at k/30 s with k/30 + 0.020 <= j/60.
TEST(TourTest, EachProjectorFrameIsMeasuredAtItsDisplayTime) {
  auto scene = demo_with("far: 10}", "far: 10, input_lag_ms: 30}");
  const auto report = tracking_tour(scene, 1, 0.5);
  ASSERT_EQ(report.visits.size(), 1U);
  const auto& timeline = report.visits[0].timeline;
  ASSERT_EQ(timeline.size(), 30U);  // 0.5 s at 60 Hz
  for (std::size_t i = 0; i < timeline.size(); ++i) {
    const double start = static_cast<double>(i + 1) / 60.0;
    EXPECT_NEAR(timeline[i].t_s, start + 1.0 / 60.0 + 0.030, 1e-9) << i;
    const double capture = std::max(0.0, std::floor((start - 0.020 + 1e-9) * 30.0) / 30.0);  // 0: the arrival's pose
    EXPECT_NEAR(timeline[i].age_ms, 1000.0 * (timeline[i].t_s - capture), 1e-6) << i;
    EXPECT_TRUE(timeline[i].shown);
    EXPECT_LT(timeline[i].mean_mm, 3.0);
  }
}

}  // namespace

namespace {

// The depth camera's reading at the image centre, looking from `eye` towards `at` (world frame).
double centre_depth_m(projbot::twin::Twin& twin, const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
  // Camera frame: z forward, x right, y down.
  const Eigen::Vector3d z = (at - eye).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix4d T_world_camera = Eigen::Matrix4d::Identity();
  T_world_camera.block<3, 1>(0, 0) = x;
  T_world_camera.block<3, 1>(0, 1) = y;
  T_world_camera.block<3, 1>(0, 2) = z;
  T_world_camera.topRightCorner<3, 1>() = eye;
  const auto depth = twin.capture(T_world_camera, 1);
  return depth.at(depth.width / 2, depth.height / 2);
}

}  // namespace

// The room stands in the depth images: walls room.wall_height high, obstacles as blocks, box props,
// supports as given.
TEST(TwinRoomTest, WallsPropsAndSupportsAreSolid) {
  std::ifstream in(kAssets + "/scenes/tour.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("  obstacles:"), 12, "  wall_height: 2.0\n  obstacles:");
  yaml.replace(yaml.find("    stop: [5.2, 2.2, 80]"), 24, "    stop: [5.2, 2.2, 80]\n    support: {width: 0.6, depth: 0.5}");
  yaml +=
      "props:\n  - {name: pillar, box: {min: [3.8, 4.3, 0.0], max: [4.0, 4.5, 2.0]}, colour: [0.2, 0.3, 0.9]}\n"
      "  - {name: toy, model: ../models/Duck/Duck.glb, scale: 0.25, recenter: true, world_pose: {translation: [6.5, 1.5, "
      "0.3]}}\n";
  const auto scene = projbot::config::parse_scene(yaml, kAssets + "/scenes/tour.yaml");
  ASSERT_EQ(scene.props.size(), 2U);
  EXPECT_DOUBLE_EQ(scene.room.wall_height_m, 2.0);
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  projbot::twin::TwinOptions o;
  o.depth_noise = false;
  projbot::twin::Twin twin(scene, o, renderer);
  // The east wall (x = 8) from 3 m away at 1.5 m height, and nothing above it.
  EXPECT_NEAR(centre_depth_m(twin, {5.0, 1.5, 1.5}, {8.0, 1.5, 1.5}), 3.0, 0.01);
  EXPECT_EQ(centre_depth_m(twin, {5.0, 1.5, 2.3}, {8.0, 1.5, 2.3}), 0.0);  // over a 2 m wall: no return
  // The obstacle [0.0, 2.4, 0.5, 3.6] is a block: seen from x = 2 at 1 m height, 1.5 m away.
  EXPECT_NEAR(centre_depth_m(twin, {2.0, 3.0, 1.0}, {0.0, 3.0, 1.0}), 1.5, 0.01);
  // The pillar prop, 1 m in front of a camera at x = 2.8.
  EXPECT_NEAR(centre_depth_m(twin, {2.8, 4.4, 1.0}, {4.0, 4.4, 1.0}), 1.0, 0.01);
  // The box's support is 60 x 50 cm: its face at y = 3.6 - 0.25, seen from y = 2.35 at 0.3 m height.
  EXPECT_NEAR(centre_depth_m(twin, {5.75, 2.35, 0.3}, {5.75, 4.0, 0.3}), 1.0, 0.01);
  // The toy duck (a glTF prop, up to 40 cm long, centred 1 m away) in front of the east wall (2.5 m).
  const double toy_m = centre_depth_m(twin, {5.5, 1.5, 0.3}, {8.0, 1.5, 0.3});
  EXPECT_GT(toy_m, 0.75);
  EXPECT_LT(toy_m, 1.0);
  // The pillar catches the projector's light too.
  const auto hit = projbot::twin::cast_ray(twin.true_scene(Eigen::Matrix4d::Identity()), {2.8, 4.4, 1.0}, {1.0, 0.0, 0.0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->x(), 3.8, 1e-6);
  // Bad props are named.
  const auto prop_error = [&](const std::string& prop) {
    try {
      projbot::config::parse_scene(text.str() + "props:\n  - " + prop + "\n", kAssets + "/scenes/tour.yaml");
    } catch (const projbot::config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(prop_error("{name: p, box: {min: [1, 1, 0], max: [1, 2, 1]}}").find("props[0].box: need min < max"),
            std::string::npos);
  EXPECT_NE(prop_error("{name: duck, box: {min: [1, 1, 0], max: [2, 2, 1]}}").find("already the name of a target"),
            std::string::npos);
  EXPECT_NE(prop_error("{name: p, model: x.glb}").find("props[0]: a model prop needs a world_pose"), std::string::npos);
  EXPECT_NE(prop_error("{name: p}").find("props[0]: give either a 'model'"), std::string::npos);
  EXPECT_NE(prop_error("{name: p, box: {min: [1, 1, 0], max: [2, 2, 1]}, colour: [2, 0, 0]}").find("props[0].colour"),
            std::string::npos);
}

TEST(TwinRoomTest, AFigureStandsOnTheFloor) {
  // The duck's lowest point is above the floor in the demo (its pedestal's height): on the floor it
  // must come down to z = 0, else the twin says so.
  double lowest_m = 0.0;
  {
    projbot::engine::Renderer probe(projbot::engine::RendererOptions{});
    projbot::twin::Twin t(demo_with("x", "x"), {}, probe);
    lowest_m = t.targets()[0].pedestal_raycaster->closest_point({0.0, 0.0, 10.0}).z();  // the pedestal's top
  }
  ASSERT_GT(lowest_m, 0.5);
  auto scene = demo_with("    stop: [3.0, 1.8, 90]\n", "    stop: [3.0, 1.8, 90]\n    support: floor\n");
  EXPECT_TRUE(scene.targets[0].support.floor);
  const std::string error = twin_error(scene);
  char expected[96];
  std::snprintf(expected, sizeof expected, "its lowest point is at z = %.3f m", lowest_m);
  EXPECT_NE(error.find("target 'duck' stands on the floor (support: floor) but"), std::string::npos) << error;
  EXPECT_NE(error.find(expected), std::string::npos) << error;
  // Lowered by that much, it stands: no pedestal under it, the box's still there.
  (*scene.targets[0].T_world_target)(2, 3) -= lowest_m;
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  projbot::twin::Twin twin(scene, {}, renderer);
  EXPECT_EQ(twin.targets()[0].pedestal_raycaster, nullptr);
  EXPECT_NE(twin.targets()[1].pedestal_raycaster, nullptr);
  for (const char* bad : {"support: table", "support: {width: 0.5}", "support: {width: 0, depth: 0.5}"}) {
    try {
      demo_with("    stop: [3.0, 1.8, 90]\n", std::string("    stop: [3.0, 1.8, 90]\n    ") + bad + "\n");
      ADD_FAILURE() << bad;
    } catch (const projbot::config::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("targets[0].support"), std::string::npos) << e.what();
    }
  }
}

// The shop (issue 11): a 1.45 m figure standing on the floor half a metre from a wall, a shelf at its
// hand. Before the floor was left out and the scan cropped to the guess's silhouette, the gate blanked it
// (inliers 0.47: floor points counted against it) after 36 s of restarts and global searches.
TEST(TourTest, TheShopFigureOnTheFloorIsLit) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto localized = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(localized.visits.size(), 1U);
  EXPECT_EQ(localized.visits[0].target, "figure");
  EXPECT_TRUE(localized.visits[0].projected);
  EXPECT_FALSE(localized.visits[0].icp.reinitialised);  // found from the guess, no global search
  // The shelf touching its hand pulled ICP to 3.7 mm; the projective polish after it does not follow it.
  EXPECT_LT(localized.visits[0].mean_mm, 2.0);
  // The pan-tilt aims at the model's middle, not its origin at the feet: every marker, the chest's too,
  // is in the projector's image and lit (aimed at the feet, the chest was above the image).
  ASSERT_EQ(localized.visits[0].markers.size(), 5U);
  for (const auto& m : localized.visits[0].markers) EXPECT_TRUE(m.in_image && m.landed) << m.marker_m.transpose();
  const auto tracked = tracking_tour(scene, 1, 1.0);
  ASSERT_EQ(tracked.visits.size(), 1U);
  EXPECT_EQ(tracked.visits[0].lit_frames, 61);
  EXPECT_LT(tracked.visits[0].still_mean_mm, 2.0);
  EXPECT_TRUE(tracked.visits[0].neighbours.empty());  // the shelf beside it is no target
}

// The shop's box, seen nearly face-on past a pillar: depth pinned it only loosely along its face (1.7-2.9
// mm off sideways over three visits, the Kinect's edges being noisy). Its texture is the content, and
// the colour registered to the depth places it along the face.
TEST(TourTest, TheShopBoxSeenFaceOnIsPlacedAlongItsFaceByItsColour) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto tour = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(tour.visits.size(), 1U);
  EXPECT_TRUE(tour.visits[0].projected);
  EXPECT_LT(tour.visits[0].mean_mm, 1.0);
  EXPECT_GT(tour.visits[0].icp.colour_shift_mm, 0.5);  // colour did the work, not depth
  EXPECT_GT(tour.visits[0].icp.colour_agreement, 0.8);
  EXPECT_LT(std::abs(tour.visits[0].icp.footing_height_error_mm), 5.0);
}

// Tracking mode: the box's first pose is placed by colour, and tracking holds it there. Before the
// hold, tracking slid it back along the face to the depth's optimum within a frame: 2.2-2.8 mm.
TEST(TourTest, TrackingHoldsTheShopBoxWhereColourPlacedIt) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  const auto tour = tracking_tour(scene, 1, 1.5);
  ASSERT_EQ(tour.visits.size(), 1U);
  const auto& v = tour.visits[0];
  EXPECT_EQ(v.lit_frames, static_cast<int>(v.timeline.size()) + 1);  // every frame, the arrival's too
  EXPECT_GT(v.icp.colour_shift_mm, 0.5);
  EXPECT_LT(v.still_mean_mm, 1.0);
  ASSERT_FALSE(v.timeline.empty());
  EXPECT_LT(v.timeline.back().mean_mm, 1.0);
}

// ...and lets go of it when the box is moved: from there on depth alone follows it. (Here the 3 mm
// rule let go, 3.2 mm from the held pose; a frame that tracking fails lets go as well.)
TEST(TourTest, AHeldBoxThatIsMovedIsFollowed) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  projbot::config::TargetMotion move;
  move.visit = 1;
  move.start_s = 0.5;
  move.duration_s = 1.0;
  move.translation_m = Eigen::Vector3d(0.05, 0.03, 0.0);
  move.stays = true;
  for (auto& t : scene.targets)
    if (t.name == "box") t.motions = {move};
  const auto tour = tracking_tour(scene, 1, 2.5);
  ASSERT_EQ(tour.visits.size(), 1U);
  const auto& v = tour.visits[0];
  EXPECT_GT(v.icp.colour_shift_mm, 0.5);  // it was held
  EXPECT_EQ(v.moving_blank_frames, 0);
  ASSERT_FALSE(v.timeline.empty());
  EXPECT_TRUE(v.timeline.back().shown);
  EXPECT_LT(v.timeline.back().mean_mm, 4.0);  // depth alone along the face: about 2 mm
}

namespace {

// The shop's twin with the robot arrived at the standing figure's stop (its first visit), one depth
// capture there, the figure's true pose in the camera and its footing from the map.
class ShopFigureStop : public ::testing::Test {
 protected:
  const projbot::config::Scene scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const std::size_t figure = twin.target_index("figure");
  const projbot::twin::Arrival arrival = twin.arrive(figure, 0);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const Eigen::Matrix4d T_true = projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[figure].T_world_target_true;
  const projbot::alignment::DepthImage depth = twin.capture(T_world_camera, 7919);
  const projbot::alignment::ModelCloud& cloud = twin.targets()[figure].cloud;
  const projbot::alignment::Footing footing =
      projbot::alignment::footing_in_camera(cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
};

}  // namespace

// From a guess 5 cm and 10 degrees off (bench acquire's), the crop grown by that much takes in the
// shelf beside the figure's hand, and ICP settled 11-19 mm sideways, turned 0.7 degrees about the line of
// sight, where the gate refused it. Cropped again at that estimate and refined, the shelf drops out;
// clustering the first crop leaves it out too, and so does ICP's median rejection.
TEST_F(ShopFigureStop, TheShopFigureIsFoundFromATenDegreeGuessBesideItsShelf) {
  using projbot::alignment::rigid_inverse;
  // 10 degrees about the line of sight through the figure's chest, and 5 cm sideways.
  const Eigen::Vector3d chest = (T_true * Eigen::Vector4d(0.0, 1.0, 0.0, 1.0)).head<3>();
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
  turn.topLeftCorner<3, 3>() = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turn.topRightCorner<3, 1>() = chest - turn.topLeftCorner<3, 3>() * chest + Eigen::Vector3d(0.05, 0.0, 0.0);
  const Eigen::Matrix4d guess = turn * T_true;
  const double grow_m = projbot::alignment::guess_reach_m(cloud, 0.05, 10.0);
  const auto error = [&](const Eigen::Matrix4d& T) { return rigid_inverse(T_true) * T; };
  const projbot::alignment::TargetFollower follower(cloud, twin.camera());
  const auto r = follower.acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r.converged) << "inliers " << r.inlier_ratio;
  EXPECT_TRUE(follower.passes(follower.verify(depth, r.T_scan_model)));
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r.T_scan_model)), 0.003);
  EXPECT_LT(projbot::alignment::rotation_angle_deg(error(r.T_scan_model)), 0.5);
  // Found by the projective start: only ICP's finest stage ran on it (coarse to fine from this guess,
  // ICP took 50-90 iterations, over a second here).
  EXPECT_LE(r.iterations, 40) << r.iterations;
  // Without the second crop (recrop_m as wide as the first), clustering alone leaves the shelf out...
  projbot::alignment::WorkerConfig once;
  once.recrop_m = 10.0;
  const auto r1 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r1.converged);
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r1.T_scan_model)), 0.003);
  // ...and now with neither, nor ICP's rejection of correspondences far past their median, the gate
  // itself takes the shelf's points beside and behind the hand as saying nothing against the pose
  // (AcquisitionConfig::scan_from_origin): found all the same (before the gate judged them, not found).
  once.cluster_neighbours = false;
  once.acquisition.icp_median_factor = 0.0;
  const auto r2 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r2.converged) << "inliers " << r2.inlier_ratio;
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r2.T_scan_model)), 0.003);
  once.acquisition.scan_from_origin = false;
  const auto r3 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(!r3.converged || projbot::alignment::translation_norm_m(error(r3.T_scan_model)) > 0.005)
      << "found with every point judged: " << 1000.0 * projbot::alignment::translation_norm_m(error(r3.T_scan_model)) << " mm";
}

// An acquisition is bounded (WorkerConfig::acquire_budget_ms): from a gross guess the whole search ran
// up to 27 s on this figure (restarts, then RANSAC over FPFH matches). Out of budget from the start, only
// the first ICP stages run (no restart, no global search) and what they leave is not taken: blanked.
TEST_F(ShopFigureStop, AnAcquisitionStopsAtItsBudgetAndBlanks) {
  Eigen::Matrix4d guess = T_true;  // 30 cm sideways and turned 40 degrees about the vertical
  guess.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(40.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix() * T_true.topLeftCorner<3, 3>();
  guess(0, 3) += 0.30;
  projbot::alignment::WorkerConfig none;
  none.acquire_budget_ms = 0.0;
  const auto r = projbot::alignment::TargetFollower(cloud, twin.camera(), none)
                     .acquire(depth, guess, footing, projbot::alignment::guess_reach_m(cloud, 0.30, 40.0));
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.reinitialised);
  // ICP's first stage from the guess, then again on the crop at its estimate: 20 iterations each at most.
  EXPECT_LE(r.iterations, 2 * projbot::alignment::AcquisitionConfig{}.coarse_iterations) << r.iterations;
}

namespace {

// The shop's twin with the robot arrived at the Duck's stop (its first visit).
class ShopDuckStop : public ::testing::Test {
 protected:
  const projbot::config::Scene scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const std::size_t duck = twin.target_index("duck");
  const projbot::twin::Arrival arrival = twin.arrive(duck, 0);
};

}  // namespace

// The twin's colour camera (issue 11): registered to its depth, the textured model as it is, and the
// colour sensor's noise. Checked against the Duck drawn alone from the same viewpoint, noiseless.
TEST_F(ShopDuckStop, ColourIsRegisteredToDepthWithTheModelsTextureAndNoise) {
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const auto colour = twin.capture_colour(T_world_camera, 7);
  const auto depth = twin.capture(T_world_camera, 7);
  ASSERT_EQ(colour.width, depth.width);
  ASSERT_EQ(colour.height, depth.height);
  EXPECT_EQ(twin.capture_colour(T_world_camera, 7).rgba, colour.rgba);  // seeded
  // The Duck alone, noiseless, in colour and depth.
  const projbot::config::ProjectorConfig pinhole(twin.camera_pinhole());  // drawn through, as the twin does
  const std::vector<projbot::engine::DrawItem> duck_only{
      {twin.target_model_ids()[duck],
       projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true}};
  auto offscreen = renderer.make_offscreen(colour.width, colour.height);
  renderer.draw_frame(*offscreen, pinhole, duck_only);
  const auto alone = offscreen->read_back();
  auto depth_camera = renderer.make_depth_camera(colour.width, colour.height);
  renderer.draw_frame(*depth_camera, pinhole, duck_only);
  const auto alone_depth = depth_camera->read_back_depth();
  // Where the Duck is (nothing stands in front of it at its stop): the scene's colour is the texture's
  // plus zero-mean noise of the sensor's sigma, and the scene's depth is the Duck's.
  double sum = 0.0, sum2 = 0.0, depth_off = 0.0;
  std::size_t n = 0, yellow = 0, depth_n = 0;
  for (int i = 0; i < colour.width * colour.height; ++i) {
    const float z = alone_depth.z_m[static_cast<std::size_t>(i)];
    if (z <= 0.0F) continue;
    const std::uint8_t* a = &alone.rgba[static_cast<std::size_t>(i) * 4];
    const std::uint8_t* c = &colour.rgba[static_cast<std::size_t>(i) * 4];
    for (int ch = 0; ch < 3; ++ch) {
      if (a[ch] < 10 || a[ch] > 245) continue;  // no clipping at 0 or 255
      const double d = static_cast<double>(c[ch]) - a[ch];
      sum += d, sum2 += d * d, ++n;
    }
    yellow += a[0] > 180 && a[1] > 150 && a[2] < 90 ? 1 : 0;
    if (depth.depth_m[static_cast<std::size_t>(i)] > 0.0F) {
      depth_off += std::abs(depth.depth_m[static_cast<std::size_t>(i)] - z);
      ++depth_n;
    }
  }
  ASSERT_GT(n, 20000U);
  const double count = static_cast<double>(n);
  const double mean = sum / count, sigma = std::sqrt(sum2 / count - mean * mean);
  EXPECT_LT(std::abs(mean), 0.2);
  EXPECT_NEAR(sigma, projbot::twin::Twin::kColourNoiseSigma, 0.3);
  EXPECT_GT(static_cast<double>(yellow) / static_cast<double>(depth_n), 0.8);  // the Duck's texture is mostly yellow
  ASSERT_GT(depth_n, 5000U);
  EXPECT_LT(depth_off / static_cast<double>(depth_n), 0.01);  // registered: the depth there is the Duck's (Kinect noise aside)
}

// The spectator's view (issue 11): the projector's light falls on the true surfaces. The Duck's own
// frame drawn at its true pose lights the Duck and almost nothing else; drawn 5 cm to the side, much of
// its light spills past it onto the table and the wall.
// Depth pins the Duck; colour alone (its luminance's correlation with the image) sometimes peaks a few
// millimetres off, on the sensor's noise. Acquisition takes colour's move only where the depth's error
// does not grow: among the 20 captures of bench acquire's Duck (after the figure's stop, as the bench
// drives), the two where colour alone moves the depth's pose more than 2 mm are acquired within 0.5 mm,
// colour's move refused (before, they were lit 2.6-3.3 mm off). And colours that disagree with the image
// refuse a pose however well the depth fits.
TEST(TourTest, ColourMovesNoPoseThatDepthPins) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  twin.arrive(twin.target_index("figure"), 0);
  const std::size_t duck = twin.target_index("duck");
  const projbot::twin::Arrival arrival = twin.arrive(duck, 1);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const Eigen::Matrix4d T_true = projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true;
  const auto& cloud = twin.targets()[duck].cloud;
  const projbot::alignment::TargetFollower follower(cloud, twin.camera());
  const auto footing =
      projbot::alignment::footing_in_camera(cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
  for (const std::uint32_t seed : {8924U, 8935U}) {  // the two captures (of 20) where it happened
    const auto depth = twin.capture(T_world_camera, seed);
    const auto colour = twin.capture_colour(T_world_camera, seed);
    const auto without = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m());
    const auto alone = projbot::alignment::colour_refined(cloud, without.T_scan_model, depth, colour, twin.camera());
    EXPECT_GT(alone.shift_m.norm(), 0.002) << "seed " << seed;  // the case is met: colour alone misleads
    const auto r = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m(), &colour);
    EXPECT_TRUE(r.converged) << "seed " << seed;
    EXPECT_EQ(r.colour_shift_mm, 0.0) << "seed " << seed;
    EXPECT_LT(projbot::alignment::translation_norm_m(projbot::alignment::rigid_inverse(T_true) * r.T_scan_model), 0.0005)
        << "seed " << seed;
    // Colours that disagree (the image's negative: correlation about -0.95) refuse a pose depth likes.
    auto negative = colour;
    for (std::size_t i = 0; i < negative.rgba.size(); ++i)
      if (i % 4 != 3) negative.rgba[i] = static_cast<std::uint8_t>(255 - negative.rgba[i]);
    const auto refused = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m(), &negative);
    EXPECT_FALSE(refused.converged) << "seed " << seed;
    EXPECT_LT(refused.colour_agreement, 0.0) << "seed " << seed;
  }
}

TEST_F(ShopDuckStop, SpectatorSeesLightFallOnTheTargetOrSpillPastIt) {
  const Eigen::Matrix4d T_world_projector = arrival.truth.T_world_projector.matrix();
  const Eigen::Matrix4d T_world_duck = twin.targets()[duck].T_world_target_true;
  projbot::twin::SpectatorView view(renderer, scene.projector);
  const Eigen::Matrix4d T_world_spectator =
      projbot::twin::spectator_pose(arrival.truth.T_world_camera.translation(), T_world_duck.topRightCorner<3, 1>());
  // Where the spectator sees the Duck.
  auto depth_camera = renderer.make_depth_camera(view.pinhole().width_px, view.pinhole().height_px);
  const std::size_t duck_id = twin.target_model_ids()[duck];
  const std::vector<projbot::engine::DrawItem> seen{
      {duck_id, projbot::alignment::rigid_inverse(T_world_spectator) * T_world_duck}};
  renderer.draw_frame(*depth_camera, view.pinhole(), seen);
  const auto duck_depth = depth_camera->read_back_depth();
  auto frame_target = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  projbot::assets::Image black;
  black.width = scene.projector.width_px, black.height = scene.projector.height_px;
  black.rgba.assign(static_cast<std::size_t>(black.width) * black.height * 4, 0);
  const auto unlit = view.draw(twin, T_world_spectator, T_world_projector, black);
  // Lit pixels on the Duck and off it, for the Duck's frame drawn at T_projector_duck.
  const auto lit = [&](const Eigen::Matrix4d& T_projector_duck) {
    const std::vector<projbot::engine::DrawItem> drawn{{duck_id, T_projector_duck}};
    renderer.draw_frame(*frame_target, scene.projector, drawn);
    const auto picture = view.draw(twin, T_world_spectator, T_world_projector, frame_target->read_back());
    std::array<std::size_t, 2> on_off{0, 0};
    for (std::size_t i = 0; i < duck_depth.z_m.size(); ++i) {
      const int gain = picture.rgba[i * 4] + picture.rgba[i * 4 + 1] - unlit.rgba[i * 4] - unlit.rgba[i * 4 + 1];
      if (gain > 20) ++on_off[duck_depth.z_m[i] > 0.0F ? 0 : 1];
    }
    return on_off;
  };
  const Eigen::Matrix4d T_projector_duck = projbot::alignment::rigid_inverse(T_world_projector) * T_world_duck;
  const auto right = lit(T_projector_duck);
  EXPECT_GT(right[0], 5000U);                                                      // the Duck is lit
  EXPECT_LT(static_cast<double>(right[1]), 0.03 * static_cast<double>(right[0]));  // edges only
  Eigen::Matrix4d shifted = T_projector_duck;
  shifted(0, 3) += 0.05;
  const auto off = lit(shifted);
  EXPECT_GT(static_cast<double>(off[1]), 0.2 * static_cast<double>(off[0] + off[1]));  // spilled past it (32 %)
  // A frame of another size than the projector's is refused, naming both.
  projbot::assets::Image small = black;
  small.width = 64, small.height = 40;
  small.rgba.assign(64 * 40 * 4, 0);
  try {
    view.draw(twin, T_world_spectator, T_world_projector, small);
    ADD_FAILURE() << "a 64x40 frame was drawn";
  } catch (const projbot::twin::TwinError& e) {
    EXPECT_NE(std::string(e.what()).find("64x40, the projector 1280x800"), std::string::npos) << e.what();
  }
  // Without light the room is dimmed to its room light: a mid-grey wall of 200 shows about 60.
  std::size_t dim = 0;
  for (std::size_t i = 0; i < unlit.rgba.size(); i += 4) dim += unlit.rgba[i] < 0.35 * 255 ? 1 : 0;
  EXPECT_EQ(dim, unlit.rgba.size() / 4);
}

// Two targets side by side (assets/scenes/display.yaml, issue 11 item 5): from either one's stop the
// other stands in the projector's image too. Both are acquired from the same capture and lit in the
// same frames; in tracking mode both are tracked all along.
TEST(TourTest, ANeighbourInViewIsTrackedAndLitWithTheVisitedTarget) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  const auto tracked = tracking_tour(scene, 2, 1.0);
  ASSERT_EQ(tracked.visits.size(), 2U);
  for (const auto& v : tracked.visits) {
    SCOPED_TRACE(v.target);
    EXPECT_EQ(v.lit_frames, 61);
    EXPECT_LT(v.still_mean_mm, 1.5);
    ASSERT_EQ(v.neighbours.size(), 1U);
    const auto& n = v.neighbours.front();
    EXPECT_EQ(n.target, v.target == "duck" ? "box" : "duck");
    EXPECT_TRUE(n.projected);
    EXPECT_LT(n.mean_mm, 1.5);
    EXPECT_EQ(n.frames, 61);  // arrival + 60 projector frames
    EXPECT_EQ(n.lit_frames, 61);
    EXPECT_LT(n.lit_mean_mm, 1.5);  // measured 0.42-0.93 (2.0 mm on the box before colour's hold)
    EXPECT_LT(n.worst_mm, 2.0);
  }
  projbot::twin::TourOptions o;
  o.visits = 2;
  const auto localized = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(localized.visits.size(), 2U);
  for (const auto& v : localized.visits) {
    SCOPED_TRACE(v.target);
    ASSERT_EQ(v.neighbours.size(), 1U);
    EXPECT_TRUE(v.neighbours.front().projected);
    EXPECT_EQ(v.neighbours.front().frames, 1);  // one alignment per stop, one frame
    EXPECT_LT(v.neighbours.front().mean_mm, 1.5);
  }
}

// The box is not on its plinth: at the duck's stop the robot still expects it there (the map), finds
// nothing and blanks it, while the duck beside it is lit all along.
TEST(TourTest, AnAbsentNeighbourIsBlankedOnItsOwn) {
  std::ifstream in(kAssets + "/scenes/display.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string from = "    model: ../models/BoxTextured/BoxTextured.gltf\n";
  ASSERT_NE(yaml.find(from), std::string::npos);
  yaml.replace(yaml.find(from), from.size(), from + "    present: false\n");
  const auto report = tracking_tour(projbot::config::parse_scene(yaml, kAssets + "/scenes/display.yaml"), 1, 1.0);
  ASSERT_EQ(report.visits.size(), 1U);
  const auto& duck = report.visits.front();
  EXPECT_EQ(duck.target, "duck");
  EXPECT_EQ(duck.lit_frames, 61);
  EXPECT_LT(duck.still_mean_mm, 1.5);
  ASSERT_EQ(duck.neighbours.size(), 1U);
  EXPECT_FALSE(duck.neighbours.front().projected);
  EXPECT_EQ(duck.neighbours.front().frames, 61);
  EXPECT_EQ(duck.neighbours.front().lit_frames, 0);
}

// Clustering where a neighbour touches the crop: the shop's vase stands inside the duck's silhouette
// crop grown by a 5 cm guess's reach; its surface runs on past the crop's edge and lies outside the
// duck's silhouette, so clustering leaves it out, and keeps the duck.
TEST_F(ShopDuckStop, ClusteringLeavesOutTheVaseTouchingTheDucksCrop) {
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const auto depth = twin.capture(T_world_camera, 11);
  const auto& cloud = twin.targets()[duck].cloud;
  const Eigen::Matrix4d T_camera_duck =
      projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true;
  const double grow_m = projbot::alignment::guess_reach_m(cloud, 0.05, 3.0);
  const auto count = [&](bool cluster) {
    const auto crop = projbot::alignment::crop_to_silhouette(depth, twin.camera(), cloud, T_camera_duck, grow_m, cluster);
    int vase = 0, near_duck = 0;
    const auto& k = twin.camera();
    for (int y = 0; y < crop.height; ++y)
      for (int x = 0; x < crop.width; ++x) {
        const float z = crop.at(x, y);
        if (!(z > 0.0F)) continue;
        const Eigen::Vector4d p((x - k.cx_px) * z / k.fx_px, (y - k.cy_px) * z / k.fy_px, z, 1.0);
        const Eigen::Vector3d w = (T_world_camera * p).head<3>();
        vase += w.x() > 5.25 && w.x() < 5.39 && w.y() > 4.49 && w.y() < 4.67 && w.z() > 0.93 ? 1 : 0;  // above the table
        near_duck += (w - twin.targets()[duck].T_world_target_true.topRightCorner<3, 1>()).norm() < 0.15 ? 1 : 0;
      }
    return std::pair{vase, near_duck};
  };
  const auto [vase_plain, duck_plain] = count(false);
  const auto [vase_clustered, duck_clustered] = count(true);
  const std::string numbers = "vase pixels " + std::to_string(vase_plain) + " -> " + std::to_string(vase_clustered) + ", duck " +
                              std::to_string(duck_plain) + " -> " + std::to_string(duck_clustered);
  EXPECT_GT(vase_plain, 100) << numbers;  // the vase is in the plain crop (157 pixels; 0 clustered)
  EXPECT_LT(vase_clustered, vase_plain / 10) << numbers;
  EXPECT_GT(duck_clustered, 0.95 * duck_plain) << numbers;  // the duck stays
}

// The session (issue 12) on the twin's base and pan-tilt: at the Duck's stop of the display it plans the
// Duck first and the box beside it, each from Eq. 1 on the believed head, with its surveyed footing; the
// believed head is the twin's truth within the localisation's error, and the guesses are the truth's
// within that too.
TEST(SessionTest, PlansTheVisitedTargetAndItsNeighbourFromTheBelievedHead) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  projbot::session::Session session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());
  const projbot::session::Stop stop = session.arrive(0);
  EXPECT_EQ(stop.target, scene.target_index("duck"));
  EXPECT_EQ(stop.target_visit, 1);
  EXPECT_TRUE(stop.drive.arrived);
  ASSERT_EQ(stop.lit.size(), 2U);
  EXPECT_EQ(stop.lit[0].target, scene.target_index("duck"));
  EXPECT_EQ(stop.lit[1].target, scene.target_index("box"));
  using projbot::alignment::rigid_inverse;
  const Eigen::Matrix4d T_world_camera = stop.believed.T_world_camera.matrix();
  const Eigen::Matrix4d T_true_camera = twin.true_head().T_world_camera.matrix();
  EXPECT_LT(projbot::alignment::translation_norm_m(rigid_inverse(T_true_camera) * T_world_camera), 0.03);
  for (const auto& l : stop.lit) {
    const auto& target = scene.targets[static_cast<std::size_t>(l.target)];
    SCOPED_TRACE(target.name);
    EXPECT_TRUE(l.T_camera_target_guess.isApprox(rigid_inverse(T_world_camera) * *target.T_world_target, 1e-12));  // Eq. 1
    const Eigen::Matrix4d T_true = rigid_inverse(T_true_camera) * *target.T_world_target;
    EXPECT_LT(projbot::alignment::translation_norm_m(rigid_inverse(T_true) * l.T_camera_target_guess), 0.05);
    EXPECT_GT(l.footing.height_m, 0.6);  // on its plinth, below the model's middle (0.9 m up)
    EXPECT_LT(l.footing.height_m, 0.9);
  }
  // The second visit is the box's; the Duck's next one is its second.
  EXPECT_EQ(session.arrive(1).target, scene.target_index("box"));
  EXPECT_EQ(session.arrive(2).target_visit, 2);
}

// What Session::visit promises the trackers it drives (the engine's TrackerWorker, the tour's lanes on
// the twin's simulated clock): each lit target's tracker gets its own Eq. 1 guess and the colour of the
// stop's first frame before any frame, then, in lockstep, every frame in order, the same frame (not a
// copy) to each, until the dwell says it is over; the observer sees what each returned for that frame.
TEST(SessionTest, AVisitHandsEachLitTrackerItsGuessThenEveryFrameInOrder) {
  struct Recorder final : projbot::alignment::PoseTracker {
    Eigen::Matrix4d guess = Eigen::Matrix4d::Zero();
    const projbot::assets::Image* colour = nullptr;
    std::vector<const projbot::alignment::DepthImage*> frames;
    int guesses = 0, submitted = 0;
    void set_initial_guess(const Eigen::Matrix4d& T, const projbot::alignment::Footing&,
                           std::shared_ptr<const projbot::assets::Image> c) override {
      guess = T;
      colour = c.get();
      ++guesses;
      EXPECT_TRUE(frames.empty()) << "a guess after a frame";
    }
    std::optional<projbot::alignment::PoseSample> track(std::shared_ptr<const projbot::alignment::DepthImage> f) override {
      frames.push_back(f.get());
      projbot::alignment::PoseSample s;
      s.capture_time_s = f->capture_time_s;
      return s;
    }
    void submit(std::shared_ptr<const projbot::alignment::DepthImage>) override { ++submitted; }
  };
  struct Observer final : projbot::session::StopObserver {
    std::vector<std::pair<int, std::size_t>> frames;  // k, samples handed over
    std::vector<double> sample_times, capture_times;
    void frame(const projbot::session::Stop&, int k, const projbot::alignment::RgbdFrame& f,
               const std::vector<std::optional<projbot::alignment::PoseSample>>& samples) override {
      frames.emplace_back(k, samples.size());
      capture_times.push_back(f.depth.capture_time_s);
      for (const auto& s : samples) sample_times.push_back(s ? s->capture_time_s : -1.0);
    }
  };
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  projbot::twin::TwinCamera camera(twin, 1);
  projbot::session::Session session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());
  std::vector<Recorder> recorders(scene.targets.size());
  std::vector<projbot::alignment::PoseTracker*> trackers;
  for (auto& r : recorders) trackers.push_back(&r);
  projbot::session::Dwell dwell;
  dwell.camera = [&](const projbot::session::Stop& at, double since_s) -> projbot::alignment::RgbdCamera& {
    camera.at_stop(twin.target_index(scene.targets[static_cast<std::size_t>(at.target)].name), at.target_visit, 0, since_s);
    return camera;
  };
  dwell.over = [](const projbot::session::Stop&, int frames, double) { return frames >= 4; };
  dwell.lockstep = true;
  Observer observer;
  const std::stop_source never;
  const projbot::session::Stop stop = session.visit(0, trackers, dwell, observer, never.get_token());

  ASSERT_EQ(stop.lit.size(), 2U);  // the Duck and the box beside it
  ASSERT_EQ(observer.frames.size(), 4U);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(observer.frames[static_cast<std::size_t>(k)], std::make_pair(k, std::size_t{2}));
  const Recorder& duck = recorders[static_cast<std::size_t>(stop.lit[0].target)];
  const Recorder& box = recorders[static_cast<std::size_t>(stop.lit[1].target)];
  for (const auto& [r, lit] : {std::pair{&duck, stop.lit[0]}, std::pair{&box, stop.lit[1]}}) {
    EXPECT_EQ(r->guesses, 1);
    EXPECT_TRUE(r->guess.isApprox(lit.T_camera_target_guess, 1e-12));
    ASSERT_NE(r->colour, nullptr);  // the twin's first frame has colour
    EXPECT_GT(r->colour->width, 0);
    EXPECT_EQ(r->submitted, 0);  // lockstep: tracked, never merely submitted
  }
  EXPECT_EQ(duck.colour, box.colour);  // the stop's one colour image, shared
  ASSERT_EQ(duck.frames.size(), 4U);
  EXPECT_EQ(duck.frames, box.frames);  // the same frames, not copies
  for (std::size_t k = 1; k < observer.capture_times.size(); ++k)
    EXPECT_GT(observer.capture_times[k], observer.capture_times[k - 1]);  // in order
  // The samples the observer saw are those each tracker returned for that frame.
  ASSERT_EQ(observer.sample_times.size(), 8U);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(observer.sample_times[i], observer.capture_times[i / 2]);
  for (const Recorder& r : recorders) EXPECT_EQ(r.guesses, &r == &duck || &r == &box ? 1 : 0);
}

// A session needs a model of every visited target; told of none, it names the first it lacks.
TEST(SessionTest, AVisitedTargetWithoutAModelIsNamed) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  auto targets = twin.session_targets();
  targets.erase(targets.begin() + 1);  // the box
  try {
    projbot::session::Session session(scene, targets, twin.robot(), twin.pan_tilt());
    FAIL() << "no error";
  } catch (const projbot::session::SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("target 'box' is visited but the session was given no model of it"), std::string::npos)
        << e.what();
  }
}

// The example site (issue 12, assets/sites/youbot-ud.yaml): the paper's devices, all four the session
// drives, and the demo tour, which the twin runs with --sim (a short localized tour here).
TEST(SessionTest, TheYoubotSiteNamesThePapersDevicesAndRunsInTheTwin) {
  const auto site = projbot::config::load_scene(kAssets + "/sites/youbot-ud.yaml");
  ASSERT_TRUE(site.devices.camera && site.devices.pan_tilt && site.devices.base && site.devices.projector);
  EXPECT_EQ(site.devices.camera->driver, "freenect");  // the Kinect v1
  EXPECT_EQ(site.devices.pan_tilt->port, "/dev/ttyUSB0");
  EXPECT_EQ(site.devices.base->cmd_vel, "cmd_vel");
  EXPECT_FALSE(site.devices.laser.has_value());  // run does not localise on a laser yet: left commented out
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto report = projbot::twin::run_tour(site, o);
  ASSERT_EQ(report.visits.size(), 1U);
  EXPECT_TRUE(report.visits[0].projected);
  EXPECT_LT(report.visits[0].mean_mm, 3.0);
}

// CIEDE2000 against Sharma, Wu and Dalal's test data (Color Res. Appl. 30(1), 2005, Table 1: pairs 1, 2, 7,
// 17, 25 and 34), and L*a*b* of sRGB's white and red.
TEST(Appearance, Ciede2000MatchesSharmasTestData) {
  struct Pair {
    Eigen::Vector3d a, b;
    double de;
  };
  const Pair pairs[] = {{{50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}, 2.0425},
                        {{50.0, 3.1571, -77.2803}, {50.0, 0.0, -82.7485}, 2.8615},
                        {{50.0, 0.0, 0.0}, {50.0, -1.0, 2.0}, 2.3669},
                        {{50.0, 2.5, 0.0}, {73.0, 25.0, -18.0}, 27.1492},
                        {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
                        {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082}};
  for (const Pair& p : pairs) {
    EXPECT_NEAR(projbot::twin::ciede2000(p.a, p.b), p.de, 1e-4) << p.a.transpose() << " / " << p.b.transpose();
    EXPECT_NEAR(projbot::twin::ciede2000(p.b, p.a), p.de, 1e-4);  // symmetric
  }
  const Eigen::Vector3d white = projbot::twin::srgb_to_lab({1.0, 1.0, 1.0}), red = projbot::twin::srgb_to_lab({1.0, 0.0, 0.0});
  EXPECT_NEAR(white[0], 100.0, 0.01);
  EXPECT_NEAR(white[1], 0.0, 0.01);
  EXPECT_NEAR(red[0], 53.24, 0.01);
  EXPECT_NEAR(red[1], 80.09, 0.02);
  EXPECT_NEAR(red[2], 67.20, 0.02);
}

// The visitor's light (issue 43) at the shop's Duck: a wall patch lit by full white shows its reflectance
// times (room + the projector's lux there) over the reference light, as photometry.hpp computes it by
// hand; unlit, the room's light alone. And the Duck's own content, compensated at its true pose, is seen
// as its content scaled by k where it can be reached, uncompensated far off it.
TEST_F(ShopDuckStop, TheVisitorSeesReflectanceTimesLight) {
  const Eigen::Matrix4d T_world_projector = arrival.truth.T_world_projector.matrix();
  const Eigen::Matrix4d T_world_duck = twin.targets()[duck].T_world_target_true;
  projbot::twin::SpectatorView view(renderer, scene.projector);
  const Eigen::Matrix4d T_world_spectator =
      projbot::twin::spectator_pose(arrival.truth.T_world_camera.translation(), T_world_duck.topRightCorner<3, 1>());
  projbot::assets::Image white;
  white.width = scene.projector.width_px, white.height = scene.projector.height_px;
  white.rgba.assign(static_cast<std::size_t>(white.width) * white.height * 4, 255);
  const auto seen = view.see(twin, T_world_spectator, T_world_projector, white);
  auto black = white;
  std::fill(black.rgba.begin(), black.rgba.end(), 0);
  const auto dark = view.see(twin, T_world_spectator, T_world_projector, black);
  const double ambient = scene.room.ambient_lux, black_level = scene.projector.photometry.black_level;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < seen.white_lux.size(); i += 97) {
    const double rho = projbot::engine::srgb_to_linear(seen.albedo.rgba[4 * i] / 255.0);
    const double lit = projbot::engine::srgb_to_linear(seen.image.rgba[4 * i] / 255.0);
    const double unlit = projbot::engine::srgb_to_linear(dark.image.rgba[4 * i] / 255.0);
    const double E = seen.white_lux[i];
    if (rho * (ambient + E) / projbot::engine::kReferenceLux > 0.95 || rho < 0.05) continue;  // saturated or black
    // 8-bit sRGB both ways: half a level of the brighter value.
    EXPECT_NEAR(lit, rho * (ambient + E) / projbot::engine::kReferenceLux, 0.004 + 0.01 * lit) << i;
    EXPECT_NEAR(unlit, rho * (ambient + black_level * E) / projbot::engine::kReferenceLux, 0.002) << i;
    checked += E > 0.0 ? 1 : 0;
  }
  EXPECT_GT(checked, 300U);
  // The Duck's frame with and without compensation, scored as bench appearance scores it.
  auto frame = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  const Eigen::Matrix4d T_projector_duck = projbot::alignment::rigid_inverse(T_world_projector) * T_world_duck;
  const auto& albedo = twin.targets()[duck].config.surface.albedo;
  const double k = projbot::engine::choose_gain(
      projbot::engine::surface_samples(twin.targets()[duck].model, scene.projector, T_projector_duck), albedo, ambient);
  EXPECT_GT(k, 0.2);
  EXPECT_LE(k, 1.0);
  std::array<projbot::twin::AppearanceScore, 2> scores;
  for (const bool on : {false, true}) {
    const projbot::engine::Compensation comp =
        on ? projbot::engine::compensation(albedo, ambient, k) : projbot::engine::Compensation{};
    renderer.draw_frame(*frame, scene.projector,
                        std::vector<projbot::engine::DrawItem>{{twin.target_model_ids()[duck], T_projector_duck, comp}});
    const auto looked = view.look(twin, T_world_spectator, T_world_projector);
    const auto picture = view.light(looked, frame->read_back());
    const auto content = view.content(twin, duck, T_world_spectator, looked);
    scores[on ? 1 : 0] = projbot::twin::score_appearance(picture, content, k, ambient, scene.projector.photometry);
  }
  EXPECT_GT(scores[1].pixels, 5000U);
  EXPECT_LT(scores[1].de2000_median, 5.0);  // issue 43's goals
  EXPECT_LT(scores[1].de2000_p95, 12.0);
  EXPECT_GT(scores[1].ssim, 0.85);
  EXPECT_GT(scores[1].psnr_db, scores[0].psnr_db + 8.0);
  EXPECT_GT(scores[0].de2000_median, 10.0);                             // the content as stored: far off
  EXPECT_EQ(scores[0].unreachable_share, scores[1].unreachable_share);  // the same k, the same reach
}
