#pragma once
// What the rendering tests share: a projector, small models made in code, the CPU's projection to check
// the GPU's image against, and the fixture with the validation layer on.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <fstream>
#include <random>
#include <thread>

#include "projbot/assets/model.hpp"
#include "projbot/assets/video.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/projection.hpp"
#include "projbot/engine/renderer.hpp"

namespace fs = std::filesystem;
using projbot::assets::Image;
using projbot::assets::Model;
using projbot::config::ProjectorConfig;
using projbot::engine::DrawItem;
using projbot::engine::Renderer;

namespace render_test {

inline const fs::path kData = fs::path(PROJBOT_SHARED_DATA) / "gltf";

inline ProjectorConfig projector(int w, int h, double fx, double fy, double cx, double cy) {
  ProjectorConfig p;
  p.width_px = w, p.height_px = h, p.fx_px = fx, p.fy_px = fy, p.cx_px = cx, p.cy_px = cy, p.near_m = 0.05, p.far_m = 20;
  return p;
}

inline Eigen::Matrix4d pose(double x, double y, double z, double roll, double pitch, double yaw) {
  return projbot::config::pose_from_xyz_rpy({x, y, z}, {roll, pitch, yaw});
}

inline Eigen::Vector3d pos(const projbot::assets::Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

// The model with every material replaced by plain white, for silhouettes.
inline Model white(Model m) {
  m.materials.assign(1, projbot::assets::Material{});
  m.materials[0].double_sided = true;
  m.images.clear();
  for (auto& p : m.primitives) {
    p.material = 0;
    for (auto& v : p.vertices) v.color = {1, 1, 1, 1};
  }
  return m;
}

// A model from triangles given in the model frame, each with one colour.
inline Model triangles(const std::vector<std::array<Eigen::Vector3d, 3>>& tris, const std::vector<std::array<float, 4>>& colors,
                       projbot::assets::Material material = {}) {
  Model m;
  m.source = "test-triangles";
  projbot::assets::Primitive p;
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (const auto& x : tris[t]) {
      projbot::assets::Vertex v;
      v.position = {static_cast<float>(x.x()), static_cast<float>(x.y()), static_cast<float>(x.z())};
      v.color = colors[t];
      p.indices.push_back(static_cast<std::uint32_t>(p.vertices.size()));
      p.vertices.push_back(v);
    }
  material.double_sided = true;
  m.materials.push_back(material);
  m.primitives.push_back(std::move(p));
  return m;
}

// A quad (two triangles) through four corners, one colour.
inline Model quad(const std::array<Eigen::Vector3d, 4>& c, std::array<float, 4> color, projbot::assets::Material material = {}) {
  Model m = triangles({{c[0], c[1], c[2]}, {c[0], c[2], c[3]}}, {color, color}, material);
  const std::array<std::array<float, 2>, 4> uv{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  const int corner[6] = {0, 1, 2, 0, 2, 3};
  for (int i = 0; i < 6; ++i) m.primitives[0].vertices[static_cast<std::size_t>(i)].uv = uv[static_cast<std::size_t>(corner[i])];
  return m;
}

// CPU reference: which pixel centres (u = i, v = j) lie inside any projected triangle (all in front).
inline std::vector<bool> cpu_silhouette(const Model& m, const Eigen::Matrix4d& T, const ProjectorConfig& p) {
  std::vector<bool> mask(static_cast<std::size_t>(p.width_px) * p.height_px, false);
  for (const auto& prim : m.primitives)
    for (std::size_t t = 0; t < prim.indices.size(); t += 3) {
      Eigen::Vector2d q[3];
      for (int k = 0; k < 3; ++k)
        q[k] = p.project((T * pos(prim.vertices[prim.indices[t + static_cast<std::size_t>(k)]]).homogeneous()).head<3>());
      const double area = (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
      if (std::abs(area) < 1e-12) continue;
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x(), q[1].x(), q[2].x()}))));
      const int x1 = std::min(p.width_px - 1, static_cast<int>(std::ceil(std::max({q[0].x(), q[1].x(), q[2].x()}))));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y(), q[1].y(), q[2].y()}))));
      const int y1 = std::min(p.height_px - 1, static_cast<int>(std::ceil(std::max({q[0].y(), q[1].y(), q[2].y()}))));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const Eigen::Vector2d c(x, y);
          bool inside = true;
          for (int k = 0; k < 3 && inside; ++k) {
            const Eigen::Vector2d a = q[k], b = q[(k + 1) % 3];
            const double e = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
            inside = (area > 0 ? e : -e) >= 0;
          }
          if (inside) mask[static_cast<std::size_t>(y) * p.width_px + x] = true;
        }
    }
  return mask;
}

inline std::vector<bool> lit_pixels(const Image& img) {
  std::vector<bool> mask(static_cast<std::size_t>(img.width) * img.height);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = img.rgba[i * 4] || img.rgba[i * 4 + 1] || img.rgba[i * 4 + 2];
  return mask;
}

inline double iou(const std::vector<bool>& a, const std::vector<bool>& b) {
  std::size_t inter = 0, uni = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    inter += (a[i] && b[i]) ? 1 : 0;
    uni += (a[i] || b[i]) ? 1 : 0;
  }
  return uni == 0 ? 1.0 : static_cast<double>(inter) / static_cast<double>(uni);
}

class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    projbot::engine::RendererOptions o;
    o.validation = true;
    renderer_ = std::make_unique<Renderer>(o);
    std::cout << "device: " << renderer_->device_info().name << '\n';
  }
  static void TearDownTestSuite() { renderer_.reset(); }
  void TearDown() override {
    // The validation layer saw every command of the test: it must have nothing to say.
    EXPECT_EQ(renderer_->validation_errors(), 0U);
    EXPECT_EQ(renderer_->validation_warnings(), 0U);
  }

  static Image render(const ProjectorConfig& p, const std::vector<DrawItem>& items) {
    auto target = renderer_->make_offscreen(p.width_px, p.height_px);
    EXPECT_TRUE(renderer_->draw_frame(*target, p, items));
    return target->read_back();
  }

  static inline std::unique_ptr<Renderer> renderer_;
};

}  // namespace render_test
