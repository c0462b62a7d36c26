// The shop's stops in the twin: acquisition of the figure beside its shelf, the Duck's colour, the
// spectator's view and what the visitor sees.

#include "projbot/config/angles.hpp"
#include "twin_helpers.hpp"

namespace {

using namespace twin_test;
using projbot::twin::MeshRaycaster;
using projbot::twin::PlacedMesh;

namespace {

// The shop's twin with the robot arrived at the standing figure's stop (its first visit), one depth
// capture there, the figure's true pose in the camera and its footing from the map.
class ShopFigureStop : public ::testing::Test {
 protected:
  const projbot::config::Scene scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const std::size_t figure = twin.target_index("figure");
  const projbot::twin::Arrival arrival = twin.arrive(figure, 0);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const Eigen::Matrix4d T_true = projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[figure].T_world_target_true;
  const projbot::alignment::DepthImage depth = twin.capture(T_world_camera, 7919);
  const projbot::alignment::ModelCloud& cloud = twin.targets()[figure].cloud;
  const projbot::alignment::Footing footing =
      projbot::alignment::footing_in_camera(cloud, arrival.T_map_target, arrival.believed.T_world_camera.matrix());
};

}  // namespace

// From a guess 5 cm and 10 degrees off (bench acquire's), the crop grown by that much takes in the
// shelf beside the figure's hand, and ICP settled 11-19 mm sideways, turned 0.7 degrees about the line of
// sight, where the gate refused it. Cropped again at that estimate and refined, the shelf drops out;
// clustering the first crop leaves it out too, and so does ICP's median rejection.
TEST_F(ShopFigureStop, TheShopFigureIsFoundFromATenDegreeGuessBesideItsShelf) {
  using projbot::alignment::rigid_inverse;
  // 10 degrees about the line of sight through the figure's chest, and 5 cm sideways.
  const Eigen::Vector3d chest = (T_true * Eigen::Vector4d(0.0, 1.0, 0.0, 1.0)).head<3>();
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
  turn.topLeftCorner<3, 3>() = Eigen::AngleAxisd(projbot::config::radians(10.0), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  turn.topRightCorner<3, 1>() = chest - turn.topLeftCorner<3, 3>() * chest + Eigen::Vector3d(0.05, 0.0, 0.0);
  const Eigen::Matrix4d guess = turn * T_true;
  const double grow_m = projbot::alignment::guess_reach_m(cloud, 0.05, 10.0);
  const auto error = [&](const Eigen::Matrix4d& T) { return rigid_inverse(T_true) * T; };
  const projbot::alignment::TargetFollower follower(cloud, twin.camera());
  const auto r = follower.acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r.converged) << "inliers " << r.inlier_ratio;
  EXPECT_TRUE(follower.passes(follower.verify(depth, r.T_scan_model)));
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r.T_scan_model)), 0.003);
  EXPECT_LT(projbot::alignment::rotation_angle_deg(error(r.T_scan_model)), 0.5);
  // Found by the projective start: only ICP's finest stage ran on it (coarse to fine from this guess,
  // ICP took 50-90 iterations, over a second here).
  EXPECT_LE(r.iterations, 40) << r.iterations;
  // Without the second crop (recrop_m as wide as the first), clustering alone leaves the shelf out...
  projbot::alignment::WorkerConfig once;
  once.recrop_m = 10.0;
  const auto r1 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r1.converged);
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r1.T_scan_model)), 0.003);
  // ...and now with neither, nor ICP's rejection of correspondences far past their median, the gate
  // itself takes the shelf's points beside and behind the hand as saying nothing against the pose
  // (AcquisitionConfig::scan_from_origin): found all the same (before the gate judged them, not found).
  once.cluster_neighbours = false;
  once.acquisition.icp_median_factor = 0.0;
  // Without those two the search takes longer: on its 1.3 s CPU budget it ended 154 mm off in about one
  // run in three on a quiet machine. The gate is what is tested here, not the budget (AnAcquisitionStops-
  // AtItsBudgetAndBlanks is), so these run unbounded.
  once.acquire_budget_ms = 1e6;
  const auto r2 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(r2.converged) << "inliers " << r2.inlier_ratio;
  EXPECT_LT(projbot::alignment::translation_norm_m(error(r2.T_scan_model)), 0.003);
  once.acquisition.scan_from_origin = false;
  const auto r3 = projbot::alignment::TargetFollower(cloud, twin.camera(), once).acquire(depth, guess, footing, grow_m);
  EXPECT_TRUE(!r3.converged || projbot::alignment::translation_norm_m(error(r3.T_scan_model)) > 0.005)
      << "found with every point judged: " << 1000.0 * projbot::alignment::translation_norm_m(error(r3.T_scan_model)) << " mm";
}

// An acquisition is bounded (WorkerConfig::acquire_budget_ms): from a gross guess the whole search ran
// up to 27 s on this figure (restarts, then RANSAC over FPFH matches). Out of budget from the start, only
// the first ICP stages run (no restart, no global search) and what they leave is not taken: blanked.
TEST_F(ShopFigureStop, AnAcquisitionStopsAtItsBudgetAndBlanks) {
  Eigen::Matrix4d guess = T_true;  // 30 cm sideways and turned 40 degrees about the vertical
  guess.topLeftCorner<3, 3>() = Eigen::AngleAxisd(projbot::config::radians(40.0), Eigen::Vector3d::UnitY()).toRotationMatrix() *
                                T_true.topLeftCorner<3, 3>();
  guess(0, 3) += 0.30;
  projbot::alignment::WorkerConfig none;
  none.acquire_budget_ms = 0.0;
  const auto r = projbot::alignment::TargetFollower(cloud, twin.camera(), none)
                     .acquire(depth, guess, footing, projbot::alignment::guess_reach_m(cloud, 0.30, 40.0));
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.reinitialised);
  // ICP's first stage from the guess, then again on the crop at its estimate: 20 iterations each at most.
  EXPECT_LE(r.iterations, 2 * projbot::alignment::AcquisitionConfig{}.coarse_iterations) << r.iterations;
}

namespace {

// The shop's twin with the robot arrived at the Duck's stop (its first visit).
class ShopDuckStop : public ::testing::Test {
 protected:
  const projbot::config::Scene scene = projbot::config::load_scene(kAssets + "/scenes/shop.yaml");
  projbot::engine::Renderer renderer{projbot::engine::RendererOptions{}};
  projbot::twin::Twin twin{scene, {}, renderer};
  const std::size_t duck = twin.target_index("duck");
  const projbot::twin::Arrival arrival = twin.arrive(duck, 0);
};

}  // namespace

// The twin's colour camera (issue 11): registered to its depth, the textured model as it is, and the
// colour sensor's noise. Checked against the Duck drawn alone from the same viewpoint, noiseless.
TEST_F(ShopDuckStop, ColourIsRegisteredToDepthWithTheModelsTextureAndNoise) {
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const auto colour = twin.capture_colour(T_world_camera, 7);
  const auto depth = twin.capture(T_world_camera, 7);
  ASSERT_EQ(colour.width, depth.width);
  ASSERT_EQ(colour.height, depth.height);
  EXPECT_EQ(twin.capture_colour(T_world_camera, 7).rgba, colour.rgba);  // seeded
  // The Duck alone, noiseless, in colour and depth.
  const projbot::config::ProjectorConfig pinhole(twin.camera_pinhole());  // drawn through, as the twin does
  const std::vector<projbot::engine::DrawItem> duck_only{
      {twin.target_model_ids()[duck],
       projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true}};
  auto offscreen = renderer.make_offscreen(colour.width, colour.height);
  renderer.draw_frame(*offscreen, pinhole, duck_only);
  const auto alone = offscreen->read_back();
  auto depth_camera = renderer.make_depth_camera(colour.width, colour.height);
  renderer.draw_frame(*depth_camera, pinhole, duck_only);
  const auto alone_depth = depth_camera->read_back_depth();
  // Where the Duck is (nothing stands in front of it at its stop): the scene's colour is the texture's
  // plus zero-mean noise of the sensor's sigma, and the scene's depth is the Duck's.
  double sum = 0.0, sum2 = 0.0, depth_off = 0.0;
  std::size_t n = 0, yellow = 0, depth_n = 0;
  for (int i = 0; i < colour.width * colour.height; ++i) {
    const float z = alone_depth.z_m[static_cast<std::size_t>(i)];
    if (z <= 0.0F) continue;
    const std::uint8_t* a = &alone.rgba[static_cast<std::size_t>(i) * 4];
    const std::uint8_t* c = &colour.rgba[static_cast<std::size_t>(i) * 4];
    for (int ch = 0; ch < 3; ++ch) {
      if (a[ch] < 10 || a[ch] > 245) continue;  // no clipping at 0 or 255
      const double d = static_cast<double>(c[ch]) - a[ch];
      sum += d, sum2 += d * d, ++n;
    }
    yellow += a[0] > 180 && a[1] > 150 && a[2] < 90 ? 1 : 0;
    if (depth.depth_m[static_cast<std::size_t>(i)] > 0.0F) {
      depth_off += std::abs(depth.depth_m[static_cast<std::size_t>(i)] - z);
      ++depth_n;
    }
  }
  ASSERT_GT(n, 20000U);
  const double count = static_cast<double>(n);
  const double mean = sum / count, sigma = std::sqrt(sum2 / count - mean * mean);
  EXPECT_LT(std::abs(mean), 0.2);
  EXPECT_NEAR(sigma, projbot::twin::Twin::kColourNoiseSigma, 0.3);
  EXPECT_GT(static_cast<double>(yellow) / static_cast<double>(depth_n), 0.8);  // the Duck's texture is mostly yellow
  ASSERT_GT(depth_n, 5000U);
  EXPECT_LT(depth_off / static_cast<double>(depth_n), 0.01);  // registered: the depth there is the Duck's (Kinect noise aside)
}

// The spectator's view (issue 11): the projector's light falls on the true surfaces. The Duck's own
// frame drawn at its true pose lights the Duck and almost nothing else; drawn 5 cm to the side, much of
// its light spills past it onto the table and the wall.
TEST_F(ShopDuckStop, SpectatorSeesLightFallOnTheTargetOrSpillPastIt) {
  const Eigen::Matrix4d T_world_projector = arrival.truth.T_world_projector.matrix();
  const Eigen::Matrix4d T_world_duck = twin.targets()[duck].T_world_target_true;
  projbot::twin::SpectatorView view(renderer, scene.projector);
  const Eigen::Matrix4d T_world_spectator =
      projbot::twin::spectator_pose(arrival.truth.T_world_camera.translation(), T_world_duck.topRightCorner<3, 1>());
  // Where the spectator sees the Duck.
  auto depth_camera = renderer.make_depth_camera(view.pinhole().width_px, view.pinhole().height_px);
  const std::size_t duck_id = twin.target_model_ids()[duck];
  const std::vector<projbot::engine::DrawItem> seen{
      {duck_id, projbot::alignment::rigid_inverse(T_world_spectator) * T_world_duck}};
  renderer.draw_frame(*depth_camera, view.pinhole(), seen);
  const auto duck_depth = depth_camera->read_back_depth();
  auto frame_target = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  projbot::assets::Image black;
  black.width = scene.projector.width_px, black.height = scene.projector.height_px;
  black.rgba.assign(static_cast<std::size_t>(black.width) * black.height * 4, 0);
  const auto unlit = view.draw(twin, T_world_spectator, T_world_projector, black);
  // Lit pixels on the Duck and off it, for the Duck's frame drawn at T_projector_duck.
  const auto lit = [&](const Eigen::Matrix4d& T_projector_duck) {
    const std::vector<projbot::engine::DrawItem> drawn{{duck_id, T_projector_duck}};
    renderer.draw_frame(*frame_target, scene.projector, drawn);
    const auto picture = view.draw(twin, T_world_spectator, T_world_projector, frame_target->read_back());
    std::array<std::size_t, 2> on_off{0, 0};
    for (std::size_t i = 0; i < duck_depth.z_m.size(); ++i) {
      const int gain = picture.rgba[i * 4] + picture.rgba[i * 4 + 1] - unlit.rgba[i * 4] - unlit.rgba[i * 4 + 1];
      if (gain > 20) ++on_off[duck_depth.z_m[i] > 0.0F ? 0 : 1];
    }
    return on_off;
  };
  const Eigen::Matrix4d T_projector_duck = projbot::alignment::rigid_inverse(T_world_projector) * T_world_duck;
  const auto right = lit(T_projector_duck);
  EXPECT_GT(right[0], 5000U);                                                      // the Duck is lit
  EXPECT_LT(static_cast<double>(right[1]), 0.03 * static_cast<double>(right[0]));  // edges only
  Eigen::Matrix4d shifted = T_projector_duck;
  shifted(0, 3) += 0.05;
  const auto off = lit(shifted);
  EXPECT_GT(static_cast<double>(off[1]), 0.2 * static_cast<double>(off[0] + off[1]));  // spilled past it (32 %)
  // A frame of another size than the projector's is refused, naming both.
  projbot::assets::Image small = black;
  small.width = 64, small.height = 40;
  small.rgba.assign(64 * 40 * 4, 0);
  try {
    view.draw(twin, T_world_spectator, T_world_projector, small);
    ADD_FAILURE() << "a 64x40 frame was drawn";
  } catch (const projbot::twin::TwinError& e) {
    EXPECT_NE(std::string(e.what()).find("64x40, the projector 1280x800"), std::string::npos) << e.what();
  }
  // Without light the room is dimmed to its room light: a mid-grey wall of 200 shows about 60.
  std::size_t dim = 0;
  for (std::size_t i = 0; i < unlit.rgba.size(); i += 4) dim += unlit.rgba[i] < 0.35 * 255 ? 1 : 0;
  EXPECT_EQ(dim, unlit.rgba.size() / 4);
}

// Clustering where a neighbour touches the crop: the shop's vase stands inside the duck's silhouette
// crop grown by a 5 cm guess's reach; its surface runs on past the crop's edge and lies outside the
// duck's silhouette, so clustering leaves it out, and keeps the duck.
TEST_F(ShopDuckStop, ClusteringLeavesOutTheVaseTouchingTheDucksCrop) {
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  const auto depth = twin.capture(T_world_camera, 11);
  const auto& cloud = twin.targets()[duck].cloud;
  const Eigen::Matrix4d T_camera_duck =
      projbot::alignment::rigid_inverse(T_world_camera) * twin.targets()[duck].T_world_target_true;
  const double grow_m = projbot::alignment::guess_reach_m(cloud, 0.05, 3.0);
  const auto count = [&](bool cluster) {
    const auto crop = projbot::alignment::crop_to_silhouette(depth, twin.camera(), cloud, T_camera_duck, grow_m, cluster);
    int vase = 0, near_duck = 0;
    const auto& k = twin.camera();
    for (int y = 0; y < crop.height; ++y)
      for (int x = 0; x < crop.width; ++x) {
        const float z = crop.at(x, y);
        if (!(z > 0.0F)) continue;
        const Eigen::Vector4d p((x - k.cx_px) * z / k.fx_px, (y - k.cy_px) * z / k.fy_px, z, 1.0);
        const Eigen::Vector3d w = (T_world_camera * p).head<3>();
        vase += w.x() > 5.25 && w.x() < 5.39 && w.y() > 4.49 && w.y() < 4.67 && w.z() > 0.93 ? 1 : 0;  // above the table
        near_duck += (w - twin.targets()[duck].T_world_target_true.topRightCorner<3, 1>()).norm() < 0.15 ? 1 : 0;
      }
    return std::pair{vase, near_duck};
  };
  const auto [vase_plain, duck_plain] = count(false);
  const auto [vase_clustered, duck_clustered] = count(true);
  const std::string numbers = "vase pixels " + std::to_string(vase_plain) + " -> " + std::to_string(vase_clustered) + ", duck " +
                              std::to_string(duck_plain) + " -> " + std::to_string(duck_clustered);
  EXPECT_GT(vase_plain, 100) << numbers;  // the vase is in the plain crop (157 pixels; 0 clustered)
  EXPECT_LT(vase_clustered, vase_plain / 10) << numbers;
  EXPECT_GT(duck_clustered, 0.95 * duck_plain) << numbers;  // the duck stays
}

// CIEDE2000 against Sharma, Wu and Dalal's test data (Color Res. Appl. 30(1), 2005, Table 1: pairs 1, 2, 7,
// 17, 25 and 34), and L*a*b* of sRGB's white and red.
TEST(Appearance, Ciede2000MatchesSharmasTestData) {
  struct Pair {
    Eigen::Vector3d a, b;
    double de;
  };
  const Pair pairs[] = {{{50.0, 2.6772, -79.7751}, {50.0, 0.0, -82.7485}, 2.0425},
                        {{50.0, 3.1571, -77.2803}, {50.0, 0.0, -82.7485}, 2.8615},
                        {{50.0, 0.0, 0.0}, {50.0, -1.0, 2.0}, 2.3669},
                        {{50.0, 2.5, 0.0}, {73.0, 25.0, -18.0}, 27.1492},
                        {{60.2574, -34.0099, 36.2677}, {60.4626, -34.1751, 39.4387}, 1.2644},
                        {{2.0776, 0.0795, -1.1350}, {0.9033, -0.0636, -0.5514}, 0.9082}};
  for (const Pair& p : pairs) {
    EXPECT_NEAR(projbot::twin::ciede2000(p.a, p.b), p.de, 1e-4) << p.a.transpose() << " / " << p.b.transpose();
    EXPECT_NEAR(projbot::twin::ciede2000(p.b, p.a), p.de, 1e-4);  // symmetric
  }
  const Eigen::Vector3d white = projbot::twin::srgb_to_lab({1.0, 1.0, 1.0}), red = projbot::twin::srgb_to_lab({1.0, 0.0, 0.0});
  EXPECT_NEAR(white[0], 100.0, 0.01);
  EXPECT_NEAR(white[1], 0.0, 0.01);
  EXPECT_NEAR(red[0], 53.24, 0.01);
  EXPECT_NEAR(red[1], 80.09, 0.02);
  EXPECT_NEAR(red[2], 67.20, 0.02);
}

// The visitor's light (issue 43) at the shop's Duck: a wall patch lit by full white shows its reflectance
// times (room + the projector's lux there) over the reference light, as photometry.hpp computes it by
// hand; unlit, the room's light alone. And the Duck's own content, compensated at its true pose, is seen
// as its content scaled by k where it can be reached, uncompensated far off it.
TEST_F(ShopDuckStop, TheVisitorSeesReflectanceTimesLight) {
  const Eigen::Matrix4d T_world_projector = arrival.truth.T_world_projector.matrix();
  const Eigen::Matrix4d T_world_duck = twin.targets()[duck].T_world_target_true;
  projbot::twin::SpectatorView view(renderer, scene.projector);
  const Eigen::Matrix4d T_world_spectator =
      projbot::twin::spectator_pose(arrival.truth.T_world_camera.translation(), T_world_duck.topRightCorner<3, 1>());
  projbot::assets::Image white;
  white.width = scene.projector.width_px, white.height = scene.projector.height_px;
  white.rgba.assign(static_cast<std::size_t>(white.width) * white.height * 4, 255);
  const auto seen = view.see(twin, T_world_spectator, T_world_projector, white);
  auto black = white;
  std::fill(black.rgba.begin(), black.rgba.end(), 0);
  const auto dark = view.see(twin, T_world_spectator, T_world_projector, black);
  const double ambient = scene.room.ambient_lux, black_level = scene.projector.photometry.black_level;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < seen.white_lux.size(); i += 97) {
    const double rho = projbot::engine::srgb_to_linear(seen.albedo.rgba[4 * i] / 255.0);
    const double lit = projbot::engine::srgb_to_linear(seen.image.rgba[4 * i] / 255.0);
    const double unlit = projbot::engine::srgb_to_linear(dark.image.rgba[4 * i] / 255.0);
    const double E = seen.white_lux[i];
    if (rho * (ambient + E) / projbot::engine::kReferenceLux > 0.95 || rho < 0.05) continue;  // saturated or black
    // 8-bit sRGB both ways: half a level of the brighter value.
    EXPECT_NEAR(lit, rho * (ambient + E) / projbot::engine::kReferenceLux, 0.004 + 0.01 * lit) << i;
    EXPECT_NEAR(unlit, rho * (ambient + black_level * E) / projbot::engine::kReferenceLux, 0.002) << i;
    checked += E > 0.0 ? 1 : 0;
  }
  EXPECT_GT(checked, 300U);
  // The Duck's frame with and without compensation, scored as bench appearance scores it.
  auto frame = renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  const Eigen::Matrix4d T_projector_duck = projbot::alignment::rigid_inverse(T_world_projector) * T_world_duck;
  const auto& albedo = twin.targets()[duck].config.surface.albedo;
  const double k = projbot::engine::choose_gain(
      projbot::engine::surface_samples(twin.targets()[duck].model, scene.projector, T_projector_duck), albedo, ambient);
  EXPECT_GT(k, 0.2);
  EXPECT_LE(k, 1.0);
  std::array<projbot::twin::AppearanceScore, 2> scores;
  for (const bool on : {false, true}) {
    const projbot::engine::Compensation comp =
        on ? projbot::engine::compensation(albedo, ambient, k) : projbot::engine::Compensation{};
    renderer.draw_frame(*frame, scene.projector,
                        std::vector<projbot::engine::DrawItem>{{twin.target_model_ids()[duck], T_projector_duck, comp}});
    const auto looked = view.look(twin, T_world_spectator, T_world_projector);
    const auto picture = view.light(looked, frame->read_back());
    const auto content = view.content(twin, duck, T_world_spectator, looked);
    scores[on ? 1 : 0] = projbot::twin::score_appearance(picture, content, k, ambient, scene.projector.photometry);
  }
  EXPECT_GT(scores[1].pixels, 5000U);
  EXPECT_LT(scores[1].de2000_median, 5.0);  // issue 43's goals
  EXPECT_LT(scores[1].de2000_p95, 12.0);
  EXPECT_GT(scores[1].ssim, 0.85);
  EXPECT_GT(scores[1].psnr_db, scores[0].psnr_db + 8.0);
  EXPECT_GT(scores[0].de2000_median, 10.0);                             // the content as stored: far off
  EXPECT_EQ(scores[0].unreachable_share, scores[1].unreachable_share);  // the same k, the same reach
}

}  // namespace

// The projector's saturated share (issue 43, bench appearance's "projector saturated"): of the target's
// pixels (lit in the compensated frame or in the content as stored) those at 254 or more in a channel.
TEST(Appearance, TheSaturatedShareCountsTheTargetsPixelsAtFull) {
  projbot::assets::Image on, off;
  on.width = off.width = 4, on.height = off.height = 1;
  on.rgba = {255, 10, 10, 255, /**/ 0, 0, 0, 255, /**/ 100, 254, 0, 255, /**/ 0, 0, 0, 255};
  off.rgba = {9, 9, 9, 255, /**/ 40, 0, 0, 255, /**/ 100, 100, 0, 255, /**/ 0, 0, 0, 255};
  // Three target pixels (the second black when compensated: content darker than the room), two saturated;
  // the fourth is not the target.
  EXPECT_NEAR(projbot::twin::saturated_share(on, off), 2.0 / 3.0, 1e-12);
  on.rgba[0] = 253, on.rgba[9] = 253;
  EXPECT_DOUBLE_EQ(projbot::twin::saturated_share(on, off), 0.0);
  EXPECT_DOUBLE_EQ(projbot::twin::saturated_share(off, off), 0.0);
  off.width = 2, off.rgba.resize(8);
  EXPECT_THROW(projbot::twin::saturated_share(on, off), std::invalid_argument);
}
