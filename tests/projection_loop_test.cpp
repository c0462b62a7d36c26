// The live projection loop (live::ProjectionLoop) on a real renderer (lavapipe, validation on), an offscreen
// target, a fake clock and a scripted pose source: frames paced on the loop's clock, a target drawn only
// while found, drawn where it will be at display time, and the display error meter's figures.

#include "projbot/live/projection_loop.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <optional>

using namespace projbot;

namespace {

config::ProjectorConfig small_projector() {
  config::ProjectorConfig p;
  p.width_px = 64, p.height_px = 48, p.fx_px = 60, p.fy_px = 60, p.cx_px = 32, p.cy_px = 24, p.near_m = 0.05, p.far_m = 20;
  p.refresh_hz = 60.0;
  return p;
}

// A white square 0.2 m a side in the model's z = 0 plane.
assets::Model square() {
  assets::Model m;
  m.source = "test-square";
  assets::Primitive p;
  const float h = 0.1F;
  for (const auto& c : {std::array<float, 3>{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}}) {
    assets::Vertex v;
    v.position = c;
    v.color = {1, 1, 1, 1};
    p.vertices.push_back(v);
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  assets::Material material;
  material.double_sided = true;
  m.materials.push_back(material);
  m.primitives.push_back(std::move(p));
  return m;
}

Eigen::Matrix4d at(double x, double y, double z) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(x, y, z);
  return T;
}

// A clock that moves when the loop sleeps (its frames at 60 Hz) and by a microsecond per read, so a test
// sees exactly the frames it scripts, however slow the renderer.
struct FakeClock {
  double t_s = 10.0;
  config::Clock clock() {
    return {[this] { return t_s += 1e-6; }, [this](double until_s) { t_s = std::max(t_s, until_s); }};
  }
};

class ProjectionLoopTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    engine::RendererOptions o;
    o.validation = true;
    renderer_ = std::make_unique<engine::Renderer>(o);
    model_ = renderer_->add_model(square());
  }
  static void TearDownTestSuite() { renderer_.reset(); }
  void TearDown() override {
    EXPECT_EQ(renderer_->validation_errors(), 0U);
    EXPECT_EQ(renderer_->validation_warnings(), 0U);
  }

  // The loop over `seconds` of fake time at 60 Hz; the pose of target 0 is `pose(t)` (nullopt: none yet,
  // or lost); the meter measures against `truth(t)`.
  using Uniform = std::optional<std::array<std::uint8_t, 3>>;
  live::ProjectionFigures run(double seconds, const std::function<std::optional<alignment::PoseSample>(double)>& pose,
                              const std::function<Eigen::Matrix4d(double)>& truth, bool predict, assets::Image* last = nullptr,
                              const std::function<Uniform(double)>& uniform = {}) {
    live::ProjectionLoopConfig c;
    c.projection.T_projector_camera = at(0.1, 0.0, 0.0);
    c.projection.refresh_hz = 60.0;
    c.projection.input_lag_ms = 20.0;
    c.projection.predict = predict;
    c.projection.max_unconfirmed_s = 0.0;  // scripted poses, no tracker to fall behind (ProjectionFrames tests it)
    c.seconds = seconds;
    c.paced_hz = 60.0;
    live::ProjectionLoop loop(*renderer_, projector_, {engine::DrawItem(model_, Eigen::Matrix4d::Identity())}, c, clock_.clock());
    live::ProjectionInputs in;
    in.stop = [] { return live::LitStop{{0}, 0.0, 1}; };
    in.poses = [&](int, alignment::PoseSample& out) {
      const auto p = pose(clock_.t_s);
      if (p) out = *p;
      return p.has_value();
    };
    in.camera_last_s = [this] { return clock_.t_s; };
    in.keep_going = [] { return true; };
    if (uniform) in.uniform = [&] { return uniform(clock_.t_s); };
    in.meter = [&](const live::DrawnPose& d) {
      const Eigen::Vector3d error = d.T_camera_target.topRightCorner<3, 1>() - truth(d.display_s).topRightCorner<3, 1>();
      return live::DisplayError{1000.0 * error.norm(), d.display_s > 10.25};
    };
    auto target = renderer_->make_offscreen(projector_.width_px, projector_.height_px);
    engine::FrameProfiler profiler;
    live::ProjectionFigures f = loop.run(*target, in, profiler);
    if (last) *last = target->read_back();
    return f;
  }

  alignment::PoseSample seen(const Eigen::Matrix4d& T, double capture_s, const Eigen::Vector3d& velocity) {
    alignment::PoseSample s;
    s.T_camera_target = T;
    s.capture_time_s = capture_s;
    s.motion.T = T;
    s.motion.time_s = capture_s;
    s.motion.velocity_m_s = velocity;
    s.lost = false;
    return s;
  }

  static inline std::unique_ptr<engine::Renderer> renderer_;
  static inline std::size_t model_ = 0;
  config::ProjectorConfig projector_ = small_projector();
  FakeClock clock_;
};

TEST_F(ProjectionLoopTest, PacesItsFramesAndBlanksATargetNotFoundOrLost) {
  // Found 0.1 s into the run, lost at 0.3 s: 30 frames in 0.5 s, those between drawn.
  const auto pose = [&](double t) -> std::optional<alignment::PoseSample> {
    if (t < 10.1) return std::nullopt;
    alignment::PoseSample s = seen(at(0, 0, 1), 10.1, Eigen::Vector3d::Zero());
    s.lost = t >= 10.3;
    return s;
  };
  assets::Image last;
  const live::ProjectionFigures f = run(
      0.5, pose, [](double) { return at(0, 0, 1); }, true, &last);
  ASSERT_NEAR(static_cast<double>(f.rows.size()), 30.0, 1.0);
  std::size_t drawn = 0;
  for (const live::ProjectionRow& r : f.rows) drawn += r.target == 0 ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(drawn), 12.0, 1.0);  // 0.2 s at 60 Hz
  EXPECT_EQ(f.blank + drawn, f.rows.size());
  EXPECT_EQ(f.ages_ms.size(), drawn);
  EXPECT_EQ(last.lit_pixels(), 0U);  // the last frame, the target lost: black
}

// A uniform colour asked for (a reflectance measured at a stop) replaces the targets over the whole image
// for as long as it is asked, counted apart from blank frames; then the target is drawn again.
TEST_F(ProjectionLoopTest, ShowsAUniformColourInsteadOfTheTargetsWhileAsked) {
  const auto pose = [&](double) -> std::optional<alignment::PoseSample> {
    return seen(at(0, 0, 1), 10.0, Eigen::Vector3d::Zero());
  };
  const auto truth = [](double) { return at(0, 0, 1); };
  const auto grey_until = [](double end_s) {
    return [end_s](double t) -> Uniform {
      if (t >= 10.2 && t < end_s) return std::array<std::uint8_t, 3>{128, 128, 128};
      return std::nullopt;
    };
  };
  assets::Image last;
  live::ProjectionFigures f = run(0.5, pose, truth, false, &last, grey_until(10.3));
  EXPECT_NEAR(static_cast<double>(f.uniform), 6.0, 1.0);  // 0.1 s at 60 Hz
  EXPECT_EQ(f.blank, 0U);
  std::size_t drawn = 0;
  for (const live::ProjectionRow& r : f.rows) drawn += r.target == 0 ? 1 : 0;
  EXPECT_EQ(drawn + f.uniform, f.rows.size());
  EXPECT_GT(last.lit_pixels(), 0U);                                                  // the square again...
  EXPECT_EQ(last.pixel(0, 0)[0], 0);                                                 // ...on black
  f = run(0.5, pose, truth, false, &last, grey_until(99.0));                         // grey to the end
  EXPECT_EQ(last.pixel(0, 0)[0], 128);                                               // the whole image
  EXPECT_EQ(last.pixel(projector_.width_px / 2, projector_.height_px / 2)[1], 128);  // the target not drawn
}

TEST_F(ProjectionLoopTest, DrawsAMovingTargetWhereItWillBeAtDisplayTimeAndMeasuresIt) {
  // A target moving at 0.5 m/s along x, each pose 30 ms old when read: drawn where it is at display time
  // (error ~0), and without prediction where it was seen (0.5 m/s x (30 ms + a frame + 20 ms lag) behind).
  const Eigen::Vector3d v(0.5, 0.0, 0.0);
  const auto truth = [&](double t) { return at(0.5 * (t - 10.0), 0.0, 1.0); };
  const auto pose = [&](double t) -> std::optional<alignment::PoseSample> { return seen(truth(t - 0.03), t - 0.03, v); };
  assets::Image last;
  const live::ProjectionFigures predicted = run(0.5, pose, truth, true, &last);
  const live::ProjectionFigures as_seen = run(0.5, pose, truth, false);
  ASSERT_EQ(predicted.blank, 0U);
  ASSERT_FALSE(predicted.still_mm.empty());
  ASSERT_FALSE(predicted.moving_mm.empty());  // the meter's `moving` (after 0.25 s) sorts the frames
  EXPECT_EQ(predicted.still_mm.size() + predicted.moving_mm.size(), predicted.rows.size());
  for (const double e : predicted.moving_mm) EXPECT_LT(e, 0.01);
  const double behind_mm = 1000.0 * 0.5 * (0.03 + 1.0 / 60.0 + 0.020);  // 33.3 mm
  for (const double e : as_seen.moving_mm) EXPECT_NEAR(e, behind_mm, 0.1);
  // Each row: the pose's age is capture to display (30 ms + a frame + 20 ms), the row's error the meter's.
  for (const live::ProjectionRow& r : predicted.rows) {
    EXPECT_NEAR(r.age_ms, 1000.0 * (0.03 + 1.0 / 60.0 + 0.020), 0.1);
    EXPECT_NEAR(r.display_ms - r.capture_ms, r.age_ms, 0.1);
    EXPECT_LT(r.error_mm, 0.01);
  }
  EXPECT_GT(last.lit_pixels(), 100U);  // the square, 0.2 m at about 1 m through a 60 px focal length
}

}  // namespace

namespace {

TEST_F(ProjectionLoopTest, StepsFrameByFrameOnASimulatedClockWithoutDrawing) {
  // As the twin's tour runs it: one frame per step at the clock's time, decided and measured, nothing
  // drawn. Found at 0.1 s, lost at 0.3 s; a truth 2 mm off in x while still, 0 mm after 0.25 s.
  double now_s = 0.0;
  live::ProjectionLoopConfig c;
  c.projection.T_projector_camera = at(0.1, 0.0, 0.0);
  c.projection.input_lag_ms = 20.0;
  c.projection.silent_camera_s = 0.0;
  c.projection.max_unconfirmed_s = 0.0;  // scripted poses, no tracker to fall behind
  live::ProjectionLoop loop(*renderer_, projector_, {}, c, {[&] { return now_s; }, [&](double t) { now_s = t; }});
  live::ProjectionInputs in;
  in.stop = [] { return live::LitStop{{0}, 0.0, 1}; };
  in.poses = [&](int, alignment::PoseSample& out) {
    if (now_s < 0.1 - 1e-9) return false;
    out = seen(at(0, 0, 1), 0.1, Eigen::Vector3d::Zero());
    out.lost = now_s >= 0.3 - 1e-9;
    return true;
  };
  in.meter = [](const live::DrawnPose& d) { return live::DisplayError{d.display_s > 0.25 ? 0.0 : 2.0, d.display_s > 0.25}; };
  loop.begin();
  std::size_t drawn = 0;
  for (int k = 0; k < 30; ++k) {
    now_s = k / 60.0;
    const std::optional<live::DecidedFrame> f = loop.frame(nullptr, in, nullptr);
    ASSERT_TRUE(f.has_value());
    EXPECT_DOUBLE_EQ(f->start_s, now_s);
    EXPECT_NEAR(f->display_s, now_s + 1.0 / 60.0 + 0.020, 1e-9);  // a frame period and the input lag later
    drawn += f->drawn.size();
    for (const live::DrawnPose& d : f->drawn) {
      EXPECT_EQ(d.target, 0);
      EXPECT_NEAR(d.T_projector_target(0, 3), 0.1, 1e-12);  // Eq. 2 with the configured R_cp, T_cp
      EXPECT_NEAR(d.display_s, f->display_s, 1e-12);
    }
  }
  EXPECT_EQ(drawn, 12U);  // frames 6..17: found at 0.1 s, lost at 0.3 s
  const live::ProjectionFigures& figures = loop.figures();
  ASSERT_EQ(figures.rows.size(), 30U);
  EXPECT_EQ(figures.blank, 18U);
  EXPECT_EQ(figures.still_mm.size() + figures.moving_mm.size(), 12U);
  for (const double e : figures.still_mm) EXPECT_DOUBLE_EQ(e, 2.0);
  EXPECT_NEAR(figures.rows[6].age_ms, 1000.0 * (6 / 60.0 + 1.0 / 60.0 + 0.020 - 0.1), 1e-6);
  EXPECT_NEAR(figures.rows[29].clock_s, 29 / 60.0, 1e-12);
}

}  // namespace
