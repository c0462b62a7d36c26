#pragma once
// What the twin's tests share: the demo scenes, short tours on a fixed processing time, a depth reading.

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
#include "projbot/live/stop_sequence.hpp"
#include "projbot/twin/appearance.hpp"
#include "projbot/twin/camera.hpp"
#include "projbot/twin/raycast.hpp"
#include "projbot/twin/spectator.hpp"
#include "projbot/twin/tour.hpp"
#include "projbot/twin/world.hpp"

namespace twin_test {

inline Eigen::Matrix4d translation(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
  return T;
}

inline const std::string kAssets = PROJBOT_ASSET_DIR;

inline std::string demo_tour_text() {
  std::ifstream in(kAssets + "/scenes/tour.yaml");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline projbot::config::Scene demo_with(const std::string& from, const std::string& to) {
  std::string text = demo_tour_text();
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("test: '" + from + "' not in the demo tour");
  text.replace(at, from.size(), to);
  return projbot::config::parse_scene(text, kAssets + "/scenes/tour.yaml");
}

inline std::string twin_error(const projbot::config::Scene& scene) {
  projbot::engine::Renderer renderer(projbot::engine::RendererOptions{});
  try {
    projbot::twin::Twin twin(scene, {}, renderer);
  } catch (const projbot::twin::TwinError& e) {
    return e.what();
  }
  return "";
}

// The demo tour's first visits (the box is moved on its second and left there), seed 3.
inline projbot::twin::TourReport short_demo_tour(projbot::twin::TourMode mode, int visits) {
  projbot::twin::TourOptions o;
  o.mode = mode;
  o.visits = visits;
  o.seed = 3;
  o.dwell_s = 3.0;
  return projbot::twin::run_tour(projbot::config::load_scene(kAssets + "/scenes/tour.yaml"), o);
}

// Tracking tours on a fixed simulated processing time (capture to pose, 20 ms), so what they measure
// does not depend on how busy the machine running the tests is.
inline projbot::twin::TourReport tracking_tour(const projbot::config::Scene& scene, int visits, double dwell_s,
                                               bool predict = true) {
  projbot::twin::TourOptions o;
  o.mode = projbot::twin::TourMode::tracking;
  o.visits = visits;
  o.dwell_s = dwell_s;
  o.predict = predict;
  o.processing_ms = 20.0;
  return projbot::twin::run_tour(scene, o);
}

// `scene` (motion.yaml) cut to one visit of the duck, with `motion` (moved to that visit) its only one.
inline projbot::config::Scene duck_alone(projbot::config::Scene scene, projbot::config::TargetMotion motion) {
  motion.visit = 1;
  scene.targets.at(static_cast<std::size_t>(scene.target_index("duck"))).motions = {motion};
  scene.visits = {"duck"};
  return scene;
}

// The depth camera's reading at the image centre, looking from `eye` towards `at` (world frame).
inline double centre_depth_m(projbot::twin::Twin& twin, const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
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

}  // namespace twin_test
