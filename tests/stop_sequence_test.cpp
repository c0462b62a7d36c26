// The projection session (issue 12) on the twin's base, pan-tilt and camera.

#include "twin_helpers.hpp"

namespace {

using namespace twin_test;
using projbot::twin::MeshRaycaster;
using projbot::twin::PlacedMesh;

// The session (issue 12) on the twin's base and pan-tilt: at the Duck's stop of the display it plans the
// Duck first and the box beside it, each from Eq. 1 on the believed head, with its surveyed footing; the
// believed head is the twin's truth within the localisation's error, and the guesses are the truth's
// within that too.
TEST(SessionTest, PlansTheVisitedTargetAndItsNeighbourFromTheBelievedHead) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  projbot::live::StopSequence session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());
  const projbot::live::Stop stop = session.arrive(0);
  EXPECT_EQ(stop.target, scene.target_index("duck"));
  EXPECT_EQ(stop.target_visit, 1);
  EXPECT_TRUE(stop.drive.arrived);
  ASSERT_EQ(stop.lit.size(), 2U);
  EXPECT_EQ(stop.lit[0].target, scene.target_index("duck"));
  EXPECT_EQ(stop.lit[1].target, scene.target_index("box"));
  using projbot::alignment::rigid_inverse;
  const Eigen::Matrix4d T_world_camera = stop.believed.T_world_camera.matrix();
  const Eigen::Matrix4d T_true_camera = twin.true_head().T_world_camera.matrix();
  EXPECT_LT(projbot::alignment::translation_norm_m(rigid_inverse(T_true_camera) * T_world_camera), 0.03);
  for (const auto& l : stop.lit) {
    const auto& target = scene.targets[static_cast<std::size_t>(l.target)];
    SCOPED_TRACE(target.name);
    EXPECT_TRUE(l.T_camera_target_guess.isApprox(rigid_inverse(T_world_camera) * *target.T_world_target, 1e-12));  // Eq. 1
    const Eigen::Matrix4d T_true = rigid_inverse(T_true_camera) * *target.T_world_target;
    EXPECT_LT(projbot::alignment::translation_norm_m(rigid_inverse(T_true) * l.T_camera_target_guess), 0.05);
    EXPECT_GT(l.footing.height_m, 0.6);  // on its plinth, below the model's middle (0.9 m up)
    EXPECT_LT(l.footing.height_m, 0.9);
  }
  // The second visit is the box's; the Duck's next one is its second.
  EXPECT_EQ(session.arrive(1).target, scene.target_index("box"));
  EXPECT_EQ(session.arrive(2).target_visit, 2);
}

// What StopSequence::visit promises the trackers it drives (the engine's TrackerWorker, the tour's lanes on
// the twin's simulated clock): each lit target's tracker gets its own Eq. 1 guess and the colour of the
// stop's first frame before any frame, then, in lockstep, every frame in order, the same frame (not a
// copy) to each, until the dwell says it is over; the observer sees what each returned for that frame.
TEST(SessionTest, AVisitHandsEachLitTrackerItsGuessThenEveryFrameInOrder) {
  struct Recorder final : projbot::alignment::PoseTracker {
    Eigen::Matrix4d guess = Eigen::Matrix4d::Zero();
    const projbot::assets::Image* colour = nullptr;
    std::vector<const projbot::alignment::DepthImage*> frames;
    int guesses = 0, submitted = 0;
    void set_initial_guess(const Eigen::Matrix4d& T, const projbot::alignment::Footing&,
                           std::shared_ptr<const projbot::assets::Image> c) override {
      guess = T;
      colour = c.get();
      ++guesses;
      EXPECT_TRUE(frames.empty()) << "a guess after a frame";
    }
    std::optional<projbot::alignment::PoseSample> track(std::shared_ptr<const projbot::alignment::DepthImage> f) override {
      frames.push_back(f.get());
      projbot::alignment::PoseSample s;
      s.capture_time_s = f->capture_time_s;
      return s;
    }
    void submit(std::shared_ptr<const projbot::alignment::DepthImage>) override { ++submitted; }
  };
  struct Observer final : projbot::live::StopObserver {
    std::vector<std::pair<int, std::size_t>> frames;  // k, samples handed over
    std::vector<double> sample_times, capture_times;
    void frame(const projbot::live::Stop&, int k, const projbot::alignment::RgbdFrame& f,
               const std::vector<std::optional<projbot::alignment::PoseSample>>& samples) override {
      frames.emplace_back(k, samples.size());
      capture_times.push_back(f.depth.capture_time_s);
      for (const auto& s : samples) sample_times.push_back(s ? s->capture_time_s : -1.0);
    }
  };
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  projbot::twin::TwinCamera camera(twin, 1);
  projbot::live::StopSequence session(scene, twin.session_targets(), twin.robot(), twin.pan_tilt());
  std::vector<Recorder> recorders(scene.targets.size());
  std::vector<projbot::alignment::PoseTracker*> trackers;
  for (auto& r : recorders) trackers.push_back(&r);
  projbot::live::Dwell dwell;
  dwell.camera = [&](const projbot::live::Stop& at, double since_s) -> projbot::alignment::RgbdCamera& {
    camera.at_stop(twin.target_index(scene.targets[static_cast<std::size_t>(at.target)].name), at.target_visit, 0, since_s);
    return camera;
  };
  dwell.over = [](const projbot::live::Stop&, int frames, double) { return frames >= 4; };
  dwell.lockstep = true;
  Observer observer;
  const std::stop_source never;
  const projbot::live::Stop stop = session.visit(0, trackers, dwell, observer, never.get_token());

  ASSERT_EQ(stop.lit.size(), 2U);  // the Duck and the box beside it
  ASSERT_EQ(observer.frames.size(), 4U);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(observer.frames[static_cast<std::size_t>(k)], std::make_pair(k, std::size_t{2}));
  const Recorder& duck = recorders[static_cast<std::size_t>(stop.lit[0].target)];
  const Recorder& box = recorders[static_cast<std::size_t>(stop.lit[1].target)];
  for (const auto& [r, lit] : {std::pair{&duck, stop.lit[0]}, std::pair{&box, stop.lit[1]}}) {
    EXPECT_EQ(r->guesses, 1);
    EXPECT_TRUE(r->guess.isApprox(lit.T_camera_target_guess, 1e-12));
    ASSERT_NE(r->colour, nullptr);  // the twin's first frame has colour
    EXPECT_GT(r->colour->width, 0);
    EXPECT_EQ(r->submitted, 0);  // lockstep: tracked, never merely submitted
  }
  EXPECT_EQ(duck.colour, box.colour);  // the stop's one colour image, shared
  ASSERT_EQ(duck.frames.size(), 4U);
  EXPECT_EQ(duck.frames, box.frames);  // the same frames, not copies
  for (std::size_t k = 1; k < observer.capture_times.size(); ++k)
    EXPECT_GT(observer.capture_times[k], observer.capture_times[k - 1]);  // in order
  // The samples the observer saw are those each tracker returned for that frame.
  ASSERT_EQ(observer.sample_times.size(), 8U);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(observer.sample_times[i], observer.capture_times[i / 2]);
  for (const Recorder& r : recorders) EXPECT_EQ(r.guesses, &r == &duck || &r == &box ? 1 : 0);
}

// A session needs a model of every visited target; told of none, it names the first it lacks.
TEST(SessionTest, AVisitedTargetWithoutAModelIsNamed) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  auto targets = twin.session_targets();
  targets.erase(targets.begin() + 1);  // the box
  try {
    projbot::live::StopSequence session(scene, targets, twin.robot(), twin.pan_tilt());
    FAIL() << "no error";
  } catch (const projbot::live::SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("target 'box' is visited but the session was given no model of it"), std::string::npos)
        << e.what();
  }
}

// The example site (issue 12, assets/sites/youbot-ud.yaml): the paper's devices, all four the session
// drives, and the demo tour, which the twin runs with --sim (a short localized tour here).
TEST(SessionTest, TheYoubotSiteNamesThePapersDevicesAndRunsInTheTwin) {
  const auto site = projbot::config::load_scene(kAssets + "/sites/youbot-ud.yaml");
  ASSERT_TRUE(site.devices.camera && site.devices.pan_tilt && site.devices.base && site.devices.projector);
  EXPECT_EQ(site.devices.camera->driver, "freenect");  // the Kinect v1
  EXPECT_EQ(site.devices.pan_tilt->port, "/dev/ttyUSB0");
  EXPECT_EQ(site.devices.base->cmd_vel, "cmd_vel");
  EXPECT_FALSE(site.devices.laser.has_value());  // run does not localise on a laser yet: left commented out
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto report = projbot::twin::run_tour(site, o);
  ASSERT_EQ(report.visits.size(), 1U);
  EXPECT_TRUE(report.visits[0].projected);
  EXPECT_LT(report.visits[0].mean_mm, 3.0);
}

}  // namespace
