// Rendering tests on whatever Vulkan device is there (lavapipe in CI), with the validation layer on:
// the GPU image is checked against an independent CPU projection of the same mesh (Eq. 3).

#include "render_fixture.hpp"

using namespace render_test;

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

// A background (issue 43: the projector's uniform grey while a target's reflectance is measured): where
// no model is, and nowhere else; black again once set back. Through a lens too (its canvas is cleared to it).
TEST_F(RenderTest, TheBackgroundFillsWhereNoModelIs) {
  Model m = quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                  Eigen::Vector3d(-0.5, 0.5, 1)},
                 {1.0F, 1.0F, 1.0F, 1.0F}, projbot::assets::Material{});
  const std::size_t white = renderer_->add_model(m);
  ProjectorConfig p = projector(100, 100, 80, 80, 49.5, 49.5);
  renderer_->set_background({128, 64, 0});
  Image img = render(p, {{white, Eigen::Matrix4d::Identity()}});
  EXPECT_EQ(img.pixel(50, 50)[0], 255);
  EXPECT_EQ(img.pixel(2, 2)[0], 128);
  EXPECT_EQ(img.pixel(2, 2)[1], 64);
  EXPECT_EQ(img.pixel(2, 2)[2], 0);
  EXPECT_EQ(render(p, {}).pixel(97, 97)[0], 128);  // no model: the whole image
  p.distortion[0] = 0.05;                          // k1
  EXPECT_EQ(render(p, {}).pixel(50, 50)[1], 64);
  renderer_->set_background({0, 0, 0});
  EXPECT_EQ(render(p, {}).pixel(50, 50)[1], 0);
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

// The operator's picture of the projector's frame (issue 70): a copy of the next frame drawn, recorded into
// that frame's commands and taken once it is done, without waiting: the frame asked for, not a later one,
// every pixel of it. A depth camera's frames are not copied.
TEST_F(RenderTest, CopiesTheNextFrameWithoutWaitingForIt) {
  const projbot::config::ProjectorConfig p = projector(64, 48, 60, 60, 31.5, 23.5);
  auto target = renderer_->make_offscreen(64, 48);
  const auto draw = [&](std::array<std::uint8_t, 3> rgb) {
    renderer_->set_background(rgb);
    ASSERT_TRUE(renderer_->draw_frame(*target, p, std::span<const DrawItem>{}));
  };
  EXPECT_FALSE(target->take_copy().has_value());  // none asked
  draw({10, 10, 10});
  ASSERT_TRUE(target->copy_next());
  draw({200, 30, 40});               // the frame copied (no read back here: it would fill the same buffer)
  ASSERT_TRUE(target->copy_next());  // asked again before taken: the same copy
  std::optional<Image> copy;
  for (int k = 0; k < 4 && !copy; ++k) {
    draw({0, 0, 255});  // later frames do not change it
    copy = target->take_copy();
  }
  ASSERT_TRUE(copy.has_value()) << "the copy never came";
  EXPECT_EQ(copy->width, 64);
  std::size_t other = 0;
  for (int y = 0; y < copy->height; ++y)
    for (int x = 0; x < copy->width; ++x) other += copy->pixel(x, y)[0] != 200 || copy->pixel(x, y)[2] != 40 ? 1 : 0;
  EXPECT_EQ(other, 0U) << "pixels not of the frame asked for";
  EXPECT_FALSE(target->take_copy().has_value());  // taken once
  renderer_->set_background({0, 0, 0});
  renderer_->finish(*target);
  EXPECT_FALSE(renderer_->make_depth_camera(32, 24)->copy_next());
}
