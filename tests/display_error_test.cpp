// The display error's one definition (twin::marker_errors) as run measures it on its render thread
// (twin::StopMeter): a snapshot of the true scene at a stop and the targets' motion scripts, agreeing
// with the tour's measure of the twin as it stands, following a carried box, and outliving the twin.

#include "projbot/twin/display_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/twin/world.hpp"

using namespace projbot;

namespace {

class BoxStop : public ::testing::Test {
 protected:
  const config::Scene scene = config::load_scene(std::string(PROJBOT_ASSET_DIR) + "/scenes/motion.yaml");
  engine::Renderer renderer{engine::RendererOptions{}};
  std::unique_ptr<twin::Twin> world = std::make_unique<twin::Twin>(scene, twin::TwinOptions{}, renderer);
  const std::size_t box = world->target_index("box");
  const twin::Arrival arrival = world->arrive(box, 0);
  const twin::ProjectorModels models{scene.projector, scene.projector, scene.pan_tilt.T_projector_camera};
  const Eigen::Matrix4d T_world_projector = arrival.truth.T_world_projector.matrix();
  // The box where it truly is `t_s` into its first visit (carried 0.5 m in 1 s from 0.5 s), camera frame.
  Eigen::Matrix4d T_camera_box(double t_s) const {
    return alignment::rigid_inverse(arrival.truth.T_world_camera.matrix()) * world->scripted_pose(box, 1, t_s);
  }
};

TEST_F(BoxStop, AStopsMeterAgreesWithTheTwinAsItStandsAndFollowsTheScript) {
  const twin::StopMeter meter(*world, models, T_world_projector);
  // At the stop's start both measure the same twin: drawn where it is, the light lands on the markers.
  const twin::MarkerErrors now = twin::marker_errors(*world, box, models, T_world_projector, T_camera_box(0.0));
  const twin::MarkerErrors snap = meter.measure(box, 1, T_camera_box(0.0), 0.0);
  ASSERT_FALSE(std::isnan(snap.mean_mm));
  ASSERT_GE(snap.markers.size(), 3U);
  EXPECT_EQ(snap.markers.size(), now.markers.size());
  EXPECT_NEAR(snap.mean_mm, now.mean_mm, 1e-9);
  EXPECT_LT(snap.mean_mm, 1.0);  // the pixel that carries a marker's light: within half a pixel (~1 mm here)
  // 1 s in, the box has been carried 0.25 m: drawn where it then is, on its markers; drawn where it
  // stood, a quarter of a metre off (less where its markers leave the light).
  EXPECT_LT(meter.measure(box, 1, T_camera_box(1.0), 1.0).mean_mm, 1.0);
  const double left_behind = meter.measure(box, 1, T_camera_box(0.0), 1.0).mean_mm;
  EXPECT_GT(left_behind, 150.0);
  // A 5 mm slide sideways (camera x) of the drawn pose: the light lands at least that far off, farther
  // on the box's faces turned away from the projector (measured 7.7 mm).
  Eigen::Matrix4d slid = T_camera_box(0.0);
  slid(0, 3) += 0.005;
  const double slid_mm = meter.measure(box, 1, slid, 0.0).mean_mm;
  EXPECT_GT(slid_mm, 4.0);
  EXPECT_LT(slid_mm, 12.0);
}

TEST_F(BoxStop, AStopsMeterOutlivesTheTwinAndIgnoresItsLaterState) {
  const Eigen::Matrix4d drawn = T_camera_box(0.0);
  const auto meter = std::make_shared<const twin::StopMeter>(*world, models, T_world_projector);
  const double before = meter->measure(box, 1, drawn, 0.0).mean_mm;
  world->targets()[box].T_world_target_true(0, 3) += 1.0;  // the twin goes on (the next frame's capture)
  EXPECT_EQ(meter->measure(box, 1, drawn, 0.0).mean_mm, before);
  world.reset();  // the robot thread's twin is gone; a frame in flight still measures
  EXPECT_EQ(meter->measure(box, 1, drawn, 0.0).mean_mm, before);
}

}  // namespace
