// The lens pass, streamed textures and moving content on whatever Vulkan device is there (lavapipe in CI),
// with the validation layer on.

#include <nlohmann/json.hpp>

#include "projbot/config/angles.hpp"
#include "render_fixture.hpp"

using namespace render_test;

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

// surface.texture is read for a model that has texture coordinates to lay it on; one line names what is wrong.
TEST(SurfaceTexture, NeedsTheFileAndTheModelsTextureCoordinates) {
  Model m = projbot::assets::make_box({-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}, {1.0F, 1.0F, 1.0F, 1.0F});
  projbot::config::TargetConfig target;
  target.name = "box";
  target.model = "box.glb";
  EXPECT_EQ(projbot::engine::load_surface_texture(target, m), nullptr);  // one colour: nothing to read
  const fs::path dir = fs::temp_directory_path() / ("projbot_surface_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  target.surface.texture = dir / "print.png";
  const auto message = [&] {
    try {
      projbot::engine::load_surface_texture(target, m);
    } catch (const projbot::assets::AssetError& e) {
      return std::string(e.what());
    }
    return std::string("no throw");
  };
  for (auto& p : m.primitives)
    for (auto& v : p.vertices) v.uv = {0.0F, 0.0F};
  projbot::assets::Image print;
  print.width = print.height = 2;
  print.rgba.assign(16, 200);
  projbot::assets::write_png(target.surface.texture, print);
  EXPECT_NE(message().find("box.glb has none"), std::string::npos) << message();
  m.primitives[0].vertices[1].uv = {1.0F, 0.0F};
  const auto read = projbot::engine::load_surface_texture(target, m);
  ASSERT_NE(read, nullptr);
  EXPECT_EQ(read->width, 2);
  fs::remove(target.surface.texture);
  EXPECT_NE(message().find("print.png"), std::string::npos) << message();
  fs::remove_all(dir);
}

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
    EXPECT_NE(std::string(e.what()).find(
                  "m.glb: no material 'glass' for the content (its 3 materials: 0 (unnamed), 1 'Label', 2 (unnamed))"),
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
  timeline.timeline.resize(2);
  timeline.timeline[0].base_color_factor = {1.0, 0.0, 0.0, 1.0};
  timeline.timeline[1].at_s = 2.0;
  timeline.timeline[1].base_color_factor = {0.0, 0.0, 1.0, 1.0};
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

TEST_F(RenderTest, SceneContentSwitchesATargetsVideoAndReusesTheTexturesLetGo) {
  // The operator's console (issue 70) switches a target's video: the new one plays from its start at a
  // later frame; switching back to the first size reuses the texture let go; a file that does not open
  // leaves the playing one, said once; a target without a video cannot switch.
  const fs::path dir = fs::temp_directory_path() / ("projbot_render_switch_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto clip = [&](const std::string& name, std::int64_t first, int w, int h) {
    projbot::assets::VideoWriter writer(dir / name, w, h, 30);
    for (int i = 0; i < 10; ++i) writer.write(projbot::assets::frame_code_image(first + i, w, h));
    writer.finish();
    return dir / name;
  };
  const fs::path first = clip("first.mp4", 0, 320, 240), other = clip("other.mp4", 700, 160, 120);
  const ContentQuad q = content_quad(*renderer_, projector(200, 200, 150, 150, 99.5, 99.5), video_content(first));
  projbot::engine::SceneContent content(*renderer_, q.scene, q.models, q.items);
  auto target = renderer_->make_offscreen(200, 200);
  const auto code_at = [&](double at) {  // waits (the test, not a renderer) for the frame due, then draws it
    for (int k = 0; k < 1000; ++k) {
      const projbot::engine::SceneContent::Sample s = content.show(0, at);
      if (std::abs(s.pts_s - std::floor(s.content_s * 30.0 + 1e-9) / 30.0) < 1e-3) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    EXPECT_TRUE(renderer_->draw_frame(*target, q.scene.projector, q.items));
    return projbot::assets::read_frame_code(target->read_back(), 25, 25, 150, 150);
  };
  const auto switched = [&](const fs::path& file) {
    content.switch_video(0, file);
    std::vector<std::string> said;
    for (int k = 0; k < 1000 && said.empty(); ++k) {
      said = content.reload_changed(0.0, 1e9);  // no file looked at again: only the switch
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return said;
  };
  EXPECT_EQ(code_at(0.2), 6);
  std::vector<std::string> said = switched(other);
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("other.mp4: now plays on 'a', from its start"), std::string::npos) << said[0];
  EXPECT_EQ(code_at(0.2), 700);  // from its own start at the content time it came in
  EXPECT_EQ(code_at(0.3), 703);
  said = switched(first);
  ASSERT_EQ(said.size(), 1U);
  EXPECT_EQ(code_at(0.3), 0);              // the first size's texture, let go, drawn again
  EXPECT_EQ(content.videos().size(), 1U);  // the file watched is the one playing
  said = switched(dir / "missing.mp4");
  ASSERT_EQ(said.size(), 1U);
  EXPECT_NE(said[0].find("missing.mp4"), std::string::npos) << said[0];
  EXPECT_NE(said[0].find("its old video goes on"), std::string::npos) << said[0];
  EXPECT_EQ(code_at(0.4), 3);
  EXPECT_THROW(content.switch_video(1, other), projbot::engine::EngineError);
  renderer_->finish(*target);
  fs::remove_all(dir);
}

namespace {

// A 4 x 1 strip (red, green, blue, white), sampled nearest and repeating: the texel for texture coordinate u.
Image strip() {
  Image s;
  s.width = 4;
  s.height = 1;
  s.rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  return s;
}

Eigen::Vector3d strip_texel(double u) {
  const int k = ((static_cast<int>(std::floor(4.0 * u)) % 4) + 4) % 4;
  const Image s = strip();
  return Eigen::Vector3d(s.rgba[4 * k], s.rgba[4 * k + 1], s.rgba[4 * k + 2]) / 255.0;
}

// KHR_texture_transform's T R S, multiplied out here, applied to (u, v).
Eigen::Vector2d placed(const projbot::assets::TextureTransform& t, double u, double v) {
  const double c = std::cos(t.rotation_rad), s = std::sin(t.rotation_rad);
  const Eigen::Matrix3d T = (Eigen::Matrix3d() << 1, 0, t.offset[0], 0, 1, t.offset[1], 0, 0, 1).finished();
  const Eigen::Matrix3d R = (Eigen::Matrix3d() << c, s, 0, -s, c, 0, 0, 0, 1).finished();
  const Eigen::Matrix3d S = Eigen::Vector3d(t.scale[0], t.scale[1], 1).asDiagonal();
  return (T * R * S * Eigen::Vector3d(u, v, 1)).head<2>();
}

bool near_texel_edge(double u) { return std::abs(4.0 * u - std::round(4.0 * u)) < 0.15; }

}  // namespace

// An animated material (issue 44) on the quad wearing the strip, whose placement as loaded (offset 0.5 along
// u) is baked into its UVs as the loader bakes it: drawn with other placements of its base colour and
// emissive textures and with an emission, every pixel away from a texel edge against the CPU reference: the
// texel at the new placement of the pixel's own texture coordinate times the base colour factor, plus the
// emission times the emissive texel.
TEST_F(RenderTest, AnAnimatedMaterialPlacesItsTexturesAndEmitsAsItsStateSays) {
  const ProjectorConfig p = projector(100, 100, 80, 80, 49.5, 49.5);
  projbot::assets::Material mat;
  mat.base_color_image = mat.emissive_image = 0;
  mat.sampler.mag = mat.sampler.min = projbot::assets::Filter::kNearest;
  mat.emissive_sampler = mat.sampler;
  mat.base_color_transform.offset = {0.5, 0.0};
  Model m = quad({Eigen::Vector3d(-0.5, -0.5, 1), Eigen::Vector3d(0.5, -0.5, 1), Eigen::Vector3d(0.5, 0.5, 1),
                  Eigen::Vector3d(-0.5, 0.5, 1)},
                 {1, 1, 1, 1}, mat);
  m.images.push_back(strip());
  for (auto& v : m.primitives[0].vertices) v.uv[0] += 0.5F;  // baked
  const std::size_t id = renderer_->add_model(m);
  struct Case {
    projbot::assets::TextureTransform base, emissive;
    std::array<float, 4> factor;
    std::array<float, 3> emission;
  };
  const Case cases[] = {{{}, {}, {1, 1, 1, 1}, {0, 0, 0}},  // the file's own texture coordinates again, not the baked
                        {{{0.3, 0.1}, {2.0, 1.0}, 0.4}, {{0.25, 0.0}, {1.0, 1.0}, 0.0}, {1, 1, 1, 1}, {0.2F, 0.1F, 0.0F}},
                        {{}, {{0.6, 0.0}, {-1.0, 1.0}, 0.0}, {0, 0, 0, 1}, {0.3F, 0.6F, 0.9F}}};
  for (std::size_t k = 0; k < std::size(cases); ++k) {
    const Case& c = cases[k];
    projbot::assets::MaterialState s = mat.state();
    s.base_color_transform = c.base;
    s.emissive_transform = c.emissive;
    s.base_color_factor = c.factor;
    s.emissive_factor = c.emission;
    s.emissive_strength = 1.0F;
    DrawItem item{id, Eigen::Matrix4d::Identity()};
    item.materials = {{0, s}};
    const Image img = render(p, {item});
    int checked = 0;
    for (int y = 12; y <= 87; ++y)
      for (int x = 12; x <= 87; ++x) {
        const double u = (x - 9.5) / 80.0, v = (y - 9.5) / 80.0;  // the file's texture coordinate at this pixel
        const Eigen::Vector2d b = placed(c.base, u, v), e = placed(c.emissive, u, v);
        if (near_texel_edge(b.x()) || near_texel_edge(e.x())) continue;
        const Eigen::Vector3d want =
            (strip_texel(b.x()).cwiseProduct(Eigen::Vector3d(c.factor[0], c.factor[1], c.factor[2])) +
             strip_texel(e.x()).cwiseProduct(Eigen::Vector3d(c.emission[0], c.emission[1], c.emission[2])))
                .cwiseMin(1.0) *
            255.0;
        for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(img.pixel(x, y)[ch], want[ch], 1.5) << k << " at " << x << ", " << y;
        ++checked;
      }
    EXPECT_GT(checked, 2000) << k;
  }
}

// A model's own material animations (glTF KHR_animation_pointer) play on the content clock without a
// `content:` key, and a timeline's keys lie over them: red to blue over 2 s (repeating), and a timeline's
// emission from none to green.
TEST_F(RenderTest, SceneContentPlaysTheModelsMaterialAnimationsUnderItsTimeline) {
  ContentQuad q = content_quad(*renderer_, projector(100, 100, 80, 80, 49.5, 49.5), {});
  q.scene.targets[0].content.reset();
  projbot::assets::MaterialChannel ch;
  ch.times = {0.0F, 2.0F};
  ch.values = {1, 0, 0, 1, 0, 0, 1, 1};
  q.models[0].material_animations.push_back({"fade", 2.0, {ch}});
  const auto colour_at = [&](const projbot::engine::SceneContent& content, double at) {
    std::vector<DrawItem> items = q.items;
    content.animate(0, at, items[0]);
    const Image img = render(q.scene.projector, items);
    return Eigen::Vector3d(img.pixel(50, 50)[0], img.pixel(50, 50)[1], img.pixel(50, 50)[2]);
  };
  {
    const projbot::engine::SceneContent content(*renderer_, q.scene, q.models, q.items);
    ASSERT_TRUE(content.has(0));
    EXPECT_FALSE(content.has_video(0));
    for (const double at : {0.0, 0.5, 1.5, 3.0}) {
      const double w = std::fmod(at, 2.0) / 2.0;
      EXPECT_LT((colour_at(content, at) - 255.0 * Eigen::Vector3d(1.0 - w, 0.0, w)).cwiseAbs().maxCoeff(), 1.5) << at;
    }
  }
  projbot::config::TargetContent glow;
  glow.timeline.resize(2);
  glow.timeline[0].emissive_factor = {0.0, 0.0, 0.0};
  glow.timeline[1].at_s = 4.0;
  glow.timeline[1].emissive_factor = {0.0, 1.0, 0.0};
  q.scene.targets[0].content = glow;
  const projbot::engine::SceneContent content(*renderer_, q.scene, q.models, q.items);
  EXPECT_LT((colour_at(content, 1.0) - Eigen::Vector3d(127.5, 63.75, 127.5)).cwiseAbs().maxCoeff(), 1.5);
}

// run's and show's watch on a target's model files (issue 44): BoxTextured's texture repainted on disk is
// drawn at a later frame without a restart; a texture that no longer decodes, and a model of another shape
// (its root node scaled), leave the model as drawn, saying why.
TEST_F(RenderTest, SceneContentSwapsAChangedTextureAndKeepsTheModelWhereItCannot) {
  const fs::path dir = fs::temp_directory_path() / ("projbot_render_model_swap_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF", dir, fs::copy_options::recursive);
  projbot::config::Scene scene;
  scene.projector = projector(200, 200, 200, 200, 99.5, 99.5);
  projbot::config::TargetConfig t;
  t.name = "box";
  t.model = dir / "BoxTextured.gltf";
  t.scale = 0.3;
  t.T_projector_target = pose(0, 0, 1, projbot::config::radians(200), projbot::config::radians(35), 0);
  scene.targets.push_back(t);
  std::vector<Model> models;
  const std::vector<DrawItem> items = projbot::engine::upload_scene(*renderer_, scene, &models);
  ASSERT_EQ(models[0].files.size(), 3U);  // the .gltf, its .bin and its texture
  projbot::engine::SceneContent content(*renderer_, scene, models, items);
  const auto await = [&](const std::string& part) {  // the line saying what became of the change
    for (int k = 0; k < 200; ++k) {
      for (const std::string& line : content.reload_changed(k, 0.0))
        if (line.find(part) != std::string::npos) return line;
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    return std::string("nothing said with '" + part + "'");
  };
  const auto red_share = [&] {
    const Image img = render(scene.projector, items);
    std::size_t lit = 0, red = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        const auto* px = img.pixel(x, y);
        if (px[0] + px[1] + px[2] == 0) continue;
        ++lit;
        red += px[0] > 200 && px[1] < 10 && px[2] < 10 ? 1 : 0;
      }
    EXPECT_GT(lit, 3000U);
    return static_cast<double>(red) / static_cast<double>(std::max<std::size_t>(lit, 1));
  };
  EXPECT_LT(red_share(), 0.05);  // the Cesium logo: white and green
  Image solid;
  solid.width = solid.height = 8;
  solid.rgba.assign(8 * 8 * 4, 0);
  for (std::size_t i = 0; i < solid.rgba.size(); i += 4) solid.rgba[i] = solid.rgba[i + 3] = 255;
  projbot::assets::write_png(dir / "CesiumLogoFlat.png", solid);
  EXPECT_NE(await("changed;").find("its textures and materials are drawn from now on"), std::string::npos);
  EXPECT_GT(red_share(), 0.99);
  std::ofstream(dir / "CesiumLogoFlat.png") << "not a PNG any more";
  const std::string broken = await("stays");
  EXPECT_NE(broken.find("BoxTextured.gltf: "), std::string::npos) << broken;
  EXPECT_NE(broken.find("image[0]"), std::string::npos) << broken;                         // tinygltf's word for it
  EXPECT_NE(broken.find("(image 0 is CesiumLogoFlat.png)"), std::string::npos) << broken;  // and the file
  EXPECT_GT(red_share(), 0.99);
  projbot::assets::write_png(dir / "CesiumLogoFlat.png", solid);
  EXPECT_NE(await("changed;").find("drawn from now on"), std::string::npos);
  std::ifstream in(dir / "BoxTextured.gltf");
  nlohmann::json j = nlohmann::json::parse(in);
  j["nodes"][0]["matrix"][0] = 2.0;
  std::ofstream(dir / "BoxTextured.gltf") << j.dump();
  EXPECT_NE(await("changed shape").find("restart to use it"), std::string::npos);
  EXPECT_GT(red_share(), 0.99);
  fs::remove_all(dir);
}
