// The digital twin: the projection-error measurement on hand-computed cases, the mesh ray caster, bad
// scenes and tours named, and the room standing in the depth images.

#include "projbot/config/angles.hpp"
#include "twin_helpers.hpp"

namespace {

using namespace twin_test;
using projbot::twin::MeshRaycaster;
using projbot::twin::PlacedMesh;

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
    T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(projbot::config::radians(deg), Eigen::Vector3d::UnitY()).toRotationMatrix();
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

}  // namespace
