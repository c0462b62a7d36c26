// Rendering tests on whatever Vulkan device is there (lavapipe in CI), with the validation layer on:
// the GPU image is checked against an independent CPU projection of the same mesh (Eq. 3).

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

namespace {

const fs::path kData = fs::path(PROJBOT_SHARED_DATA) / "gltf";

ProjectorConfig projector(int w, int h, double fx, double fy, double cx, double cy) {
  ProjectorConfig p;
  p.width_px = w, p.height_px = h, p.fx_px = fx, p.fy_px = fy, p.cx_px = cx, p.cy_px = cy, p.near_m = 0.05, p.far_m = 20;
  return p;
}

Eigen::Matrix4d pose(double x, double y, double z, double roll, double pitch, double yaw) {
  return projbot::config::pose_from_xyz_rpy({x, y, z}, {roll, pitch, yaw});
}

Eigen::Vector3d pos(const projbot::assets::Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

// The model with every material replaced by plain white, for silhouettes.
Model white(Model m) {
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
Model triangles(const std::vector<std::array<Eigen::Vector3d, 3>>& tris, const std::vector<std::array<float, 4>>& colors,
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
Model quad(const std::array<Eigen::Vector3d, 4>& c, std::array<float, 4> color, projbot::assets::Material material = {}) {
  Model m = triangles({{c[0], c[1], c[2]}, {c[0], c[2], c[3]}}, {color, color}, material);
  const std::array<std::array<float, 2>, 4> uv{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
  const int corner[6] = {0, 1, 2, 0, 2, 3};
  for (int i = 0; i < 6; ++i) m.primitives[0].vertices[static_cast<std::size_t>(i)].uv = uv[static_cast<std::size_t>(corner[i])];
  return m;
}

// CPU reference: which pixel centres (u = i, v = j) lie inside any projected triangle (all in front).
std::vector<bool> cpu_silhouette(const Model& m, const Eigen::Matrix4d& T, const ProjectorConfig& p) {
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

std::vector<bool> lit_pixels(const Image& img) {
  std::vector<bool> mask(static_cast<std::size_t>(img.width) * img.height);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = img.rgba[i * 4] || img.rgba[i * 4 + 1] || img.rgba[i * 4 + 2];
  return mask;
}

double iou(const std::vector<bool>& a, const std::vector<bool>& b) {
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

}  // namespace

TEST_F(RenderTest, SilhouetteMatchesCpuProjection) {
  Model duck = white(projbot::assets::load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb"));
  projbot::assets::scale_and_recenter(duck, 0.25, true);
  Model box = white(projbot::assets::load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf"));
  projbot::assets::scale_and_recenter(box, 0.3, true);
  const std::size_t duck_id = renderer_->add_model(duck);
  const std::size_t box_id = renderer_->add_model(box);
  struct Case {
    ProjectorConfig p;
    Eigen::Matrix4d T;
    bool use_duck;
  };
  const std::vector<Case> cases{
      {projector(640, 480, 600, 600, 319.5, 239.5), pose(0, 0, 1.0, 180, 0, 0), true},
      {projector(640, 480, 700, 560, 250.3, 300.7), pose(0.05, -0.03, 0.9, 160, 30, 45), true},  // off-centre, fx != fy
      {projector(800, 500, 900, 1000, 480.0, 180.0), pose(-0.1, 0.08, 1.4, 200, -40, 110), true},
      {projector(640, 480, 650, 520, 300.0, 260.0), pose(0.02, 0.01, 0.8, 25, 35, 10), false},
      {projector(500, 700, 800, 800, 200.0, 420.0), pose(-0.05, 0.1, 1.1, 120, 200, -30), false},
  };
  for (const auto& c : cases) {
    const Model& m = c.use_duck ? duck : box;
    const Image img = render(c.p, {{c.use_duck ? duck_id : box_id, c.T}});
    const auto gpu = lit_pixels(img);
    const auto cpu = cpu_silhouette(m, c.T, c.p);
    std::size_t lit = 0;
    for (bool b : cpu) lit += b ? 1 : 0;
    ASSERT_GT(lit, 5000U) << "the case must show the model large enough to measure";
    EXPECT_GE(iou(gpu, cpu), 0.99) << "fx " << c.p.fx_px << " cx " << c.p.cx_px;
  }
}

TEST_F(RenderTest, ProjectedVertexPositionsWithinHalfPixel) {
  // Small marker triangles, each in its own colour, centred on Duck vertices. The centroid of the pixels a
  // marker covers is compared with the centroid of its three CPU-projected corners.
  Model duck = projbot::assets::load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  projbot::assets::scale_and_recenter(duck, 0.25, true);
  for (const auto& [p, T] : std::vector<std::pair<ProjectorConfig, Eigen::Matrix4d>>{
           {projector(800, 600, 900, 750, 420.5, 260.25), pose(0.02, -0.01, 1.0, 170, 20, 35)},
           {projector(640, 480, 600, 640, 300.0, 250.0), pose(-0.03, 0.02, 0.8, 200, -25, -60)}}) {
    std::vector<std::array<Eigen::Vector3d, 3>> tris;
    std::vector<std::array<float, 4>> colors;
    const Eigen::Matrix4d T_inv = T.inverse();
    const auto& verts = duck.primitives[0].vertices;
    // Markers at least 40 px apart and inside the image, so none hides part of another.
    std::vector<Eigen::Vector2d> centres;
    for (std::size_t v = 0; v < verts.size() && centres.size() < 40; v += 7) {
      const Eigen::Vector3d c = (T * pos(verts[v]).homogeneous()).head<3>();  // projector frame
      const Eigen::Vector2d uv = p.project(c);
      if (uv.x() < 20 || uv.y() < 20 || uv.x() > p.width_px - 20 || uv.y() > p.height_px - 20) continue;
      if (std::any_of(centres.begin(), centres.end(), [&](const Eigen::Vector2d& o) { return (o - uv).norm() < 40; })) continue;
      centres.push_back(uv);
      const std::size_t k = tris.size();
      const double r = 14.0 * c.z() / p.fx_px;  // about 14 px radius
      std::array<Eigen::Vector3d, 3> tri;
      for (int i = 0; i < 3; ++i) {
        const double a = 2.0 * M_PI * i / 3.0 + 0.3 * static_cast<double>(k);
        tri[static_cast<std::size_t>(i)] =
            (T_inv * (c + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0)).homogeneous()).head<3>();
      }
      tris.push_back(tri);
      colors.push_back({static_cast<float>(k + 1) / 255.0F, 1.0F, 0.0F, 1.0F});
    }
    const Model markers = triangles(tris, colors);
    const Image img = render(p, {{renderer_->add_model(markers), T}});
    std::vector<Eigen::Vector3d> sums(tris.size(), Eigen::Vector3d::Zero());  // x, y, count
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const auto* px = img.pixel(x, y);
        if (px[1] != 255 || px[0] == 0) continue;
        sums[static_cast<std::size_t>(px[0] - 1)] += Eigen::Vector3d(x, y, 1);
      }
    std::size_t seen = 0;
    double worst = 0;
    for (std::size_t k = 0; k < tris.size(); ++k) {
      ASSERT_GT(sums[k].z(), 150) << "marker " << k << " is not fully visible";
      Eigen::Vector2d expected = Eigen::Vector2d::Zero();
      for (const auto& x : tris[k]) expected += p.project((T * x.homogeneous()).head<3>()) / 3.0;
      const Eigen::Vector2d measured = sums[k].head<2>() / sums[k].z();
      worst = std::max(worst, (measured - expected).norm());
      ++seen;
    }
    EXPECT_GE(seen, 15U);
    EXPECT_LT(worst, 0.5) << "worst marker offset in pixels";
    std::cout << seen << " markers, worst offset " << worst << " px\n";
  }
}

TEST_F(RenderTest, TextureColourLandsWhereCpuPredicts) {
  Model box = projbot::assets::load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf");
  projbot::assets::scale_and_recenter(box, 0.2, true);
  const ProjectorConfig p = projector(640, 480, 650, 640, 330.0, 235.0);
  const Eigen::Matrix4d T = pose(0.0, 0.0, 0.45, 150, 35, 20);
  const Image img = render(p, {{renderer_->add_model(box), T}});
  const Image& tex = box.images[0];
  const auto texel = [&](int x, int y) {
    x = ((x % tex.width) + tex.width) % tex.width;  // REPEAT
    y = ((y % tex.height) + tex.height) % tex.height;
    return tex.pixel(x, y);
  };
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uni(0, 1);
  const auto& prim = box.primitives[0];
  int checked = 0, matched = 0;
  for (int trial = 0; trial < 4000 && checked < 200; ++trial) {
    const std::size_t t = 3 * (rng() % (prim.indices.size() / 3));
    const auto& a = prim.vertices[prim.indices[t]];
    const auto& b = prim.vertices[prim.indices[t + 1]];
    const auto& c = prim.vertices[prim.indices[t + 2]];
    double s = uni(rng), r = uni(rng);
    if (s + r > 1) s = 1 - s, r = 1 - r;
    const Eigen::Vector3d x = pos(a) + s * (pos(b) - pos(a)) + r * (pos(c) - pos(a));
    const Eigen::Vector3d xp = (T * x.homogeneous()).head<3>();
    const Eigen::Vector3d n = T.topLeftCorner<3, 3>() * (pos(b) - pos(a)).cross(pos(c) - pos(a));
    if (n.dot(xp) >= -0.3 * n.norm() * xp.norm()) continue;  // keep faces that clearly face the projector
    const Eigen::Vector2d uv_px = p.project(xp);
    const int i = static_cast<int>(std::lround(uv_px.x())), j = static_cast<int>(std::lround(uv_px.y()));
    // Stay 3 px inside the triangle so the pixel centre belongs to this face.
    Eigen::Vector2d q[3];
    for (int k = 0; k < 3; ++k)
      q[k] = p.project((T * pos(prim.vertices[prim.indices[t + static_cast<std::size_t>(k)]]).homogeneous()).head<3>());
    bool inside = true;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d e = q[(k + 1) % 3] - q[k];
      const double dist = std::abs(e.x() * (j - q[k].y()) - e.y() * (i - q[k].x())) / e.norm();
      inside = inside && dist > 3.0;
    }
    if (!inside) continue;
    const double u = a.uv[0] + s * (b.uv[0] - a.uv[0]) + r * (c.uv[0] - a.uv[0]);
    const double v = a.uv[1] + s * (b.uv[1] - a.uv[1]) + r * (c.uv[1] - a.uv[1]);
    const int tx = static_cast<int>(std::floor(u * tex.width)), ty = static_cast<int>(std::floor(v * tex.height));
    // Only where the texture is uniform for 4 texels around: the pixel centre is within a texel or two.
    bool uniform = true;
    for (int dy = -4; dy <= 4 && uniform; ++dy)
      for (int dx = -4; dx <= 4 && uniform; ++dx) uniform = std::memcmp(texel(tx + dx, ty + dy), texel(tx, ty), 3) == 0;
    if (!uniform) continue;
    ++checked;
    const auto* want = texel(tx, ty);
    const auto* got = img.pixel(i, j);
    bool same = true;
    for (int k = 0; k < 3; ++k) same = same && std::abs(int(want[k]) - int(got[k])) <= 2;
    matched += same ? 1 : 0;
    EXPECT_TRUE(same) << "pixel (" << i << "," << j << ") shows " << int(got[0]) << "," << int(got[1]) << "," << int(got[2])
                      << " but texel (" << tx << "," << ty << ") is " << int(want[0]) << "," << int(want[1]) << ","
                      << int(want[2]);
  }
  EXPECT_GE(checked, 100) << "too few uniform texture points were checked";
}

TEST_F(RenderTest, TextureValuesAreReproducedAsStored) {
  // A 2x2 texture with nearest filtering: the UNORM path must not apply any sRGB curve.
  Model m = quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                  Eigen::Vector3d(-0.5, 0.5, 1)},
                 {1, 1, 1, 1});
  Image tex;
  tex.width = tex.height = 2;
  tex.rgba = {10, 20, 30, 255, 100, 128, 140, 255, 200, 64, 1, 255, 255, 250, 5, 255};
  m.images.push_back(tex);
  m.materials[0].base_color_image = 0;
  m.materials[0].sampler.mag = m.materials[0].sampler.min = projbot::assets::Filter::kNearest;
  const ProjectorConfig p = projector(200, 200, 150, 150, 99.5, 99.5);
  const Image img = render(p, {{renderer_->add_model(m), Eigen::Matrix4d::Identity()}});
  // Quad corner (-0.5,-0.5) has uv (0,0) and lands top-left: each quadrant shows one texel.
  const int at[4][2] = {{70, 70}, {130, 70}, {70, 130}, {130, 130}};
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      EXPECT_EQ(img.pixel(at[k][0], at[k][1])[c], tex.rgba[static_cast<std::size_t>(k * 4 + c)]) << "texel " << k;
}

TEST_F(RenderTest, BaseColorFactorAndVertexColourMultiply) {
  projbot::assets::Material mat;
  mat.base_color_factor = {0.5F, 1.0F, 0.25F, 1.0F};
  Model m = quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                  Eigen::Vector3d(-0.5, 0.5, 1)},
                 {1.0F, 0.5F, 1.0F, 1.0F}, mat);
  const ProjectorConfig p = projector(100, 100, 80, 80, 49.5, 49.5);
  const Image img = render(p, {{renderer_->add_model(m), Eigen::Matrix4d::Identity()}});
  EXPECT_NEAR(img.pixel(50, 50)[0], 128, 1);
  EXPECT_NEAR(img.pixel(50, 50)[1], 128, 1);
  EXPECT_NEAR(img.pixel(50, 50)[2], 64, 1);
  EXPECT_EQ(img.pixel(2, 2)[0], 0);  // background is black
}

TEST_F(RenderTest, AlphaModes) {
  const std::array<Eigen::Vector3d, 4> c{Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1),
                                         Eigen::Vector3d(0.5, 0.5, 1), Eigen::Vector3d(-0.5, 0.5, 1)};
  projbot::assets::Material mask;
  mask.alpha_mode = projbot::assets::AlphaMode::kMask;
  mask.alpha_cutoff = 0.5F;
  projbot::assets::Material blend;
  blend.alpha_mode = projbot::assets::AlphaMode::kBlend;
  const std::size_t below = renderer_->add_model(quad(c, {1, 1, 1, 0.3F}, mask));
  const std::size_t above = renderer_->add_model(quad(c, {1, 1, 1, 0.7F}, mask));
  const std::size_t half = renderer_->add_model(quad(c, {1, 1, 1, 0.5F}, blend));
  const std::size_t opaque = renderer_->add_model(quad(c, {1, 1, 1, 0.1F}));
  const ProjectorConfig p = projector(100, 100, 80, 80, 49.5, 49.5);
  EXPECT_EQ(render(p, {{below, Eigen::Matrix4d::Identity()}}).pixel(50, 50)[0], 0);        // discarded
  EXPECT_EQ(render(p, {{above, Eigen::Matrix4d::Identity()}}).pixel(50, 50)[0], 255);      // kept, alpha ignored
  EXPECT_NEAR(render(p, {{half, Eigen::Matrix4d::Identity()}}).pixel(50, 50)[0], 128, 1);  // half over black
  EXPECT_EQ(render(p, {{opaque, Eigen::Matrix4d::Identity()}}).pixel(50, 50)[0], 255);     // OPAQUE ignores alpha
}

TEST_F(RenderTest, DepthTestBetweenTwoTargetsInEitherOrder) {
  const auto square = [](double half, double z) {
    return std::array<Eigen::Vector3d, 4>{Eigen::Vector3d(-half, -half, z), Eigen::Vector3d(half, -half, z),
                                          Eigen::Vector3d(half, half, z), Eigen::Vector3d(-half, half, z)};
  };
  const std::size_t near_red = renderer_->add_model(quad(square(0.2, 0), {1, 0, 0, 1}));
  const std::size_t far_green = renderer_->add_model(quad(square(0.6, 0), {0, 1, 0, 1}));
  const ProjectorConfig p = projector(200, 200, 150, 150, 99.5, 99.5);
  const Eigen::Matrix4d Tn = pose(0, 0, 1.0, 0, 0, 0), Tf = pose(0, 0, 1.5, 0, 0, 0);
  for (const auto& items :
       {std::vector<DrawItem>{{near_red, Tn}, {far_green, Tf}}, std::vector<DrawItem>{{far_green, Tf}, {near_red, Tn}}}) {
    const Image img = render(p, items);
    EXPECT_EQ(img.pixel(100, 100)[0], 255);  // the nearer red square wins in the middle
    EXPECT_EQ(img.pixel(100, 100)[1], 0);
    EXPECT_EQ(img.pixel(100, 50)[1], 255);  // only the green one covers here (it spans 40..160)
    EXPECT_EQ(img.pixel(100, 50)[0], 0);
  }
}

TEST_F(RenderTest, TargetPartlyBehindTheProjector) {
  // A floor strip at y = 0.3 from z = -1 (behind) to z = 3: only its part in front of the near plane shows.
  const ProjectorConfig p = projector(320, 240, 250, 250, 159.5, 119.5);
  const std::size_t strip = renderer_->add_model(quad({Eigen::Vector3d(-0.5, 0.3, -1), Eigen::Vector3d(0.5, 0.3, -1),
                                                       Eigen::Vector3d(0.5, 0.3, 3), Eigen::Vector3d(-0.5, 0.3, 3)},
                                                      {1, 1, 1, 1}));
  const Image img = render(p, {{strip, Eigen::Matrix4d::Identity()}});
  std::vector<bool> expected(static_cast<std::size_t>(p.width_px) * p.height_px);
  for (int j = 0; j < p.height_px; ++j)
    for (int i = 0; i < p.width_px; ++i) {
      const double dx = (i - p.cx_px) / p.fx_px, dy = (j - p.cy_px) / p.fy_px;
      if (dy <= 0) continue;
      const double z = 0.3 / dy;  // the ray meets y = 0.3 at depth z
      expected[static_cast<std::size_t>(j) * p.width_px + i] = z >= p.near_m && z <= 3.0 && std::abs(z * dx) <= 0.5;
    }
  EXPECT_GE(iou(lit_pixels(img), expected), 0.99);
  // Entirely behind: nothing at all.
  const Image behind = render(p, {{strip, pose(0, 0, -5, 0, 0, 0)}});
  for (bool lit : lit_pixels(behind)) ASSERT_FALSE(lit);
}

TEST_F(RenderTest, TargetPartlyOutsideTheImageMatchesACrop) {
  // A smaller image whose principal point is shifted is a crop of the larger one.
  Model duck = projbot::assets::load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  projbot::assets::scale_and_recenter(duck, 0.25, true);
  const std::size_t id = renderer_->add_model(duck);
  const Eigen::Matrix4d T = pose(0.03, 0.0, 0.7, 180, 10, 25);
  const ProjectorConfig big = projector(640, 480, 600, 600, 319.5, 239.5);
  const ProjectorConfig crop = projector(300, 200, 600, 600, 319.5 - 200, 239.5 - 150);
  const Image a = render(big, {{id, T}});
  const Image b = render(crop, {{id, T}});
  std::size_t differ = 0, lit = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 300; ++x) {
      const auto* pa = a.pixel(x + 200, y + 150);
      const auto* pb = b.pixel(x, y);
      lit += pb[0] ? 1 : 0;
      for (int c = 0; c < 3; ++c) differ += std::abs(int(pa[c]) - int(pb[c])) > 2 ? 1 : 0;
    }
  EXPECT_GT(lit, 20000U);   // the duck fills much of the crop...
  EXPECT_LT(differ, 300U);  // ...and it is the same picture (edge pixels may round differently)
}

TEST_F(RenderTest, ProfilerGetsOneRecordPerFrame) {
  Model box = projbot::assets::load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf");
  const std::size_t id = renderer_->add_model(box);
  const ProjectorConfig p = projector(160, 120, 150, 150, 79.5, 59.5);
  auto target = renderer_->make_offscreen(p.width_px, p.height_px);
  projbot::engine::FrameProfiler prof;
  int pose_reads = 0;
  for (int i = 0; i < 12; ++i)
    renderer_->draw_frame(
        *target, p,
        [&](std::vector<DrawItem>& items) {
          ++pose_reads;
          items.push_back({id, pose(0, 0, 2, 0, 0, 0)});
        },
        &prof);
  renderer_->finish(*target);
  EXPECT_EQ(pose_reads, 12);
  ASSERT_EQ(prof.records().size(), 12U);
  for (const auto& r : prof.records()) {
    EXPECT_LE(r.start_ms, r.pose_read_ms);
    EXPECT_LE(r.pose_read_ms, r.recorded_ms);
    EXPECT_LE(r.recorded_ms, r.submitted_ms);
    EXPECT_LE(r.submitted_ms, r.completed_ms);
    if (renderer_->device_info().gpu_timestamps) {
      EXPECT_GE(r.gpu_ms, 0.0);
    }
  }
}

TEST_F(RenderTest, BadRequestsAreErrors) {
  EXPECT_THROW(renderer_->make_offscreen(0, 10), projbot::engine::EngineError);
  const ProjectorConfig p = projector(16, 16, 10, 10, 7.5, 7.5);
  auto target = renderer_->make_offscreen(16, 16);
  EXPECT_THROW(target->read_back(), projbot::engine::EngineError);  // nothing drawn yet
  EXPECT_THROW(renderer_->draw_frame(*target, p, std::vector<DrawItem>{{999, Eigen::Matrix4d::Identity()}}),
               projbot::engine::EngineError);
  Model empty;
  empty.source = "empty";
  EXPECT_THROW(renderer_->add_model(empty), projbot::engine::EngineError);
}

// The lens pass (issue 13): with the projector's distortion, content drawn for a ray lands on the panel
// pixel the lens sends along that ray (config::ProjectorConfig::project_lit). Small white squares over the
// whole image, corners included, on the rays of known panel pixels: the weighted centroid of each one's
// pixels against that panel pixel, tens of pixels from where a pinhole would draw it near the corners. Each
// frame is drawn 25 times, the squares moved by a fifth of a pixel each way, so that the rasteriser's pixel
// quantisation averages out and a systematic offset (a half-pixel convention, a wrong canvas margin) shows.
TEST_F(RenderTest, LensPassPutsContentWhereTheLensSendsIt) {
  ProjectorConfig p = projector(640, 480, 600, 600, 319.5, 239.5);
  p.distortion = {-0.22, 0.06, 0.002, -0.0015, 0.0};
  const double half = 0.006;  // a 12 mm square at 1 m: about 7 px
  const std::size_t id = renderer_->add_model(
      quad({Eigen::Vector3d(-half, -half, 0), {half, -half, 0}, {half, half, 0}, {-half, half, 0}}, {1, 1, 1, 1}));
  std::vector<Eigen::Vector2d> panel;
  for (const double v : {20.0, 240.0, 460.0})
    for (const double u : {20.0, 180.0, 320.0, 460.0, 620.0}) panel.emplace_back(u, v);
  std::vector<Eigen::Vector2d> offset(panel.size(), Eigen::Vector2d::Zero());
  double largest_shift = 0.0;
  constexpr double kSteps[] = {-0.37, -0.17, 0.03, 0.23, 0.43};  // off the half pixels, where rasterisers break ties
  for (const double du : kSteps)
    for (const double dv : kSteps) {
      std::vector<DrawItem> items;
      for (const Eigen::Vector2d& x : panel) {
        const auto ray = p.panel_ray(x.x() + du, x.y() + dv);
        ASSERT_TRUE(ray);
        items.push_back({id, pose(ray->x(), ray->y(), 1.0, 0, 0, 0)});
        largest_shift = std::max(largest_shift, (p.project(*ray) - x).norm());
      }
      const Image img = render(p, items);
      std::vector<Eigen::Vector3d> sums(panel.size(), Eigen::Vector3d::Zero());
      for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
          if (img.pixel(x, y)[0] == 0) continue;
          std::size_t k = 0;  // the nearest square's (they are 140 px apart or more)
          for (std::size_t j = 1; j < panel.size(); ++j)
            if ((panel[j] - Eigen::Vector2d(x, y)).norm() < (panel[k] - Eigen::Vector2d(x, y)).norm()) k = j;
          sums[k] += img.pixel(x, y)[0] / 255.0 * Eigen::Vector3d(x, y, 1);
        }
      for (std::size_t k = 0; k < panel.size(); ++k) {
        ASSERT_GT(sums[k].z(), 25.0) << "square at " << panel[k].transpose() << " not drawn";
        offset[k] += (sums[k].head<2>() / sums[k].z() - panel[k] - Eigen::Vector2d(du, dv)) / 25.0;
      }
    }
  double worst = 0.0;
  for (const auto& o : offset) worst = std::max(worst, o.norm());
  std::cout << "lens pass: worst mean centroid offset " << worst << " px; the lens moves content up to " << largest_shift
            << " px\n";
  EXPECT_LT(worst, 0.15);  // a pinhole projector (no lens pass) draws these squares to 0.099 px by the same measure
  EXPECT_GT(largest_shift, 30.0) << "the case must have a lens worth correcting";
}

// A barrel lens throws the panel's corners' light outside the pinhole's image: the canvas holds those rays,
// so a surface filling the whole view lights every panel pixel (none left black at the corners).
// The lens pass's map of rays is made once per target and lens: a target drawn through one lens and
// then another shows the second lens, pixel for pixel as a new target does, and not the first.
TEST_F(RenderTest, LensPassFollowsALensChangeOnTheSameTarget) {
  ProjectorConfig a = projector(160, 100, 150, 150, 79.5, 49.5), b = a;
  // Mirror images in y: their canvases have one size (the margins above and below trade places), so
  // only the lens itself tells that the map must be made again.
  a.distortion = {-0.3, 0.08, 0.004, 0.0, 0.0};
  b.distortion = {-0.3, 0.08, -0.004, 0.0, 0.0};
  const auto ca = projbot::engine::lens_canvas(a), cb = projbot::engine::lens_canvas(b);
  ASSERT_EQ(ca.pinhole.width_px, cb.pinhole.width_px);
  ASSERT_EQ(ca.pinhole.height_px, cb.pinhole.height_px);
  const std::size_t id = renderer_->add_model(
      quad({Eigen::Vector3d(-0.2, -0.15, 0), {0.25, -0.15, 0}, {0.25, 0.1, 0}, {-0.2, 0.1, 0}}, {1, 0.5F, 0.25F, 1}));
  const std::vector<DrawItem> items{{id, pose(0, 0, 1.0, 0, 0, 0)}};
  auto target = renderer_->make_offscreen(a.width_px, a.height_px);
  ASSERT_TRUE(renderer_->draw_frame(*target, a, items));
  const Image through_a = target->read_back();
  ASSERT_TRUE(renderer_->draw_frame(*target, b, items));
  const Image through_b = target->read_back();
  EXPECT_EQ(through_b.rgba, render(b, items).rgba);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < through_a.rgba.size(); ++i) differ += through_a.rgba[i] != through_b.rgba[i] ? 1 : 0;
  EXPECT_GT(differ, 400U) << "the two lenses must place the quad differently";
}

TEST_F(RenderTest, LensPassFillsThePanelOutToTheCorners) {
  ProjectorConfig p = projector(320, 200, 300, 300, 159.5, 99.5);
  p.distortion = {-0.3, 0.08, 0.0, 0.0, 0.0};
  const auto corner = p.panel_ray(-0.5, -0.5);
  ASSERT_TRUE(corner);
  ASSERT_LT(p.fx_px * corner->x() + p.cx_px, -5.0) << "the corner's ray must leave the pinhole's image";
  const double s = 2.0;  // a 4 m wall 1 m away: wider than every ray
  const std::size_t id =
      renderer_->add_model(quad({Eigen::Vector3d(-s, -s, 0), {s, -s, 0}, {s, s, 0}, {-s, s, 0}}, {0.5F, 1, 1, 1}));
  const Image img = render(p, {{id, pose(0, 0, 1.0, 0, 0, 0)}});
  std::size_t dark = 0;
  for (std::size_t i = 0; i < img.rgba.size(); i += 4) dark += img.rgba[i + 1] != 255 ? 1 : 0;
  EXPECT_EQ(dark, 0U) << "panel pixels left unlit";
}

TEST_F(RenderTest, StreamedTextureShowsTheFrameOfEachDraw) {
  // A video on a material (issue 44): each frame drawn shows the texels streamed for it, through both frame
  // slots, the quad's texture filling pixels 25..174 of the target.
  Model m = quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                  Eigen::Vector3d(-0.5, 0.5, 1)},
                 {1, 1, 1, 1});
  const std::size_t model = renderer_->add_model(m);
  const std::size_t tex = renderer_->add_streamed_texture(model, 0, 320, 240);
  const ProjectorConfig p = projector(200, 200, 150, 150, 99.5, 99.5);
  auto target = renderer_->make_offscreen(p.width_px, p.height_px);
  const std::vector<DrawItem> items{{model, Eigen::Matrix4d::Identity()}};
  ASSERT_TRUE(renderer_->draw_frame(*target, p, items));
  EXPECT_EQ(target->read_back().pixel(100, 150)[0], 0);  // black until a frame comes
  projbot::engine::FrameProfiler profiler;
  for (std::int64_t n : {3, 4, 5, 900, 901}) {
    renderer_->stream_frame(tex, std::make_shared<Image>(projbot::assets::frame_code_image(n, 320, 240)));
    ASSERT_TRUE(renderer_->draw_frame(*target, p, items, &profiler));
    EXPECT_EQ(projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150), n);
  }
  // Drawn again with nothing new streamed: the last frame stays.
  ASSERT_TRUE(renderer_->draw_frame(*target, p, items, &profiler));
  EXPECT_EQ(projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150), 901);
  renderer_->finish(*target);
  ASSERT_EQ(profiler.records().size(), 6U);
  EXPECT_GT(profiler.records()[0].upload_ms, 0.0);
  EXPECT_THROW(renderer_->stream_frame(tex, std::make_shared<Image>(projbot::assets::frame_code_image(1, 32, 24))),
               projbot::engine::EngineError);
  EXPECT_THROW(renderer_->add_streamed_texture(model, 1, 32, 32), projbot::engine::EngineError);
}

namespace {

// Issue 44's tests: one target, a white quad 1 m before the projector filling pixels 25..174 of a 200 x 200
// target (or 20..79 of 100 x 100), wearing `content`, uploaded to `renderer`.
struct ContentQuad {
  projbot::config::Scene scene;
  std::vector<Model> models;
  std::vector<DrawItem> items;
};

ContentQuad content_quad(Renderer& renderer, const ProjectorConfig& p, const projbot::config::TargetContent& content) {
  ContentQuad q;
  q.scene.projector = p;
  projbot::config::TargetConfig t;
  t.name = "a";
  t.content = content;
  q.scene.targets.push_back(t);
  q.models.push_back(quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                           Eigen::Vector3d(-0.5, 0.5, 1)},
                          {1, 1, 1, 1}));
  q.items.push_back({renderer.add_model(q.models[0]), Eigen::Matrix4d::Identity()});
  return q;
}

projbot::config::TargetContent video_content(const fs::path& clip) {
  projbot::config::TargetContent c;
  c.video = clip;
  c.loop = false;
  return c;
}

}  // namespace

TEST(SceneContentMaterial, ByNameIndexOrFirstTextured) {
  Model m;
  m.source = "m.glb";
  m.materials.resize(3);
  m.materials[1].name = "Label";
  m.images.resize(1);
  m.materials[2].base_color_image = 0;
  EXPECT_EQ(projbot::engine::content_material(m, ""), 2);
  EXPECT_EQ(projbot::engine::content_material(m, "Label"), 1);
  EXPECT_EQ(projbot::engine::content_material(m, "0"), 0);
  try {
    projbot::engine::content_material(m, "glass");
    ADD_FAILURE() << "no throw";
  } catch (const projbot::assets::AssetError& e) {
    EXPECT_NE(std::string(e.what()).find("m.glb: no material 'glass' for the content (it has 0, 1 'Label', 2)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(projbot::engine::content_material(m, "3"), projbot::assets::AssetError);
  m.materials[2].base_color_image = -1;
  EXPECT_EQ(projbot::engine::content_material(m, ""), 0);
}

TEST_F(RenderTest, SceneContentDrawsTheVideoFrameOfEachDisplayTime) {
  // A 30 fps clip on a quad (issue 44): the frame drawn for content time t shows video frame floor(30 t).
  const fs::path clip = fs::temp_directory_path() / ("projbot_render_content_" + std::to_string(::getpid()) + ".mp4");
  {
    projbot::assets::VideoWriter w(clip, 320, 240, 30);
    for (int i = 0; i < 40; ++i) w.write(projbot::assets::frame_code_image(i, 320, 240));
    w.finish();
  }
  const ContentQuad q = content_quad(*renderer_, projector(200, 200, 150, 150, 99.5, 99.5), video_content(clip));
  const projbot::config::Scene& scene = q.scene;
  const std::vector<DrawItem>& items = q.items;
  projbot::engine::SceneContent content(*renderer_, scene, q.models, items);
  ASSERT_TRUE(content.has(0));
  EXPECT_FALSE(content.has(1));
  auto target = renderer_->make_offscreen(200, 200);
  for (const double at : {0.0, 0.02, 0.034, 0.1, 0.25, 0.5, 0.9}) {
    const auto expected = static_cast<std::int64_t>(std::floor(at * 30.0 + 1e-9));
    // The test waits for the decoder (a renderer never does): up to 2 s for the frame of `at` to be decoded.
    projbot::engine::SceneContent::Sample s;
    for (int k = 0; k < 1000; ++k) {
      s = content.show(0, at);
      if (std::abs(s.pts_s - static_cast<double>(expected) / 30.0) < 1e-3) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_TRUE(renderer_->draw_frame(*target, scene.projector, items));
    EXPECT_EQ(projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150), expected) << "content time " << at;
  }
  // Past its end without looping: the last frame stays.
  content.show(0, 5.0);
  for (int k = 0; k < 500 && content.show(0, 5.0).pts_s < 39.0 / 30.0 - 1e-3; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_TRUE(renderer_->draw_frame(*target, scene.projector, items));
  EXPECT_EQ(projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150), 39);
  EXPECT_TRUE(content.take_errors().empty());
  renderer_->finish(*target);
  fs::remove(clip);
}

TEST_F(RenderTest, SceneContentTimelineAnimatesTheBaseColourFactor) {
  // A timeline (issue 44) on a white quad: red at 0 s, blue at 2 s, looping; the colour drawn at each content
  // time against the linear interpolation between the keys (CPU reference), within one 8-bit step.
  projbot::config::TargetContent timeline;
  timeline.timeline = {{0.0, {1.0, 0.0, 0.0, 1.0}}, {2.0, {0.0, 0.0, 1.0, 1.0}}};
  const ContentQuad q = content_quad(*renderer_, projector(100, 100, 80, 80, 49.5, 49.5), timeline);
  const projbot::config::Scene& scene = q.scene;
  const std::size_t model = q.items[0].model;
  projbot::engine::SceneContent content(*renderer_, scene, q.models, q.items);
  ASSERT_TRUE(content.has(0));
  EXPECT_FALSE(content.has_video(0));
  for (const double at : {0.0, 0.5, 1.5, 2.5, -1.0}) {
    std::vector<DrawItem> items = q.items;
    content.animate(0, at, items[0]);
    const Image img = render(scene.projector, items);
    const double phase = std::fmod(std::max(0.0, at), 2.0) / 2.0;  // looping every 2 s
    EXPECT_NEAR(img.pixel(50, 50)[0], 255.0 * (1.0 - phase), 1.0) << at;
    EXPECT_NEAR(img.pixel(50, 50)[1], 0.0, 1.0) << at;
    EXPECT_NEAR(img.pixel(50, 50)[2], 255.0 * phase, 1.0) << at;
  }
  // Without the timeline's item override the quad is its own white.
  const Image plain = render(scene.projector, {{model, Eigen::Matrix4d::Identity()}});
  EXPECT_EQ(plain.pixel(50, 50)[1], 255);
}

TEST_F(RenderTest, SceneContentSwapsAChangedVideoAndKeepsTheOldOneWhenTheNewFails) {
  // run's watch on content files (issue 44): a clip replaced on disk plays from its own start at a later
  // frame; a replacement that does not decode leaves the playing one and says why.
  const fs::path dir = fs::temp_directory_path() / ("projbot_render_swap_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path clip = dir / "clip.mp4";
  const auto write = [&](std::int64_t first, int w, int h) {
    projbot::assets::VideoWriter writer(clip, w, h, 30);
    for (int i = 0; i < 10; ++i) writer.write(projbot::assets::frame_code_image(first + i, w, h));
    writer.finish();
  };
  write(0, 320, 240);
  const ContentQuad q = content_quad(*renderer_, projector(200, 200, 150, 150, 99.5, 99.5), video_content(clip));
  const projbot::config::Scene& scene = q.scene;
  const std::vector<DrawItem>& items = q.items;
  projbot::engine::SceneContent content(*renderer_, scene, q.models, items);
  auto target = renderer_->make_offscreen(200, 200);
  const auto code_at = [&](double at) {  // waits (the test, not a renderer) for a frame, then draws it
    for (int k = 0; k < 500 && std::isnan(content.show(0, at).pts_s); ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    EXPECT_TRUE(renderer_->draw_frame(*target, scene.projector, items));
    return projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150);
  };
  EXPECT_EQ(code_at(0.0), 0);
  EXPECT_TRUE(content.reload_changed(0.0).empty());  // unchanged
  write(500, 160, 120);                              // another size: a new texture
  std::vector<std::string> said;
  for (int k = 0; k < 1000 && said.empty(); ++k) {
    said = content.reload_changed(1.0 + k, 0.5);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("clip.mp4: changed; the new video plays from its start"), std::string::npos) << said[0];
  EXPECT_EQ(code_at(0.0), 500);  // content time 0 of the old is the new one's start
  // A replacement that is not a video: the last good one stays, said once.
  std::ofstream(clip, std::ios::binary | std::ios::trunc) << "not a video at all, and longer than before............";
  said.clear();
  for (int k = 0; k < 1000 && said.empty(); ++k) {
    said = content.reload_changed(2000.0 + k, 0.5);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("clip.mp4: not a video FFmpeg can read"), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("the old video goes on"), std::string::npos) << said[0];
  EXPECT_EQ(code_at(0.0), 500);
  EXPECT_TRUE(content.reload_changed(5000.0).empty());  // said once
  renderer_->finish(*target);
  fs::remove_all(dir);
}
