#pragma once
// What the synthetic-depth tests share: the Duck rendered by the engine's depth camera at known poses,
// with and without the Kinect v1 noise model.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <random>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

namespace synthetic_depth {

inline const fs::path kDuck = fs::path(PROJBOT_SHARED_DATA) / "gltf" / "Duck" / "glTF-Binary" / "Duck.glb";

inline projbot::config::Camera as_pinhole(const CameraIntrinsics& k) { return {k, 0.1, 10.0}; }

inline Eigen::Matrix4d perturb(const Eigen::Matrix4d& T, double angle_deg, double shift_m, std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Matrix4d D = Eigen::Matrix4d::Identity();
  D.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(projbot::config::radians(angle_deg), Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized())
          .toRotationMatrix();
  // Rotate about the target's own centre (its origin after recentring), then shift.
  Eigen::Matrix4d out = T;
  out.topLeftCorner<3, 3>() = D.topLeftCorner<3, 3>() * T.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() += shift_m * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  return out;
}

class SyntheticDepthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    renderer_ = std::make_unique<projbot::engine::Renderer>(projbot::engine::RendererOptions{});
    auto duck = projbot::assets::load_gltf(kDuck);
    projbot::assets::scale_and_recenter(duck, 0.2, true);  // a 32 cm toy
    model_id_ = renderer_->add_model(duck);
    model_ = std::make_unique<ModelCloud>(model_cloud_from(duck, 50000));
    camera_ = renderer_->make_depth_camera(k_.width_px, k_.height_px);
  }
  static void TearDownTestSuite() {
    camera_.reset();
    renderer_.reset();
    model_.reset();
  }

  static DepthImage render(const Eigen::Matrix4d& T_camera_target) {
    const std::vector<projbot::engine::DrawItem> items{{model_id_, T_camera_target}};
    renderer_->draw_frame(*camera_, as_pinhole(k_), items);
    const auto map = camera_->read_back_depth();
    return {map.width, map.height, map.z_m, 0.0};
  }

  // The textured box, 30 cm, 1.6 m away, nearly face-on (turned 8 degrees, tipped 10): its model cloud,
  // and depth and colour rendered at its pose (colour registered to depth, as a Kinect v1 delivers it).
  struct FaceOnBox {
    ModelCloud cloud;
    Eigen::Matrix4d T = projbot::config::pose_from_xyz_rpy({0.02, 0.05, 1.6}, {-10, 8, 0});
    DepthImage depth;
    projbot::assets::Image colour;
  };
  static FaceOnBox face_on_box(const std::optional<Eigen::Matrix4d>& T = std::nullopt) {
    FaceOnBox b;
    if (T) b.T = *T;
    auto box = projbot::assets::load_gltf(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF" / "BoxTextured.gltf");
    projbot::assets::scale_and_recenter(box, 0.3, true);
    const std::size_t id = renderer_->add_model(box);
    b.cloud = model_cloud_from(box, 50000);
    const std::vector<projbot::engine::DrawItem> items{{id, b.T}};
    renderer_->draw_frame(*camera_, as_pinhole(k_), items);
    const auto map = camera_->read_back_depth();
    b.depth = DepthImage{map.width, map.height, map.z_m, 0.0};
    const auto colour_target = renderer_->make_offscreen(k_.width_px, k_.height_px);
    renderer_->draw_frame(*colour_target, as_pinhole(k_), items);
    b.colour = colour_target->read_back();
    return b;
  }

  // The test poses: the duck upright (camera y is down) and turned, 0.8 - 2.0 m away.
  static std::vector<Eigen::Matrix4d> poses() {
    return {projbot::config::pose_from_xyz_rpy({0.05, -0.02, 0.8}, {180, 10, 30}),
            projbot::config::pose_from_xyz_rpy({-0.1, 0.05, 1.2}, {170, -20, -50}),
            projbot::config::pose_from_xyz_rpy({0.1, 0.1, 1.6}, {190, 0, 120}),
            projbot::config::pose_from_xyz_rpy({0.0, -0.1, 2.0}, {175, 15, -100})};
  }

  static inline std::unique_ptr<projbot::engine::Renderer> renderer_;
  static inline std::unique_ptr<projbot::engine::RenderTarget> camera_;
  static inline std::unique_ptr<ModelCloud> model_;
  static inline std::size_t model_id_ = 0;
  static inline const CameraIntrinsics k_ = CameraIntrinsics::kinect_v1();
};

}  // namespace synthetic_depth
