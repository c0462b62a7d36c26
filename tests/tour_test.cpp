// The twin's tours (localised, odometry, tracking): the demo, motion, shop and display scenes, measured
// at the markers at each projector frame's display time.

#include "twin_helpers.hpp"

namespace {

using namespace twin_test;
using projbot::twin::MeshRaycaster;
using projbot::twin::PlacedMesh;

// Localisation keeps every visit within the 3 mm, also the box's third, found 10 cm and
// 15 degrees away from its surveyed pose.
TEST(TourTest, ShortLocalizedTourStaysWithin3mm) {
  const auto report = short_demo_tour(projbot::twin::TourMode::localized, 6);
  ASSERT_EQ(report.visits.size(), 6U);
  for (const auto& v : report.visits) {
    SCOPED_TRACE(v.target + " visit " + std::to_string(v.target_visit));
    EXPECT_TRUE(v.projected);
    EXPECT_EQ(v.markers.size(), v.target == "duck" ? 5U : 6U);
    for (const auto& m : v.markers) EXPECT_TRUE(m.landed);
    EXPECT_LT(v.mean_mm, 3.0);
    EXPECT_LT(v.max_mm, 5.0);
    EXPECT_LT(v.base_error_cm, 2.0);  // the robot issue's bound on localisation
    if (v.visit == 6) {
      EXPECT_GT(v.guess_error_cm, 8.0);  // the box was left moved
    } else {
      EXPECT_LT(v.guess_error_cm, 2.0);
    }
    // The report's true pose is the twin's: markers under it land within a pixel's rounding.
    EXPECT_LT(projbot::alignment::translation_norm_m(projbot::alignment::rigid_inverse(v.T_projector_target_true) *
                                                     v.T_projector_target_estimated),
              0.005);
  }
  EXPECT_EQ(report.visits[3].target, "box");
  EXPECT_EQ(report.visits[5].target, "box");
  EXPECT_TRUE(report.visits[3].moved);
  // Aligned once, the moved box is not followed: its content stays where the box was.
  EXPECT_LT(report.visits[3].reconverge_s, 0.0);
  EXPECT_GT(report.visits[3].max_mm_moving, 50.0);
}

// The paper's experiment as it was (assets/scenes/paper.yaml: nothing moved, half the demo's drift) in
// the paper's set-up: odometry alone and one plain point-to-point ICP per stop. Seed 1, three visits per
// target. The errors are the paper's order (mm to cm, theirs 4-19 mm) and grow with the drift.
TEST(TourTest, OdometryModeReproducesThePapersGrowth) {
  projbot::twin::TourOptions o;
  o.mode = projbot::twin::TourMode::odometry;
  o.seed = 1;
  const auto report = projbot::twin::run_tour(projbot::config::load_scene(kAssets + "/scenes/paper.yaml"), o);
  ASSERT_EQ(report.visits.size(), 6U);
  for (const auto& v : report.visits) {
    SCOPED_TRACE(v.target + " visit " + std::to_string(v.target_visit));
    EXPECT_TRUE(v.projected);   // the paper projected whatever ICP gave
    EXPECT_GT(v.mean_mm, 3.0);  // above what localisation and our acquisition keep (< 3 mm, test above)
    EXPECT_LT(v.mean_mm, 100.0);
    EXPECT_FALSE(v.moved);
  }
  for (const std::string target : {"duck", "box"}) {
    SCOPED_TRACE(target);
    std::vector<const projbot::twin::VisitReport*> visits;
    for (const auto& v : report.visits)
      if (v.target == target) visits.push_back(&v);
    ASSERT_EQ(visits.size(), 3U);
    // Odometry drifts: the robot believes itself further off at each visit, so ICP starts worse...
    EXPECT_GT(visits[2]->odometry_error_cm, visits[0]->odometry_error_cm);
    EXPECT_GT(visits[2]->guess_error_cm, visits[0]->guess_error_cm + 1.0);
    // ...and ends worse: the third projection is the worst of the three, as in the paper's Table 1.
    EXPECT_GT(visits[2]->mean_mm, visits[0]->mean_mm);
    EXPECT_GT(visits[2]->mean_mm, visits[1]->mean_mm);
  }
}

// The tracker follows the box while it is moved 10 cm and 15 degrees, back within 3 mm within 0.5 s.
TEST(TourTest, TrackingFollowsTheMovedTarget) {
  const auto report = short_demo_tour(projbot::twin::TourMode::tracking, 4);
  const auto& moved = report.visits[3];
  ASSERT_TRUE(moved.moved);
  EXPECT_EQ(moved.timeline.size(), 180U);  // 3 s of projector frames at 60 Hz
  EXPECT_GE(moved.reconverge_s, 0.0);
  EXPECT_LE(moved.reconverge_s, 0.5);
  EXPECT_LT(moved.max_mm_moving, 15.0);
  EXPECT_LT(moved.timeline.back().mean_mm, 3.0);
  for (const auto& s : moved.timeline) EXPECT_TRUE(s.shown);
}

// A start is blank until a pose confirms the motion restarted from it (MotionFilter::confirmed): the
// pose that shows it and the next, two camera frames, four projector frames at 60 Hz.
constexpr int kStartBlankFrames = 4;

// Targets moved at human speed (assets/scenes/motion.yaml): the duck still, the box carried at 0.5 m/s,
// the duck carried at 0.5 m/s while turned at 90 deg/s, the box at 1 m/s. Each projector frame's error
// is measured at its display time (about 50 ms after the capture its pose came from).
TEST(TourTest, PredictionKeepsMovingTargetsWithinTheGoal) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/motion.yaml");
  const auto off = tracking_tour(scene, 4, 2.0, false);
  const auto on = tracking_tour(scene, 4, 2.0, true);
  ASSERT_EQ(off.visits.size(), 4U);
  ASSERT_EQ(on.visits.size(), 4U);
  // Still: prediction adds nothing (the goal: at most 0.1 mm).
  EXPECT_FALSE(on.visits[0].moved);
  EXPECT_NEAR(on.visits[0].still_mean_mm, off.visits[0].still_mean_mm, 0.1);
  for (const int i : {1, 2}) {
    SCOPED_TRACE(on.visits[i].target);
    ASSERT_TRUE(on.visits[i].moved);
    EXPECT_GT(off.visits[i].moving_mean_mm, 10.0);  // without prediction the content trails the target
    EXPECT_LT(on.visits[i].moving_mean_mm, 5.0);    // the goal at 0.5 m/s and 90 deg/s
    EXPECT_LE(on.visits[i].moving_blank_frames, kStartBlankFrames);
    EXPECT_LT(on.visits[i].timeline.back().mean_mm, 3.0);
    EXPECT_NEAR(on.visits[i].age_p50_ms, 50.0, 1.0);  // 20 ms processing, the next frame, one refresh
  }
  EXPECT_LT(on.visits[1].moving_p95_mm, 10.0);
  // 1 m/s, 3.3 cm between camera frames: followed without a blank frame (the tracker starts from the
  // prediction). The start is sudden: for the first frames the newest pose is from before it, and the
  // light of the edge markers falls past the box onto the wall (about 200 mm on two frames), which
  // weighs on the mean; the median frame is on the object.
  EXPECT_EQ(on.visits[3].target, "box");
  EXPECT_LE(on.visits[3].moving_blank_frames, kStartBlankFrames);
  // ...and within the tracker's first pass (its coarsest level reaches 10 cm): with 4 cm there the
  // start's frame needed the wider second pass, twice the time.
  EXPECT_EQ(on.visits[3].second_pass_frames, 0);
  EXPECT_EQ(off.visits[3].second_pass_frames, 0);
  EXPECT_LT(on.visits[3].moving_mean_mm, 20.0);
  std::vector<double> moving;
  for (const auto& x : on.visits[3].timeline)
    if (x.moving) moving.push_back(x.mean_mm);
  ASSERT_GT(moving.size(), 30U);
  std::nth_element(moving.begin(), moving.begin() + moving.size() / 2, moving.end());
  EXPECT_LT(moving[moving.size() / 2], 3.0);
  EXPECT_LT(on.visits[3].timeline.back().mean_mm, 3.0);
}

// The duck's fourth visit in motion.yaml: turned and slid from rest at constant acceleration to 1 m/s
// and 180 deg/s (3.3 cm and 6 degrees between camera frames at the end), then let go. Run alone (the
// scene's tour cut to that visit): followed on every frame within the tracker's first pass, and with
// prediction within 8 mm mean (20 ms processing; the 0.5 m/s goal is 5).
TEST(TourTest, ATargetTurnedAt180DegreesPerSecondIsFollowed) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/motion.yaml");
  const auto* fast = scene.targets.at(static_cast<std::size_t>(scene.target_index("duck"))).motion_on(4);
  ASSERT_NE(fast, nullptr);
  const auto on = tracking_tour(duck_alone(scene, *fast), 1, 2.0, true);
  ASSERT_EQ(on.visits.size(), 1U);
  const auto& v = on.visits[0];
  ASSERT_TRUE(v.moved);
  EXPECT_LE(v.moving_blank_frames, kStartBlankFrames);
  EXPECT_EQ(v.second_pass_frames, 0);
  EXPECT_LT(v.moving_mean_mm, 8.0);
  EXPECT_LT(v.moving_p95_mm, 15.0);
  EXPECT_LT(v.timeline.back().mean_mm, 3.0);
}

// Faster than tracking follows (issue 14: recovery within 0.5 s): the duck lifted and put down 18 cm
// away and turned 30 degrees within 40 ms. The worker finds it again on the same or the next frames
// (the wider pass, then one ICP), the motion filter starts again from where it is instead of
// extrapolating the jump, and the error is back under 3 mm for good within half a second.
TEST(TourTest, ATargetMovedFasterThanTrackingFollowsIsFoundAgainWithinHalfASecond) {
  projbot::config::TargetMotion jump;
  jump.start_s = 0.5;
  jump.duration_s = 0.04;
  jump.translation_m = {0.15, 0.1, 0.0};
  jump.rpy_deg = {0.0, 0.0, 30.0};
  jump.profile = projbot::config::MotionProfile::constant;
  const auto on = tracking_tour(duck_alone(projbot::config::load_scene(kAssets + "/scenes/motion.yaml"), jump), 1, 2.0, true);
  ASSERT_EQ(on.visits.size(), 1U);
  const auto& v = on.visits[0];
  ASSERT_TRUE(v.moved);
  EXPECT_GT(v.reconverge_s, 0.0);  // the jump itself is not followed: the error left 3 mm...
  EXPECT_LT(v.reconverge_s, 0.5);  // ...and was back within half a second
  EXPECT_TRUE(v.timeline.back().shown);
  EXPECT_LT(v.timeline.back().mean_mm, 1.5);
}

// A target that is not there (present: false) is searched for within the follower's budget and never
// lit; the target before it is tracked on every frame of its dwell (counted in simulated time).
TEST(TourTest, AnAbsentTargetIsNeverLitAndSearchedWithinItsBudget) {
  const auto scene = demo_with("    model: ../models/BoxTextured/BoxTextured.gltf\n",
                               "    model: ../models/BoxTextured/BoxTextured.gltf\n    present: false\n");
  const auto report = tracking_tour(scene, 2, 1.0);
  ASSERT_EQ(report.visits.size(), 2U);
  const auto& duck = report.visits[0];
  const auto& box = report.visits[1];
  EXPECT_TRUE(duck.target_present);
  EXPECT_EQ(duck.lit_frames, 61);  // arrival + 60 projector frames: tracked on every one
  EXPECT_DOUBLE_EQ(duck.first_light_s, 0.0);
  EXPECT_FALSE(box.target_present);
  EXPECT_EQ(box.lit_frames, 0);
  EXPECT_LT(box.first_light_s, 0.0);
  for (const auto& t : box.timeline) EXPECT_FALSE(t.shown);
  // The spacing {0, 3, 9, 15, 30} allows attempts at arrival and on frames 1, 5 and 15 of 30 at most;
  // the duty cycle (a quarter of the worker's time) may space them further. Every frame the worker
  // took is either an attempt or a wait; those that came while it was busy were dropped.
  EXPECT_GE(box.search.attempts, 1);
  EXPECT_LE(box.search.attempts, 4);
  EXPECT_EQ(box.search.attempts + box.search.frames_waited, box.tracked_frames + 1);
  EXPECT_EQ(box.tracked_frames + box.dropped_frames, 30);
}

// Someone carries the box away mid-visit: the light goes out within 100 ms of the first depth frame
// that shows it gone, and its next visit finds it absent and never lights it.
TEST(TourTest, ARemovedTargetIsBlankedWithin100ms) {
  const auto scene = demo_with(
      "motion: {visit: 2, start_s: 0.5, duration_s: 2.0, translation: [0.08, -0.06, 0.0], rpy_deg: [0, 0, 15], stays: true}",
      "motion: {visit: 1, start_s: 0.5, duration_s: 0.2, removed: true}");
  const auto report = tracking_tour(scene, 4, 1.5);
  ASSERT_EQ(report.visits.size(), 4U);
  const auto& removed = report.visits[1];
  ASSERT_EQ(removed.target, "box");
  EXPECT_TRUE(removed.projected);
  EXPECT_GE(removed.blank_after_removal_s, 0.0);
  EXPECT_LE(removed.blank_after_removal_s, 0.1);
  // Lit at arrival and on the projector frames shown until the blank shows (0.7 s plus at most 0.1 s,
  // at 60 Hz: 42 to 48 frames).
  EXPECT_GE(removed.lit_frames, 42);
  EXPECT_LE(removed.lit_frames, 49);
  EXPECT_FALSE(report.visits[3].target_present);
  EXPECT_EQ(report.visits[3].lit_frames, 0);
}

// The twin's clock on a hand-computed case: a still duck, 20 ms from capture to pose, a 60 Hz projector
// with 30 ms of input lag. Projector frame j starts at j/60 s and is lit at j/60 + 1/60 + 0.030 s; it
// draws the newest pose ready by its start, from the capture at k/30 s with k/30 + 0.020 <= j/60.
TEST(TourTest, EachProjectorFrameIsMeasuredAtItsDisplayTime) {
  auto scene = demo_with("far: 10}", "far: 10, input_lag_ms: 30}");
  const auto report = tracking_tour(scene, 1, 0.5);
  ASSERT_EQ(report.visits.size(), 1U);
  const auto& timeline = report.visits[0].timeline;
  ASSERT_EQ(timeline.size(), 30U);  // 0.5 s at 60 Hz
  for (std::size_t i = 0; i < timeline.size(); ++i) {
    const double start = static_cast<double>(i + 1) / 60.0;
    EXPECT_NEAR(timeline[i].t_s, start + 1.0 / 60.0 + 0.030, 1e-9) << i;
    const double capture = std::max(0.0, std::floor((start - 0.020 + 1e-9) * 30.0) / 30.0);  // 0: the arrival's pose
    EXPECT_NEAR(timeline[i].age_ms, 1000.0 * (timeline[i].t_s - capture), 1e-6) << i;
    EXPECT_TRUE(timeline[i].shown);
    EXPECT_LT(timeline[i].mean_mm, 3.0);
  }
}

// The shop (issue 11): a 1.45 m figure standing on the floor half a metre from a wall, a shelf at its
// hand. Before the floor was left out and the scan cropped to the guess's silhouette, the gate blanked it
// (inliers 0.47: floor points counted against it) after 36 s of restarts and global searches.
TEST(TourTest, TheShopFigureOnTheFloorIsLit) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto localized = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(localized.visits.size(), 1U);
  EXPECT_EQ(localized.visits[0].target, "figure");
  EXPECT_TRUE(localized.visits[0].projected);
  EXPECT_FALSE(localized.visits[0].icp.reinitialised);  // found from the guess, no global search
  // The shelf touching its hand pulled ICP to 3.7 mm; the projective polish after it does not follow it.
  EXPECT_LT(localized.visits[0].mean_mm, 2.0);
  // The pan-tilt aims at the model's middle, not its origin at the feet: every marker, the chest's too,
  // is in the projector's image and lit (aimed at the feet, the chest was above the image).
  ASSERT_EQ(localized.visits[0].markers.size(), 5U);
  for (const auto& m : localized.visits[0].markers) EXPECT_TRUE(m.in_image && m.landed) << m.marker_m.transpose();
  const auto tracked = tracking_tour(scene, 1, 1.0);
  ASSERT_EQ(tracked.visits.size(), 1U);
  EXPECT_EQ(tracked.visits[0].lit_frames, 61);
  EXPECT_LT(tracked.visits[0].still_mean_mm, 2.0);
  EXPECT_TRUE(tracked.visits[0].neighbours.empty());  // the shelf beside it is no target
}

// The shop's box, seen nearly face-on past a pillar: depth pinned it only loosely along its face (1.7-2.9
// mm off sideways over three visits, the Kinect's edges being noisy). Its texture is the content, and
// the colour registered to the depth places it along the face.
TEST(TourTest, TheShopBoxSeenFaceOnIsPlacedAlongItsFaceByItsColour) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  projbot::twin::TourOptions o;
  o.visits = 1;
  const auto tour = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(tour.visits.size(), 1U);
  EXPECT_TRUE(tour.visits[0].projected);
  EXPECT_LT(tour.visits[0].mean_mm, 1.0);
  EXPECT_GT(tour.visits[0].icp.colour_shift_mm, 0.5);  // colour did the work, not depth
  EXPECT_GT(tour.visits[0].icp.colour_agreement, 0.8);
  EXPECT_LT(std::abs(tour.visits[0].icp.footing_height_error_mm), 5.0);
}

// Tracking mode: the box's first pose is placed by colour, and tracking holds it there. Before the
// hold, tracking slid it back along the face to the depth's optimum within a frame: 2.2-2.8 mm.
TEST(TourTest, TrackingHoldsTheShopBoxWhereColourPlacedIt) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  const auto tour = tracking_tour(scene, 1, 1.5);
  ASSERT_EQ(tour.visits.size(), 1U);
  const auto& v = tour.visits[0];
  EXPECT_EQ(v.lit_frames, static_cast<int>(v.timeline.size()) + 1);  // every frame, the arrival's too
  EXPECT_GT(v.icp.colour_shift_mm, 0.5);
  EXPECT_LT(v.still_mean_mm, 1.0);
  ASSERT_FALSE(v.timeline.empty());
  EXPECT_LT(v.timeline.back().mean_mm, 1.0);
}

// ...and lets go of it when the box is moved: from there on depth alone follows it. (Here the 3 mm
// rule let go, 3.2 mm from the held pose; a frame that tracking fails lets go as well.)
TEST(TourTest, AHeldBoxThatIsMovedIsFollowed) {
  auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  scene.visits = {"box"};
  projbot::config::TargetMotion move;
  move.visit = 1;
  move.start_s = 0.5;
  move.duration_s = 1.0;
  move.translation_m = Eigen::Vector3d(0.05, 0.03, 0.0);
  move.stays = true;
  for (auto& t : scene.targets)
    if (t.name == "box") t.motions = {move};
  const auto tour = tracking_tour(scene, 1, 2.5);
  ASSERT_EQ(tour.visits.size(), 1U);
  const auto& v = tour.visits[0];
  EXPECT_GT(v.icp.colour_shift_mm, 0.5);  // it was held
  EXPECT_LE(v.moving_blank_frames, kStartBlankFrames);
  ASSERT_FALSE(v.timeline.empty());
  EXPECT_TRUE(v.timeline.back().shown);
  EXPECT_LT(v.timeline.back().mean_mm, 4.0);  // depth alone along the face: about 2 mm
}

// Depth pins the Duck; colour alone (its luminance's correlation with the image) sometimes peaks a few
// millimetres off, on the sensor's noise. Acquisition takes colour's move only where the depth's error
// does not grow: among the 20 captures of bench acquire's Duck (after the figure's stop, as the bench
// drives), the two where colour alone moves the depth's pose more than 2 mm are acquired within 0.5 mm,
// colour's move refused (before, they were lit 2.6-3.3 mm off). And colours that disagree with the image
// refuse a pose however well the depth fits.
TEST(TourTest, ColourMovesNoPoseThatDepthPins) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  twin.arrive(twin.target_index("figure"), 0);
  const std::size_t duck = twin.target_index("duck");
  const projbot::twin::Arrival arrival = twin.arrive(duck, 1);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const Eigen::Matrix4d T_true = projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true;
  const auto& cloud = twin.targets()[duck].cloud;
  const projbot::alignment::TargetFollower follower(cloud, twin.camera());
  const auto footing =
      projbot::alignment::footing_in_camera(cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
  for (const std::uint32_t seed : {8924U, 8935U}) {  // the two captures (of 20) where it happened
    const auto depth = twin.capture(T_world_camera, seed);
    const auto colour = twin.capture_colour(T_world_camera, seed);
    const auto without = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m());
    const auto alone = projbot::alignment::colour_refined(cloud, without.T_scan_model, depth, colour, twin.camera());
    EXPECT_GT(alone.shift_m.norm(), 0.002) << "seed " << seed;  // the case is met: colour alone misleads
    const auto r = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m(), &colour);
    EXPECT_TRUE(r.converged) << "seed " << seed;
    EXPECT_EQ(r.colour_shift_mm, 0.0) << "seed " << seed;
    EXPECT_LT(projbot::alignment::translation_norm_m(projbot::alignment::rigid_inverse(T_true) * r.T_scan_model), 0.0005)
        << "seed " << seed;
    // Colours that disagree (the image's negative: correlation about -0.95) refuse a pose depth likes.
    auto negative = colour;
    for (std::size_t i = 0; i < negative.rgba.size(); ++i)
      if (i % 4 != 3) negative.rgba[i] = static_cast<std::uint8_t>(255 - negative.rgba[i]);
    const auto refused = follower.acquire(depth, T_true, footing, follower.silhouette_grow_m(), &negative);
    EXPECT_FALSE(refused.converged) << "seed " << seed;
    EXPECT_LT(refused.colour_agreement, 0.0) << "seed " << seed;
  }
}

// Two targets side by side (assets/scenes/display.yaml, issue 11 item 5): from either one's stop the
// other stands in the projector's image too. Both are acquired from the same capture and lit in the
// same frames; in tracking mode both are tracked all along.
TEST(TourTest, ANeighbourInViewIsTrackedAndLitWithTheVisitedTarget) {
  const auto scene = projbot::config::load_scene(kAssets + "/scenes/display.yaml");
  const auto tracked = tracking_tour(scene, 2, 1.0);
  ASSERT_EQ(tracked.visits.size(), 2U);
  for (const auto& v : tracked.visits) {
    SCOPED_TRACE(v.target);
    EXPECT_EQ(v.lit_frames, 61);
    EXPECT_LT(v.still_mean_mm, 1.5);
    ASSERT_EQ(v.neighbours.size(), 1U);
    const auto& n = v.neighbours.front();
    EXPECT_EQ(n.target, v.target == "duck" ? "box" : "duck");
    EXPECT_TRUE(n.projected);
    EXPECT_LT(n.mean_mm, 1.5);
    EXPECT_EQ(n.frames, 61);  // arrival + 60 projector frames
    EXPECT_EQ(n.lit_frames, 61);
    EXPECT_LT(n.lit_mean_mm, 1.5);  // measured 0.42-0.93 (2.0 mm on the box before colour's hold)
    EXPECT_LT(n.worst_mm, 2.0);
  }
  projbot::twin::TourOptions o;
  o.visits = 2;
  const auto localized = projbot::twin::run_tour(scene, o);
  ASSERT_EQ(localized.visits.size(), 2U);
  for (const auto& v : localized.visits) {
    SCOPED_TRACE(v.target);
    ASSERT_EQ(v.neighbours.size(), 1U);
    EXPECT_TRUE(v.neighbours.front().projected);
    EXPECT_EQ(v.neighbours.front().frames, 1);  // one alignment per stop, one frame
    EXPECT_LT(v.neighbours.front().mean_mm, 1.5);
  }
}

// The box is not on its plinth: at the duck's stop the robot still expects it there (the map), finds
// nothing and blanks it, while the duck beside it is lit all along.
TEST(TourTest, AnAbsentNeighbourIsBlankedOnItsOwn) {
  std::ifstream in(kAssets + "/scenes/display.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string from = "    model: ../models/BoxTextured/BoxTextured.gltf\n";
  ASSERT_NE(yaml.find(from), std::string::npos);
  yaml.replace(yaml.find(from), from.size(), from + "    present: false\n");
  const auto report = tracking_tour(projbot::config::parse_scene(yaml, kAssets + "/scenes/display.yaml"), 1, 1.0);
  ASSERT_EQ(report.visits.size(), 1U);
  const auto& duck = report.visits.front();
  EXPECT_EQ(duck.target, "duck");
  EXPECT_EQ(duck.lit_frames, 61);
  EXPECT_LT(duck.still_mean_mm, 1.5);
  ASSERT_EQ(duck.neighbours.size(), 1U);
  EXPECT_FALSE(duck.neighbours.front().projected);
  EXPECT_EQ(duck.neighbours.front().frames, 61);
  EXPECT_EQ(duck.neighbours.front().lit_frames, 0);
}

}  // namespace
