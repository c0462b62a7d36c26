// The twin's radiometry and the renderer's compensation (issue 43): light on a surface computed by hand,
// the compensation's round trip through the forward model, and mesh.frag against its CPU reference.

#include "projbot/engine/photometry.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <memory>

#include "projbot/config/angles.hpp"
#include "projbot/engine/renderer.hpp"

namespace {

using projbot::config::ProjectorConfig;
namespace engine = projbot::engine;

// The default projector: 1280 x 800, fx = fy = 1400 px, 3000 lm, gamma 2.2, black 0.0005.
const ProjectorConfig kProjector;

// The same with a colour wheel's crosstalk and a gamma of its own per channel.
ProjectorConfig mixed_projector() {
  ProjectorConfig p;
  p.photometry.gamma_rgb = {2.1, 2.3, 2.5};
  p.photometry.mixing << 0.94, 0.05, 0.01, 0.04, 0.92, 0.04, 0.01, 0.06, 0.93;
  return p;
}

TEST(Photometry, FullWhiteOnAPatchByHand) {
  // 3000 lm over 1280 x 800 pixels, each (z / 1400)^2 m^2 at depth z: at 2 m facing the lens,
  // 3000 * 1400^2 / (1280 * 800) / 4 = 1435.5 lux.
  const double on_axis = engine::white_lux(kProjector, {0.0, 0.0, 2.0}, {0.0, 0.0, -1.0});
  EXPECT_NEAR(on_axis, 1435.5469, 1e-3);
  // The same plane z = 2 off the axis: the footprints of a plane facing the lens are all equal.
  EXPECT_NEAR(engine::white_lux(kProjector, {0.5, -0.3, 2.0}, {0.0, 0.0, 1.0}), on_axis, 1e-9);
  // Tilted 60 degrees to the ray on the axis: half the light. Twice as far: a quarter.
  const Eigen::Vector3d tilted(std::sin(M_PI / 3), 0.0, -std::cos(M_PI / 3));
  EXPECT_NEAR(engine::white_lux(kProjector, {0.0, 0.0, 2.0}, tilted), on_axis / 2, 1e-9);
  EXPECT_NEAR(engine::white_lux(kProjector, {0.0, 0.0, 4.0}, {0.0, 0.0, -1.0}), on_axis / 4, 1e-9);
  // A surface facing the lens off the axis, at distance r along its ray: a point source's 1 / r^2, the
  // pixel's flux over its solid angle, which shrinks by cos^3 of the ray to the axis.
  const Eigen::Vector3d q(1.0, 0.0, 2.0);
  const double cos_axis = 2.0 / q.norm();
  EXPECT_NEAR(engine::white_lux(kProjector, q, -q), engine::white_gain(kProjector) / (q.squaredNorm() * std::pow(cos_axis, 3)),
              1e-9);
  EXPECT_EQ(engine::white_lux(kProjector, {0.0, 0.0, -1.0}, {0.0, 0.0, 1.0}), 0.0);  // behind the lens
  // The response: black + (1 - black) c^2.2.
  const Eigen::Vector3d d = engine::drive(kProjector.photometry, {0.0, 0.5, 1.0});
  EXPECT_NEAR(d[0], 0.0005, 1e-12);
  EXPECT_NEAR(d[1], 0.0005 + 0.9995 * std::pow(0.5, 2.2), 1e-12);
  EXPECT_NEAR(d[2], 1.0, 1e-12);
  EXPECT_NEAR(engine::srgb_to_linear(engine::linear_to_srgb(0.2)), 0.2, 1e-12);
  EXPECT_NEAR(engine::srgb_to_linear(0.5), 0.21404, 1e-5);  // sRGB 128 is about 21 % linear
}

// What the visitor sees of a compensated surface: rho (ambient + white drive(input)) / kReferenceLux
// equals k linear(content) wherever the input is not clipped, and a clipped input is reported.
TEST(Photometry, CompensationShowsTheContentScaledByItsGain) {
  const Eigen::Vector3d albedo(0.8, 0.55, 0.3);  // a beige surface
  const double ambient = 30.0, k = 0.5;
  const engine::Compensation comp = engine::compensation(albedo, ambient, k);
  const Eigen::Vector3d q(0.2, -0.1, 1.8), n = Eigen::Vector3d(0.3, 0.1, -1.0).normalized();
  const double white = engine::white_lux(kProjector, q, n);
  // With crosstalk and three gammas: the channels unmixed, the same light reaches the visitor.
  const ProjectorConfig mixed = mixed_projector();
  const Eigen::Vector3d tan(0.7, 0.6, 0.5);
  const Eigen::Vector3d through = engine::light(mixed.photometry, engine::compensated_input(mixed, comp, tan, q, n));
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(albedo[i] * (ambient + white * through[i]) / engine::kReferenceLux, k * engine::srgb_to_linear(tan[i]), 1e-6)
        << "channel " << i << " with mixing";
  for (const Eigen::Vector3d& content :
       {Eigen::Vector3d(0.9, 0.6, 0.3), Eigen::Vector3d(0.4, 0.4, 0.4), Eigen::Vector3d(0.45, 0.7, 0.5)}) {
    bool clipped = true;
    const Eigen::Vector3d input = engine::compensated_input(kProjector, comp, content, q, n, &clipped);
    EXPECT_FALSE(clipped) << content.transpose();
    const Eigen::Vector3d light = engine::drive(kProjector.photometry, input);
    for (int i = 0; i < 3; ++i) {
      const double seen = albedo[i] * (ambient + white * light[i]) / engine::kReferenceLux;
      EXPECT_NEAR(seen, k * engine::srgb_to_linear(content[i]), 1e-6) << "channel " << i;  // scale_lux is a float
    }
  }
  bool clipped = false;
  const Eigen::Vector3d dark = engine::compensated_input(kProjector, comp, {0.02, 0.02, 0.02}, q, n, &clipped);
  EXPECT_TRUE(clipped);  // the room alone is brighter than this content at k = 0.5
  EXPECT_EQ(dark, Eigen::Vector3d::Zero());
  const auto bright =
      engine::compensated_input(kProjector, engine::compensation(albedo, ambient, 5.0), {1, 1, 1}, q, n, &clipped);
  EXPECT_TRUE(clipped);  // more than full white
  EXPECT_EQ(bright, Eigen::Vector3d::Ones());
}

// The gain: the largest k that leaves 2 % of the samples clipped.
TEST(Photometry, TheGainClipsTheShareAskedFor) {
  std::vector<engine::SurfaceSample> samples;
  for (int i = 0; i < 100; ++i) samples.push_back({Eigen::Vector3d::Ones(), 500.0 + 10.0 * i});  // white content
  const Eigen::Vector3d albedo(0.5, 0.5, 0.5);
  const double k = engine::choose_gain(samples, albedo, 0.0, 0.02);
  EXPECT_NEAR(k, 0.5 * 520.0 / engine::kReferenceLux, 1e-12);  // the third-weakest light sets it
  int clipped = 0;
  const engine::Compensation comp = engine::compensation(albedo, 0.0, k);
  for (const auto& s : samples) clipped += comp.scale_lux[0] > s.white_lux * (1.0 + 1e-6) ? 1 : 0;
  EXPECT_EQ(clipped, 2);
  EXPECT_EQ(engine::choose_gain({}, albedo, 0.0), 1.0);
  // Weighted by the projector's pixels: a dim patch that fills half the view sets k by itself.
  samples[0].weight = 99.0;
  EXPECT_NEAR(engine::choose_gain(samples, albedo, 0.0, 0.02), 0.5 * 500.0 / engine::kReferenceLux, 1e-12);
  // Never above 1: brighter than the content under the reference light is not asked for.
  EXPECT_EQ(engine::choose_gain({{Eigen::Vector3d::Ones(), 1e5, 1.0}}, albedo, 0.0), 1.0);
}

// A flat 0.6 m square patch of one colour (sRGB `content`), its UVs 0..1 across it, tilted 40 degrees and
// off the axis of a 320 x 200 projector with crosstalk and a gamma per channel (the shader's set 1).
struct Patch {
  explicit Patch(const Eigen::Vector3d& content) {
    quad.source = "quad";
    projbot::assets::Primitive prim;
    for (const auto& [x, y] : {std::pair{-0.3F, -0.3F}, {0.3F, -0.3F}, {0.3F, 0.3F}, {-0.3F, 0.3F}}) {
      projbot::assets::Vertex v;
      v.position = {x, y, 0.0F};
      v.normal = {0.0F, 0.0F, -1.0F};
      v.uv = {x / 0.6F + 0.5F, y / 0.6F + 0.5F};
      prim.vertices.push_back(v);
    }
    prim.indices = {0, 1, 2, 0, 2, 3};
    quad.primitives.push_back(prim);
    projbot::assets::Material material;
    material.base_color_factor = {static_cast<float>(content[0]), static_cast<float>(content[1]), static_cast<float>(content[2]),
                                  1.0F};
    material.double_sided = true;
    quad.materials.push_back(material);
    projector = mixed_projector();
    projector.width_px = 320, projector.height_px = 200, projector.fx_px = projector.fy_px = 350.0;
    projector.cx_px = 150.3, projector.cy_px = 104.1;
    T.topLeftCorner<3, 3>() = Eigen::AngleAxisd(projbot::config::radians(40.0), Eigen::Vector3d::UnitY()).toRotationMatrix();
    T.topRightCorner<3, 1>() = Eigen::Vector3d(0.15, -0.05, 2.0);
  }
  Eigen::Vector3d normal() const { return T.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ(); }
  // Pixel (u, v)'s ray on the patch's plane: the point, projector frame.
  Eigen::Vector3d point(int u, int v) const {
    const Eigen::Vector3d ray((u - projector.cx_px) / projector.fx_px, (v - projector.cy_px) / projector.fy_px, 1.0);
    const Eigen::Vector3d p0 = T.topRightCorner<3, 1>();
    return ray * (normal().dot(p0) / normal().dot(ray));
  }
  // That point on the patch (model frame; inside where |x|, |y| < 0.3).
  Eigen::Vector3d local(const Eigen::Vector3d& q) const {
    return T.topLeftCorner<3, 3>().transpose() * (q - T.topRightCorner<3, 1>().eval());
  }
  projbot::assets::Model quad;
  ProjectorConfig projector;
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
};

// The gain choice reads a texture inside each triangle, not at its corners alone: the patch's two
// triangles textured black with a white disc over a fifth of it (its corners black) ask about as much of
// the projector as a white patch (the disc is more than the 2 % allowed to clip), and about 2 % of the
// projector's pixels on it then need more than full white.
TEST(Photometry, TheGainReadsATextureInsideLargeTriangles) {
  Patch white(Eigen::Vector3d::Ones()), disc(Eigen::Vector3d::Ones());
  projbot::assets::Image texture;
  texture.width = texture.height = 64;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool in = std::hypot(x - 31.5, y - 31.5) < 16.0;  // a fifth of the square
      const std::uint8_t c = in ? 255 : 0;
      texture.rgba.insert(texture.rgba.end(), {c, c, c, std::uint8_t{255}});
    }
  disc.quad.images.push_back(texture);
  disc.quad.materials[0].base_color_image = 0;
  const Eigen::Vector3d albedo(0.5, 0.5, 0.5);
  const auto gain = [&](const Patch& p) {
    return engine::choose_gain(engine::surface_samples(p.quad, p.projector, p.T), albedo, 20.0, 0.02,
                               p.projector.photometry.mixing);
  };
  const double k_white = gain(white), k_disc = gain(disc);
  ASSERT_LT(k_white, 1.0);
  EXPECT_GE(k_disc, 0.9 * k_white);  // the disc lies where the light is strongest: a little more
  EXPECT_LE(k_disc, 0.75);           // read at the corners (black), the patch would ask for nothing: k 1
  // The disc's pixels that need more than full white at that gain: the projector's pixels on the patch,
  // each through the CPU reference of the shader.
  const engine::Compensation comp = engine::compensation(albedo, 20.0, k_disc);
  int on_patch = 0, clipped = 0;
  for (int v = 0; v < disc.projector.height_px; ++v)
    for (int u = 0; u < disc.projector.width_px; ++u) {
      const Eigen::Vector3d q = disc.point(u, v), l = disc.local(q);
      if (std::abs(l.x()) >= 0.3 || std::abs(l.y()) >= 0.3) continue;
      const Eigen::Vector2d uv(l.x() / 0.6 + 0.5, l.y() / 0.6 + 0.5);
      const bool in = std::hypot(64.0 * uv.x() - 32.0, 64.0 * uv.y() - 32.0) < 16.0;
      bool clip = false;
      engine::compensated_input(disc.projector, comp, Eigen::Vector3d::Constant(in ? 1.0 : 0.0), q, disc.normal(), &clip);
      ++on_patch;
      clipped += in && clip ? 1 : 0;  // black content clips below black (the room's light): not counted
    }
  ASSERT_GT(on_patch, 1000);
  EXPECT_LE(clipped, 0.03 * on_patch) << clipped << " of " << on_patch;
}

// mesh.frag's compensation against compensated_input: a flat patch of one colour, tilted and off the
// axis, each pixel's input from the ray's point on the plane.
TEST(Photometry, TheShaderMatchesItsCpuReference) {
  engine::Renderer renderer{engine::RendererOptions{}};
  const Eigen::Vector3d content(0.85, 0.55, 0.35);  // sRGB
  const Patch patch(content);
  const std::size_t id = renderer.add_model(patch.quad);
  auto target = renderer.make_offscreen(patch.projector.width_px, patch.projector.height_px);
  const engine::Compensation comp = engine::compensation({0.7, 0.6, 0.5}, 20.0, 0.35);
  renderer.draw_frame(*target, patch.projector, std::vector<engine::DrawItem>{{id, patch.T, comp}});
  const auto image = target->read_back();
  std::size_t compared = 0;
  double worst = 0.0;
  for (int v = 0; v < patch.projector.height_px; ++v)
    for (int u = 0; u < patch.projector.width_px; ++u) {
      const Eigen::Vector3d q = patch.point(u, v), local = patch.local(q);
      if (std::abs(local.x()) > 0.29 || std::abs(local.y()) > 0.29) continue;  // off the patch or on its edge
      const Eigen::Vector3d want = engine::compensated_input(patch.projector, comp, content, q, patch.normal());
      const std::uint8_t* px = image.pixel(u, v);
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(px[i] - 255.0 * want[i]));
      ++compared;
    }
  EXPECT_GT(compared, 8000U);
  EXPECT_LT(worst, 1.5) << "levels of 255";  // float in the shader, rounding to 8 bits
  // Without compensation the content is sent as stored.
  renderer.draw_frame(*target, patch.projector, std::vector<engine::DrawItem>{{id, patch.T}});
  const auto plain = target->read_back();
  const std::uint8_t* mid = plain.pixel(160, 100);
  EXPECT_EQ(mid[0], 217);
  EXPECT_EQ(mid[1], 140);
  EXPECT_EQ(mid[2], 89);
}

// surface.texture: a patch printed in two colours (its left half reddish, its right half blue-grey, sRGB
// bytes over its UVs) compensated with an albedo of 1 and the print bound as its surface: each half's
// input is the CPU reference's for a one-colour surface of that half's reflectance, and the gain choice
// reads the print as such a surface would be read.
TEST(Photometry, TheShaderDividesByTheSurfaceTexture) {
  engine::Renderer renderer{engine::RendererOptions{}};
  const Eigen::Vector3d content(0.85, 0.55, 0.35);
  const Patch patch(content);
  const std::size_t id = renderer.add_model(patch.quad);
  projbot::assets::Image print;
  print.width = 64, print.height = 4;
  const std::array<std::uint8_t, 3> left{230, 120, 90}, right{110, 140, 200};
  for (int y = 0; y < print.height; ++y)
    for (int x = 0; x < print.width; ++x) {
      const auto& c = x < 32 ? left : right;
      print.rgba.insert(print.rgba.end(), {c[0], c[1], c[2], 255});
    }
  ASSERT_EQ(print.rgba.size(), 64U * 4U * 4U);
  renderer.set_surface(id, print);
  const auto rho = [](const std::array<std::uint8_t, 3>& c) {
    return Eigen::Vector3d(engine::srgb_to_linear(c[0] / 255.0), engine::srgb_to_linear(c[1] / 255.0),
                           engine::srgb_to_linear(c[2] / 255.0));
  };
  auto target = renderer.make_offscreen(patch.projector.width_px, patch.projector.height_px);
  const engine::Compensation comp = engine::compensation(Eigen::Vector3d::Ones(), 20.0, 0.35);
  renderer.draw_frame(*target, patch.projector, std::vector<engine::DrawItem>{{id, patch.T, comp}});
  const auto image = target->read_back();
  std::size_t compared[2] = {0, 0};
  double worst = 0.0;
  for (int v = 0; v < patch.projector.height_px; ++v)
    for (int u = 0; u < patch.projector.width_px; ++u) {
      const Eigen::Vector3d q = patch.point(u, v), local = patch.local(q);
      // On the patch, clear of its edges and of the seam between the halves (texels blend there).
      if (std::abs(local.x()) > 0.28 || std::abs(local.y()) > 0.28 || std::abs(local.x()) < 0.02) continue;
      const bool on_left = local.x() < 0.0;
      const engine::Compensation half = engine::compensation(rho(on_left ? left : right), 20.0, 0.35);
      const Eigen::Vector3d want = engine::compensated_input(patch.projector, half, content, q, patch.normal());
      const std::uint8_t* px = image.pixel(u, v);
      for (int i = 0; i < 3; ++i) worst = std::max(worst, std::abs(px[i] - 255.0 * want[i]));
      ++compared[on_left ? 0 : 1];
    }
  EXPECT_GT(compared[0], 3000U);
  EXPECT_GT(compared[1], 3000U);
  EXPECT_LT(worst, 1.5) << "levels of 255";
  // The gain: a print of one colour reads as that colour's albedo.
  projbot::assets::Image plain = print;
  for (std::size_t i = 0; i < plain.rgba.size(); i += 4) std::copy(right.begin(), right.end(), plain.rgba.begin() + i);
  const auto samples = engine::surface_samples(patch.quad, patch.projector, patch.T, &plain);
  ASSERT_FALSE(samples.empty());
  EXPECT_NEAR(engine::choose_gain(samples, Eigen::Vector3d::Ones(), 20.0),
              engine::choose_gain(engine::surface_samples(patch.quad, patch.projector, patch.T), rho(right), 20.0),
              1e-6);  // the texel is read in single precision
  // A plan keeps a printed surface: one colour measured over it is not taken.
  auto shared = std::make_shared<const projbot::assets::Image>(plain);
  engine::CompensationPlan plan({{&patch.quad, Eigen::Vector3d::Ones(), shared}}, 20.0, true);
  const engine::Compensation first = plan.at(0, 1, patch.projector, patch.T);
  plan.add_measured_albedo(0, Eigen::Vector3d(0.2, 0.2, 0.2));
  EXPECT_EQ(plan.albedo(0), Eigen::Vector3d::Ones());
  EXPECT_EQ(plan.at(0, 1, patch.projector, patch.T).scale_lux, first.scale_lux);
}

}  // namespace

namespace {

// The plan keeps a target's gain through a visit, whatever the pose does, and chooses it again in the next.
TEST(Photometry, ThePlanKeepsTheGainThroughAVisit) {
  projbot::assets::Model quad = projbot::assets::make_box({-0.2, -0.2, -0.01}, {0.2, 0.2, 0.01}, {1.0F, 1.0F, 1.0F, 1.0F});
  engine::CompensationPlan plan({{&quad, Eigen::Vector3d(0.5, 0.5, 0.5), nullptr}}, 20.0, true);
  Eigen::Matrix4d near = Eigen::Matrix4d::Identity(), far = Eigen::Matrix4d::Identity();
  near(2, 3) = 1.0;
  far(2, 3) = 3.0;  // nine times less light: a smaller gain
  const engine::Compensation first = plan.at(0, 1, kProjector, near);
  EXPECT_TRUE(first.on);
  const double k_near = plan.gain(0);
  EXPECT_EQ(plan.at(0, 1, kProjector, far).scale_lux, first.scale_lux);  // the same visit: kept
  plan.at(0, 2, kProjector, far);
  EXPECT_LT(plan.gain(0), 0.5 * k_near);  // the next visit: chosen again, far away
  // Measured reflectances replace the scene's, averaged over the visits that measured them.
  plan.add_measured_albedo(0, Eigen::Vector3d(0.6, 0.4, 0.2));
  EXPECT_EQ(plan.albedo(0), Eigen::Vector3d(0.6, 0.4, 0.2));
  plan.add_measured_albedo(0, Eigen::Vector3d(0.7, 0.5, 0.3));
  EXPECT_TRUE(plan.albedo(0).isApprox(Eigen::Vector3d(0.65, 0.45, 0.25), 1e-12)) << plan.albedo(0).transpose();
  const engine::Compensation refined = plan.at(0, 2, kProjector, far);  // its gain chosen again for the new albedo
  EXPECT_FLOAT_EQ(refined.scale_lux[0], static_cast<float>(plan.gain(0) * engine::kReferenceLux / 0.65));
  engine::CompensationPlan off({{&quad, Eigen::Vector3d(0.5, 0.5, 0.5), nullptr}}, 20.0, false);
  EXPECT_FALSE(off.at(0, 1, kProjector, near).on);
}

// Given the frames' display times, the gain follows the pose through a visit: a patch carried from 3 m to
// 4.5 m (2.25 times less light) at t = 0 dims no faster than kRatePerS and settles at the far pose's own
// gain; a pose a hair away (under kDeadband) leaves it as it is; the next visit chooses at once.
TEST(Photometry, ThePlanFollowsThePoseSlowlyGivenTheFramesTimes) {
  using Plan = engine::CompensationPlan;
  projbot::assets::Model quad = projbot::assets::make_box({-0.2, -0.2, -0.01}, {0.2, 0.2, 0.01}, {1.0F, 1.0F, 1.0F, 1.0F});
  Eigen::Matrix4d near = Eigen::Matrix4d::Identity(), far = near, hair = near;
  near(2, 3) = 3.0;
  far(2, 3) = 4.5;
  hair(2, 3) = 3.03;  // 2 % less light
  Plan plan({{&quad, Eigen::Vector3d(0.5, 0.5, 0.5), nullptr}}, 20.0, true);
  Plan at_far({{&quad, Eigen::Vector3d(0.5, 0.5, 0.5), nullptr}}, 20.0, true);
  at_far.at(0, 1, kProjector, far);
  const double k_far = at_far.gain(0);
  plan.at(0, 1, kProjector, near, 10.0);
  const double k_near = plan.gain(0);
  ASSERT_LT(k_far, 0.6 * k_near);
  for (int frame = 0; frame <= 60; ++frame) plan.at(0, 1, kProjector, hair, 10.0 + frame / 60.0);
  EXPECT_EQ(plan.gain(0), k_near);  // within the dead band: kept
  double previous = k_near;
  for (int frame = 1; frame <= 60 * 3; ++frame) {  // three seconds at 60 Hz, carried away
    const double t = 11.0 + frame / 60.0;
    plan.at(0, 1, kProjector, far, t);
    const double k = plan.gain(0);
    EXPECT_LE(k, previous + 1e-12) << frame;                                      // only dimmer
    EXPECT_GE(k, previous * std::exp(-Plan::kRatePerS / 60.0) - 1e-12) << frame;  // never faster than the rate
    EXPECT_GE(k, k_near * std::exp(-Plan::kRatePerS * (t - 11.0 + Plan::kRechooseS)) - 1e-9) << frame;
    previous = k;
  }
  EXPECT_NEAR(plan.gain(0), k_far, 1e-9 * k_far);  // settled at the far pose's own (ln 2.25 / 0.5 = 1.6 s)
  plan.at(0, 2, kProjector, near, 15.0);           // the next visit: chosen at once
  EXPECT_EQ(plan.gain(0), k_near);
  Plan untimed({{&quad, Eigen::Vector3d(0.5, 0.5, 0.5), nullptr}}, 20.0, true);
  untimed.at(0, 1, kProjector, near);
  for (int frame = 0; frame < 60; ++frame) untimed.at(0, 1, kProjector, far);
  EXPECT_EQ(untimed.gain(0), k_near);  // without times, the visit's first gain
}

}  // namespace

namespace {

// measure_albedo refuses what it cannot read: pictures of another size than the camera, no grey, or a
// target the camera does not see; bench appearance --reflectance measured checks it on the twin's shop.
TEST(Photometry, MeasuringReflectanceNeedsPicturesItCanRead) {
  const projbot::assets::Model box = projbot::assets::make_box({-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2}, {1.0F, 1.0F, 1.0F, 1.0F});
  ProjectorConfig camera;
  camera.width_px = 64, camera.height_px = 48, camera.fx_px = camera.fy_px = 60.0, camera.cx_px = 31.5, camera.cy_px = 23.5;
  projbot::assets::Image picture;
  picture.width = 64, picture.height = 48;
  picture.rgba.assign(64 * 48 * 4, 100);
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T(2, 3) = 2.0;
  EXPECT_FALSE(engine::measure_albedo(box, camera, T, kProjector, T, picture, picture, 0.0));  // no grey
  projbot::assets::Image small = picture;
  small.width = 32;
  EXPECT_FALSE(engine::measure_albedo(box, camera, T, kProjector, T, small, picture, 0.5));
  Eigen::Matrix4d behind = T;
  behind(2, 3) = -2.0;
  EXPECT_FALSE(engine::measure_albedo(box, camera, behind, kProjector, behind, picture, picture, 0.5));
  // Seen and lit: the same picture twice is no light added, a reflectance of 0.
  const auto none = engine::measure_albedo(box, camera, T, kProjector, T, picture, picture, 0.5);
  ASSERT_TRUE(none);
  EXPECT_EQ(*none, Eigen::Vector3d::Zero());
}

// A reflectance map (--reflectance mapped): points of a print, its left half one colour and its right
// half another, measured only over the lower half of the UVs (one point in three an outlier, as points at
// a silhouette are). Measured texels are their points' median; the upper half grows from the nearest
// measured texels in texture space; too few points give no map.
TEST(Photometry, AReflectanceMapKeepsEachTexelsMedianAndGrowsIntoTheRest) {
  const Eigen::Vector3d left(0.6, 0.2, 0.1), right(0.1, 0.3, 0.7);
  std::vector<engine::ReflectancePoint> points;
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 16; ++x)
      for (int k = 0; k < 3; ++k) {
        engine::ReflectancePoint p;
        p.uv = Eigen::Vector2d((x + 0.5) / 16.0, (y + 0.5) / 16.0);
        p.rho = (x < 8 ? left : right) * (k == 2 ? 3.0 : 1.0);
        p.valid = {true, true, true};
        points.push_back(p);
      }
  engine::ReflectanceMap map(16, 16);
  map.add(std::vector<engine::ReflectancePoint>(points.begin(), points.begin() + 18));
  EXPECT_FALSE(map.image());  // 18 points: fewer than 20
  map.add(std::vector<engine::ReflectancePoint>(points.begin() + 18, points.end()));
  const std::optional<projbot::assets::Image> image = map.image();
  ASSERT_TRUE(image);
  ASSERT_EQ(image->width, 16);
  ASSERT_EQ(image->height, 16);
  const auto rho = [&](int x, int y) {
    const std::uint8_t* px = image->pixel(x, y);
    return Eigen::Vector3d(engine::srgb_to_linear(px[0] / 255.0), engine::srgb_to_linear(px[1] / 255.0),
                           engine::srgb_to_linear(px[2] / 255.0));
  };
  for (const int y : {0, 7, 8, 12, 15})  // measured, then grown (each column from the rows above and below)
    for (const int x : {0, 3, 7, 8, 12, 15}) {
      const Eigen::Vector3d want = x < 8 ? left : right;
      EXPECT_LT((rho(x, y) - want).cwiseAbs().maxCoeff(), 0.01) << x << ", " << y << ": " << rho(x, y).transpose();
    }
}

// A long tour keeps a bounded map (issue 43): a thousand visits of a print, each a hundred points in every
// texel of a 4 x 4 map, hold at most kPerTexel values a texel and channel and kFillPoints points; each texel
// follows the newest values (the print repainted grey after 900 visits shows grey, not the old red).
TEST(Photometry, AReflectanceMapStaysBoundedAndFollowsTheNewestValues) {
  engine::ReflectanceMap map(4, 4);
  const Eigen::Vector3d red(0.6, 0.1, 0.1), grey(0.3, 0.3, 0.3);
  std::vector<engine::ReflectancePoint> visit(1600);
  for (int visit_index = 0; visit_index < 1000; ++visit_index) {
    for (std::size_t k = 0; k < visit.size(); ++k) {
      visit[k].uv = Eigen::Vector2d((static_cast<double>(k % 4) + 0.5) / 4.0, (static_cast<double>(k / 4 % 4) + 0.5) / 4.0);
      visit[k].rho = visit_index < 900 ? red : grey;
      visit[k].valid = {true, true, true};
    }
    map.add(visit);
  }
  EXPECT_LE(map.values_kept(), 16 * 3 * engine::ReflectanceMap::kPerTexel + engine::ReflectanceMap::kFillPoints);
  const std::optional<projbot::assets::Image> image = map.image();
  ASSERT_TRUE(image);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(engine::srgb_to_linear(image->pixel(x, y)[ch] / 255.0), grey[ch], 0.005) << x << ", " << y;
}

// A model without texture coordinates puts every point of a measurement in one texel: the texel's median
// is that of the whole measurement (2500 points, the last 400 of them in shadow), not of its last points.
TEST(Photometry, AReflectanceMapOfAModelWithoutTextureCoordinatesTakesTheWholeMeasurement) {
  engine::ReflectanceMap map(8, 8);
  std::vector<engine::ReflectancePoint> points(2500);
  for (std::size_t k = 0; k < points.size(); ++k) {
    points[k].rho = k < 2100 ? Eigen::Vector3d(0.72, 0.58, 0.44) : Eigen::Vector3d(0.02, 0.02, 0.02);
    points[k].valid = {true, true, true};
  }
  map.add(points);
  const std::optional<projbot::assets::Image> image = map.image();
  ASSERT_TRUE(image);
  for (const auto& [x, y] : {std::pair{0, 0}, std::pair{4, 4}, std::pair{7, 3}}) {
    EXPECT_NEAR(engine::srgb_to_linear(image->pixel(x, y)[0] / 255.0), 0.72, 0.005) << x << ", " << y;
    EXPECT_NEAR(engine::srgb_to_linear(image->pixel(x, y)[2] / 255.0), 0.44, 0.005) << x << ", " << y;
  }
  EXPECT_LE(map.values_kept(), 3 * engine::ReflectanceMap::kPerTexel + points.size());
}

}  // namespace
