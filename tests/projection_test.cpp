#include "projbot/engine/projection.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

using projbot::config::ProjectorConfig;
using projbot::engine::clip_from_projector;

namespace {

// Framebuffer coordinate of a projector-frame point after clip, divide and the viewport (Vulkan rules).
Eigen::Vector3d to_framebuffer(const ProjectorConfig& p, const Eigen::Vector3d& x) {
  const Eigen::Vector4d clip = clip_from_projector(p) * x.homogeneous();
  const Eigen::Vector3d ndc = clip.head<3>() / clip.w();
  return {(ndc.x() + 1.0) * 0.5 * p.width_px, (ndc.y() + 1.0) * 0.5 * p.height_px, ndc.z()};
}

}  // namespace

TEST(ProjectionTest, PixelCentreConventionWithOffCentrePrincipalPoint) {
  ProjectorConfig p;
  p.width_px = 800;
  p.height_px = 600;
  p.fx_px = 900;
  p.fy_px = 700;  // non-square pixels
  p.cx_px = 350.25;
  p.cy_px = 280.75;
  p.near_m = 0.2;
  p.far_m = 8.0;
  for (const Eigen::Vector3d& x : {Eigen::Vector3d(0.1, -0.2, 1.3), Eigen::Vector3d(-0.4, 0.3, 2.7), Eigen::Vector3d(0, 0, 5)}) {
    const Eigen::Vector2d uv = p.project(x);
    EXPECT_NEAR(uv.x(), 900 * x.x() / x.z() + 350.25, 1e-9);
    EXPECT_NEAR(uv.y(), 700 * x.y() / x.z() + 280.75, 1e-9);
    // Pixel (i, j) has its centre at u = i: framebuffer coordinate i + 0.5.
    const Eigen::Vector3d fb = to_framebuffer(p, x);
    EXPECT_NEAR(fb.x(), uv.x() + 0.5, 1e-9);
    EXPECT_NEAR(fb.y(), uv.y() + 0.5, 1e-9);
  }
  // The principal point lands on the pixel centre (cx, cy).
  const Eigen::Vector3d centre = to_framebuffer(p, {0, 0, 1});
  EXPECT_NEAR(centre.x(), 350.75, 1e-9);
  EXPECT_NEAR(centre.y(), 281.25, 1e-9);
}

TEST(ProjectionTest, DepthRangeNearToFar) {
  ProjectorConfig p;
  p.near_m = 0.5;
  p.far_m = 4.0;
  EXPECT_NEAR(to_framebuffer(p, {0, 0, 0.5}).z(), 0.0, 1e-12);
  EXPECT_NEAR(to_framebuffer(p, {0, 0, 4.0}).z(), 1.0, 1e-12);
  EXPECT_LT(to_framebuffer(p, {0, 0, 1.0}).z(), to_framebuffer(p, {0, 0, 2.0}).z());  // nearer is smaller
}

TEST(ProjectionTest, GpuMatrixIsColumnMajor) {
  Eigen::Matrix4d m;
  for (int i = 0; i < 16; ++i) m(i / 4, i % 4) = i;
  const auto g = projbot::engine::to_gpu_matrix(m);
  EXPECT_FLOAT_EQ(g[1], 4.0F);  // column 0, row 1
  EXPECT_FLOAT_EQ(g[4], 1.0F);  // column 1, row 0
  EXPECT_FLOAT_EQ(g[15], 15.0F);
}

// The one pinhole type (issue 12): project and back-project are inverse, the projector's model is one, and
// a depth camera's intrinsics are the same type.
TEST(PinholeTest, ProjectAndBackProjectAreInverse) {
  const projbot::config::Pinhole k{640, 480, 520.0, 530.0, 318.2, 241.7};
  const Eigen::Vector3d p(0.12, -0.34, 1.7);
  const Eigen::Vector2d x = k.project(p);
  EXPECT_NEAR(x.x(), 520.0 * 0.12 / 1.7 + 318.2, 1e-12);
  EXPECT_NEAR(x.y(), 530.0 * -0.34 / 1.7 + 241.7, 1e-12);
  EXPECT_LT((k.back_project(x.x(), x.y(), 1.7) - p).norm(), 1e-12);
  int u = 0, v = 0;
  EXPECT_TRUE(k.nearest_pixel(p, u, v));
  EXPECT_EQ(u, static_cast<int>(std::lround(x.x())));
  EXPECT_FALSE(k.contains({640.0, 10.0}));
  EXPECT_TRUE(k.contains({639.9, 479.9}));
  // nearest_pixel rounds as lround does (half away from zero) at the image's edges, and refuses NaN.
  const projbot::config::Pinhole unit{640, 480, 1.0, 1.0, 0.0, 0.0};  // pixel position = (x, y) / z
  for (const double at : {-0.5, -0.49, 0.0, 2.5, 638.5, 639.49, 639.5}) {
    const bool inside = std::lround(at) >= 0 && std::lround(at) < 640;
    EXPECT_EQ(unit.nearest_pixel({at, 3.0, 1.0}, u, v), inside) << at;
    if (!inside) continue;
    EXPECT_EQ(u, std::lround(at)) << at;
    EXPECT_EQ(v, 3);
  }
  EXPECT_FALSE(unit.nearest_pixel({std::nan(""), 3.0, 1.0}, u, v));
  const ProjectorConfig projector;  // 1280x800, f 1400: a Pinhole too
  EXPECT_NEAR(projector.project({0.0, 0.0, 2.0}).x(), 639.5, 1e-12);
  const projbot::config::Pinhole& as_pinhole = projector;
  EXPECT_EQ(as_pinhole.width_px, 1280);
}
