// Acquisition on synthetic Kinect v1 frames: the Duck rendered by the engine's depth camera at known
// poses 0.8-2.0 m away, with and without the Kinect v1 noise model.

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <random>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

namespace {

const fs::path kDuck = fs::path(PROJBOT_SHARED_DATA) / "gltf" / "Duck" / "glTF-Binary" / "Duck.glb";

projbot::config::ProjectorConfig as_pinhole(const CameraIntrinsics& k) { return {k, 0.1, 10.0}; }

Eigen::Matrix4d perturb(const Eigen::Matrix4d& T, double angle_deg, double shift_m, std::mt19937& rng) {
  std::normal_distribution<double> g;
  Eigen::Matrix4d D = Eigen::Matrix4d::Identity();
  D.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(angle_deg * M_PI / 180.0, Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized()).toRotationMatrix();
  // Rotate about the target's own centre (its origin after recentring), then shift.
  Eigen::Matrix4d out = T;
  out.topLeftCorner<3, 3>() = D.topLeftCorner<3, 3>() * T.topLeftCorner<3, 3>();
  out.topRightCorner<3, 1>() += shift_m * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  return out;
}

class SyntheticDepthTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    renderer_ = std::make_unique<projbot::engine::Renderer>(projbot::engine::RendererOptions{});
    auto duck = projbot::assets::load_gltf(kDuck);
    projbot::assets::scale_and_recenter(duck, 0.2, true);  // a 32 cm toy
    model_id_ = renderer_->add_model(duck);
    model_ = std::make_unique<ModelCloud>(model_cloud_from(duck, 50000));
    camera_ = renderer_->make_depth_camera(k_.width_px, k_.height_px);
  }
  static void TearDownTestSuite() {
    camera_.reset();
    renderer_.reset();
    model_.reset();
  }

  static DepthImage render(const Eigen::Matrix4d& T_camera_target) {
    const std::vector<projbot::engine::DrawItem> items{{model_id_, T_camera_target}};
    renderer_->draw_frame(*camera_, as_pinhole(k_), items);
    const auto map = camera_->read_back_depth();
    return {map.width, map.height, map.z_m, 0.0};
  }

  // The textured box, 30 cm, 1.6 m away, nearly face-on (turned 8 degrees, tipped 10): its model cloud,
  // and depth and colour rendered at its pose (colour registered to depth, as a Kinect v1 delivers it).
  struct FaceOnBox {
    ModelCloud cloud;
    Eigen::Matrix4d T = projbot::config::pose_from_xyz_rpy({0.02, 0.05, 1.6}, {-10, 8, 0});
    DepthImage depth;
    projbot::assets::Image colour;
  };
  static FaceOnBox face_on_box(const std::optional<Eigen::Matrix4d>& T = std::nullopt) {
    FaceOnBox b;
    if (T) b.T = *T;
    auto box = projbot::assets::load_gltf(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF" / "BoxTextured.gltf");
    projbot::assets::scale_and_recenter(box, 0.3, true);
    const std::size_t id = renderer_->add_model(box);
    b.cloud = model_cloud_from(box, 50000);
    const std::vector<projbot::engine::DrawItem> items{{id, b.T}};
    renderer_->draw_frame(*camera_, as_pinhole(k_), items);
    const auto map = camera_->read_back_depth();
    b.depth = DepthImage{map.width, map.height, map.z_m, 0.0};
    const auto colour_target = renderer_->make_offscreen(k_.width_px, k_.height_px);
    renderer_->draw_frame(*colour_target, as_pinhole(k_), items);
    b.colour = colour_target->read_back();
    return b;
  }

  // The test poses: the duck upright (camera y is down) and turned, 0.8 - 2.0 m away.
  static std::vector<Eigen::Matrix4d> poses() {
    return {projbot::config::pose_from_xyz_rpy({0.05, -0.02, 0.8}, {180, 10, 30}),
            projbot::config::pose_from_xyz_rpy({-0.1, 0.05, 1.2}, {170, -20, -50}),
            projbot::config::pose_from_xyz_rpy({0.1, 0.1, 1.6}, {190, 0, 120}),
            projbot::config::pose_from_xyz_rpy({0.0, -0.1, 2.0}, {175, 15, -100})};
  }

  static inline std::unique_ptr<projbot::engine::Renderer> renderer_;
  static inline std::unique_ptr<projbot::engine::RenderTarget> camera_;
  static inline std::unique_ptr<ModelCloud> model_;
  static inline std::size_t model_id_ = 0;
  static inline const CameraIntrinsics k_ = CameraIntrinsics::kinect_v1();
};

}  // namespace

TEST_F(SyntheticDepthTest, DepthCameraMatchesTheModelSurface) {
  // Every rendered depth pixel back-projects onto the model's surface (within the sampling spacing).
  const Eigen::Matrix4d T = poses()[0];
  const PointCloud cloud = finite_points(depth_to_cloud(render(T), k_, 0.1, 10.0));
  ASSERT_GT(cloud.points.size(), 10000U);
  Aligner aligner(*model_);
  const AlignmentResult at_truth = aligner.score(cloud, T);
  EXPECT_GT(at_truth.inlier_ratio, 0.99);
  EXPECT_LT(at_truth.rmse_mm, 0.3);
}

TEST_F(SyntheticDepthTest, TheGateAllowsForTheSensorNoiseAtItsRange) {
  // Kinect v1 at 2 m: sigma 5.7 mm plus 11.5 mm disparity steps. A fixed 6 mm inlier distance leaves
  // part of a scan at its true pose unexplained; within two sigma of the noise at each point's range
  // nearly all of it is explained, and a pose 3 cm nearer still is not. At 0.8 m the tolerance stays the fixed 6 mm.
  const Eigen::Matrix4d far = poses()[3], near = poses()[0];
  const DepthImage noisy = apply_kinect_v1_noise(render(far), k_, KinectNoiseConfig{}, 77);
  const PointCloud scan = depth_to_cloud(noisy, k_);
  AcquisitionConfig fixed;
  fixed.depth_sigma_coeff = 0.0;
  const AlignmentResult by_fixed = Aligner(*model_, fixed).score(scan, far);
  const Aligner aligner(*model_);
  const AlignmentResult by_noise = aligner.score(scan, far);
  EXPECT_GT(by_noise.inlier_ratio, 0.95);
  EXPECT_GT(by_noise.inlier_ratio, by_fixed.inlier_ratio + 0.08);
  EXPECT_TRUE(by_noise.converged) << "rmse " << by_noise.rmse_mm << " scale " << by_noise.tolerance_scale;
  EXPECT_NEAR(by_noise.tolerance_scale, 2.0 * 1.65e-3 * 4.0 / 0.006, 0.3);  // about 2.2 at 2 m
  Eigen::Matrix4d nearer = far;
  nearer(2, 3) -= 0.03;
  EXPECT_FALSE(aligner.score(scan, nearer).converged);
  const PointCloud close = depth_to_cloud(apply_kinect_v1_noise(render(near), k_, KinectNoiseConfig{}, 78), k_);
  EXPECT_DOUBLE_EQ(aligner.score(close, near).tolerance_scale, 1.0);
}

TEST_F(SyntheticDepthTest, AnOccluderInFrontSaysNothingAgainstThePose) {
  // A board 2.5 cm in front of the duck's left half (a neighbour leaning on it): those points are not
  // the duck's, but they say nothing against its pose. Judged as occluders (the scan seen from its
  // origin) the truth passes; judged as unexplained it does not. The duck pushed 10 cm back, behind
  // its own surface, has most of the crop in front of it and is refused either way.
  const Eigen::Matrix4d T = poses()[0];
  DepthImage depth = render(T);
  int left = depth.width, right = 0;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x)
      if (has_depth(depth.at(x, y))) left = std::min(left, x), right = std::max(right, x);
  ASSERT_LT(left, right);
  std::size_t boarded = 0, seen = 0;
  for (int y = 0; y < depth.height; ++y)
    for (int x = 0; x < depth.width; ++x) {
      float& z = depth.depth_m[static_cast<std::size_t>(y) * depth.width + x];
      if (!has_depth(z)) continue;
      ++seen;
      if (x < (left + right) / 2) z -= 0.025F, ++boarded;
    }
  ASSERT_GT(boarded * 5, seen) << "the board hides a good part of the duck";
  const PointCloud scan = depth_to_cloud(depth, k_);
  AcquisitionConfig every_point;
  every_point.scan_from_origin = false;
  const AlignmentResult judged_all = Aligner(*model_, every_point).score(scan, T);
  const Aligner aligner(*model_);
  const AlignmentResult occluded = aligner.score(scan, T);
  EXPECT_FALSE(judged_all.converged) << "inliers " << judged_all.inlier_ratio;
  EXPECT_TRUE(occluded.converged) << "inliers " << occluded.inlier_ratio << " neutral " << occluded.neutral_ratio;
  EXPECT_GT(occluded.inlier_ratio, 0.95);
  EXPECT_GT(occluded.neutral_ratio, 0.15);
  EXPECT_LT(occluded.neutral_ratio, 0.6);
  Eigen::Matrix4d behind = T;
  behind(2, 3) += 0.10;
  const AlignmentResult pushed = aligner.score(scan, behind);
  EXPECT_FALSE(pushed.converged) << "inliers " << pushed.inlier_ratio << " neutral " << pushed.neutral_ratio;
}

TEST_F(SyntheticDepthTest, ABigScanIsThinnedToTheCapAndStaysAccurate) {
  // The duck at 0.8 m fills 20000 pixels; with a cap of 2000 points ICP and the gate work on a coarser
  // grid, and the pose stays within a millimetre.
  const Eigen::Matrix4d T = poses()[0];
  const PointCloud scan = depth_to_cloud(render(T), k_);
  ASSERT_GT(scan.finite_count(), 15000U);
  AcquisitionConfig capped;
  capped.max_scan_points = 2000;
  std::mt19937 rng(4);
  const AlignmentResult r = Aligner(*model_, capped).align(scan, perturb(T, 5.0, 0.02, rng));
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.scan_points, 2600U);
  EXPECT_GT(r.scan_points, 1000U);
  const Eigen::Matrix4d err = rigid_inverse(T) * r.T_scan_model;
  EXPECT_LT(translation_norm_m(err), 0.001);
  EXPECT_LT(rotation_angle_deg(err), 0.3);
}

TEST_F(SyntheticDepthTest, AFootingFromTheMapHoldsThePoseUprightAtItsHeight) {
  // A camera 1.1 m up, looking along the world's y and 20 degrees down, at the duck standing at 0.8 m
  // (a table's height). The footing is where the map says it stands: upright, its lowest point 0.8 m
  // up. A pose lifted 3 cm or tipped fails it; a guess tipped 35 degrees and 4 cm too high is stood
  // upright at the surveyed height before ICP and found.
  const double s = std::sin(20.0 * M_PI / 180.0), c = std::cos(20.0 * M_PI / 180.0);
  Eigen::Matrix4d T_world_camera = Eigen::Matrix4d::Identity();
  T_world_camera.topLeftCorner<3, 3>().col(0) = Eigen::Vector3d(1, 0, 0);
  T_world_camera.topLeftCorner<3, 3>().col(1) = Eigen::Vector3d(0, -s, -c);
  T_world_camera.topLeftCorner<3, 3>().col(2) = Eigen::Vector3d(0, c, -s);
  T_world_camera.topRightCorner<3, 1>() = Eigen::Vector3d(0.0, 0.0, 1.1);
  Eigen::Matrix4d T_world_target = projbot::config::pose_from_xyz_rpy({0.05, 1.4, 0.0}, {90, 0, 30});
  double lowest = 1e9;
  for (const auto& p : model_->points) lowest = std::min(lowest, (T_world_target.topLeftCorner<3, 3>() * p.cast<double>()).z());
  T_world_target(2, 3) = 0.8 - lowest;
  const Footing footing = footing_in_camera(*model_, T_world_target, T_world_camera);
  EXPECT_NEAR(footing.height_m, 0.8, 1e-9);
  EXPECT_NEAR(footing.floor.d, 1.1, 1e-9);  // the camera is 1.1 m above the floor
  EXPECT_NEAR(footing.floor.normal.dot(Eigen::Vector3d(0, -c, -s)), 1.0, 1e-9);
  const Eigen::Matrix4d T = rigid_inverse(T_world_camera) * T_world_target;
  const PointCloud scan = depth_to_cloud(render(T), k_);
  const Aligner aligner(*model_);
  const AlignmentResult truth = aligner.score(scan, T, footing);
  EXPECT_TRUE(truth.converged && truth.stands);
  EXPECT_NEAR(truth.footing_height_error_mm, 0.0, 0.5);
  EXPECT_LT(truth.footing_tilt_deg, 0.01);
  const auto moved = [&](const Eigen::Matrix4d& T_world_delta) {
    return Eigen::Matrix4d(rigid_inverse(T_world_camera) * T_world_delta * T_world_target);
  };
  const AlignmentResult lifted = aligner.score(scan, moved(projbot::config::pose_from_xyz_rpy({0, 0, 0.03}, {0, 0, 0})), footing);
  EXPECT_FALSE(lifted.stands || lifted.converged);
  EXPECT_NEAR(lifted.footing_height_error_mm, 30.0, 0.5);
  Eigen::Matrix4d tipped = Eigen::Matrix4d::Identity();  // 120 degrees about the world's x through the duck
  tipped.topLeftCorner<3, 3>() = Eigen::AngleAxisd(120.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d middle = T_world_target.topRightCorner<3, 1>();
  tipped.topRightCorner<3, 1>() = middle - tipped.topLeftCorner<3, 3>() * middle + Eigen::Vector3d(0.0, 0.0, 0.04);
  const AlignmentResult tipped_score = aligner.score(scan, moved(tipped), footing);
  EXPECT_NEAR(tipped_score.footing_tilt_deg, 120.0, 0.01);
  EXPECT_FALSE(tipped_score.stands);
  AcquisitionConfig one_icp;  // ICP from the guess alone: no restarts, no global search
  one_icp.reinitialise = false;
  one_icp.restart_angle_deg = 0.0;
  const Aligner icp_only(*model_, one_icp);
  const AlignmentResult r = icp_only.align(scan, moved(tipped), SearchStage::full, footing);
  EXPECT_TRUE(r.converged && r.stands);
  const Eigen::Matrix4d err = rigid_inverse(T) * r.T_scan_model;
  EXPECT_LT(translation_norm_m(err), 0.002);
  EXPECT_LT(rotation_angle_deg(err), 0.5);
  const AlignmentResult without = icp_only.align(scan, moved(tipped), SearchStage::full);
  EXPECT_GT(rotation_angle_deg(rigid_inverse(T) * without.T_scan_model), 30.0);  // ICP alone cannot turn it back
  EXPECT_THROW(footing_in_camera(ModelCloud{}, T_world_target, T_world_camera), AlignmentError);
}

TEST_F(SyntheticDepthTest, ColourMovesABoxSeenFaceOnAlongItsFace) {
  // The face-on box (face_on_box). From the truth moved along its face 3 mm sideways and 2 mm down, the
  // colour search along the face brings it back within 0.6 mm, unturned; a model without colours, or a
  // colour image of another size, leaves the pose as it was.
  const FaceOnBox b = face_on_box();
  const ModelCloud& cloud = b.cloud;
  const Eigen::Matrix4d& T = b.T;
  const DepthImage& depth = b.depth;
  const projbot::assets::Image& colour = b.colour;
  ASSERT_EQ(cloud.colours.size(), cloud.points.size());
  EXPECT_GT(colour_agreement(cloud, T, depth, colour, k_), 0.9);
  Eigen::Matrix4d off = T;
  off.topRightCorner<3, 1>() += T.topLeftCorner<3, 3>() * Eigen::Vector3d(0.003, 0.002, 0.0);  // along the face
  const double agreement_off = colour_agreement(cloud, off, depth, colour, k_);
  EXPECT_LT(agreement_off, colour_agreement(cloud, T, depth, colour, k_) - 0.05);
  const ColourRefinement r = colour_refined(cloud, off, depth, colour, k_);
  EXPECT_NEAR(r.agreement_before, agreement_off, 1e-12);
  EXPECT_GT(r.agreement_after, r.agreement_before + 0.05);
  EXPECT_LT((r.T_camera_model.topRightCorner<3, 1>() - T.topRightCorner<3, 1>()).norm(), 0.0006);
  EXPECT_LT(rotation_angle_deg(rigid_inverse(T) * r.T_camera_model), 0.1);
  ModelCloud plain = cloud;
  plain.colours.clear();
  EXPECT_TRUE(std::isnan(colour_agreement(plain, T, depth, colour, k_)));
  EXPECT_TRUE(colour_refined(plain, off, depth, colour, k_).T_camera_model.isApprox(off));
  projbot::assets::Image small = colour;
  small.width /= 2;
  EXPECT_TRUE(colour_refined(cloud, off, depth, small, k_).T_camera_model.isApprox(off));
}

TEST_F(SyntheticDepthTest, ColourTurnsABoxSeenFaceOnAboutItsFacesNormalAndReachesPastItsGrid) {
  // The bench's face-on box left by depth a degree turned about its face's normal (only the face's
  // edges hold that turn, and a degree is within the footing's tolerance) and 10 mm along its face,
  // past the colour search's first grid (8 mm): colour brings it back within 1 mm and 0.15 degrees.
  const FaceOnBox b = face_on_box();
  const Eigen::Vector3d normal = b.T.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ();  // the face towards the camera
  ASSERT_GT(std::abs(normal.z()), 0.9);
  for (const double turn_deg : {1.0, -1.0}) {
    Eigen::Matrix4d off = b.T;
    off.topLeftCorner<3, 3>() = Eigen::AngleAxisd(turn_deg * M_PI / 180.0, normal).toRotationMatrix() * b.T.topLeftCorner<3, 3>();
    off.topRightCorner<3, 1>() += b.T.topLeftCorner<3, 3>() * Eigen::Vector3d(0.008, -0.006, 0.0);
    const ColourRefinement r = colour_refined(b.cloud, off, b.depth, b.colour, k_);
    const Eigen::Matrix4d err = rigid_inverse(b.T) * r.T_camera_model;
    EXPECT_GT(r.agreement_after, r.agreement_before + 0.1) << turn_deg;
    EXPECT_GT(r.turn_deg, 0.5) << turn_deg;
    EXPECT_LT(translation_norm_m(err), 0.001) << turn_deg;  // 0.92 and 0.78 mm: the turn found is about the view's
    // weakest rotation, which is not quite the face's normal: 0.13 degrees of the turn stay
    EXPECT_LT(rotation_angle_deg(err), 0.15) << turn_deg;
  }
}

TEST_F(SyntheticDepthTest, ColourSaysWhenItsSearchRanOutOfReachAndASecondSearchGoesOn) {
  // The face-on box left 30 mm along its face, past what one search reaches (its coarse grid moves
  // twice: about 26 mm): the search says so, and one more from where it got to (as
  // TargetFollower::by_colour does) brings the box within 1 mm and 0.15 degrees. One that ends inside
  // its reach says that too.
  const FaceOnBox b = face_on_box();
  Eigen::Matrix4d off = b.T;
  off.topRightCorner<3, 1>() += b.T.topLeftCorner<3, 3>() * Eigen::Vector3d(0.030, 0.0, 0.0);
  const ColourRefinement first = colour_refined(b.cloud, off, b.depth, b.colour, k_);
  EXPECT_TRUE(first.out_of_reach);
  EXPECT_GT(translation_norm_m(rigid_inverse(b.T) * first.T_camera_model), 0.002);
  const ColourRefinement second = colour_refined(b.cloud, first.T_camera_model, b.depth, b.colour, k_);
  EXPECT_FALSE(second.out_of_reach);
  const Eigen::Matrix4d err = rigid_inverse(b.T) * second.T_camera_model;
  EXPECT_LT(translation_norm_m(err), 0.001);
  EXPECT_LT(rotation_angle_deg(err), 0.15);
  EXPECT_GT(second.agreement_after, first.agreement_after + 0.05);
}

TEST_F(SyntheticDepthTest, LooksAlikeTellsATexturedBoxsTurnsOntoItselfFromWrongPoses) {
  // BoxTextured turned 90 or 180 degrees lands on its own surface (the cube's symmetry), but its faces'
  // texture does not follow: over the whole model no such turn looks alike, nor does a 10 degree turn
  // or a 15 mm move; the duck turned half round is not the duck either. On the face-on box's faces the
  // camera sees, the truth looks like itself and a 15 mm move along the face does not.
  const FaceOnBox b = face_on_box();
  const auto turned = [](double deg, const Eigen::Vector3d& axis, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
    Eigen::Matrix4d D = Eigen::Matrix4d::Identity();
    D.topLeftCorner<3, 3>() = Eigen::AngleAxisd(deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
    D.topRightCorner<3, 1>() = t;
    return D;
  };
  EXPECT_TRUE(looks_alike(b.cloud, Eigen::Matrix4d::Identity()));
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)}) {
    for (const double deg : {10.0, 90.0, 180.0})
      EXPECT_FALSE(looks_alike(b.cloud, turned(deg, axis))) << deg << ' ' << axis.transpose();
    EXPECT_FALSE(looks_alike(b.cloud, turned(0.0, axis, 0.015 * axis))) << axis.transpose();
  }
  EXPECT_FALSE(looks_alike(*model_, turned(180.0, Eigen::Vector3d::UnitY())));
  EXPECT_FALSE(looks_alike(ModelCloud{}, Eigen::Matrix4d::Identity()));
  ModelCloud plain = b.cloud;  // one colour: content is where the shape is, and the shape alone says nothing
  std::fill(plain.colours.begin(), plain.colours.end(), Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  EXPECT_FALSE(looks_alike(plain, turned(180.0, Eigen::Vector3d::UnitX())));
  const std::vector<std::size_t> seen = visible_samples(b.cloud, b.T, b.depth, k_);
  ASSERT_EQ(seen.size(), 300u);
  for (const std::size_t i : seen)  // facing the camera: the box's points it sees are on its near faces
    ASSERT_LT((b.T.topLeftCorner<3, 3>() * b.cloud.normals[i].cast<double>()).z(), 0.0);
  EXPECT_TRUE(looks_alike(b.cloud, Eigen::Matrix4d::Identity(), seen));
  EXPECT_FALSE(looks_alike(b.cloud, turned(0.0, Eigen::Vector3d::UnitX(), Eigen::Vector3d(0.015, 0, 0)), seen));
  EXPECT_FALSE(looks_alike(b.cloud, Eigen::Matrix4d::Identity(), {b.cloud.points.size()}));  // no such point
}

TEST_F(SyntheticDepthTest, ALookAlikeTurnOfTheBoxIsTurnedBackToTheGuess) {
  // The face-on box's seen faces look the same under some of a cube's turns (bench acquire lit it
  // turned 180 degrees from gross guesses). Found turned so, the pose nearest a guess 40 degrees off the
  // truth is the truth; a pose near its guess is never moved.
  // Seen within 5 degrees of face-on, three of a cube's turns show the same picture (from 10 degrees
  // off, none: the top and a side come into view).
  const FaceOnBox b = face_on_box(projbot::config::pose_from_xyz_rpy({0.02, 0.05, 1.6}, {-5, 5, 0}));
  const std::vector<Eigen::Matrix4d> turns = box_turns(b.cloud);
  ASSERT_EQ(turns.size(), 23u);
  // A cube's turns: 90 or 270 degrees about its 3 axes (6), 180 about them and about 6 face diagonals
  // (9), 120 or 240 about its 4 body diagonals (8).
  std::map<long, int> by_angle;
  for (const Eigen::Matrix4d& t : turns) {
    ASSERT_NEAR(Eigen::Matrix3d(t.block(0, 0, 3, 3)).determinant(), 1.0, 1e-12);
    ++by_angle[std::lround(rotation_angle_deg(t))];
  }
  EXPECT_EQ(by_angle, (std::map<long, int>{{90, 6}, {120, 8}, {180, 9}}));
  const Eigen::Matrix4d off40 = b.T * projbot::config::pose_from_xyz_rpy({0.1, -0.2, 0.1}, {25, -20, 20});
  ASSERT_NEAR(rotation_angle_deg(rigid_inverse(b.T) * off40), 38.0, 3.0);
  const std::vector<std::size_t> seen = visible_samples(b.cloud, b.T, b.depth, k_, 100);
  int look_alikes = 0;
  for (const Eigen::Matrix4d& t : turns) {
    const Eigen::Matrix4d found = b.T * t;
    if (!looks_alike(b.cloud, rigid_inverse(t), seen)) {  // a different picture: never turned to the truth's
      const Eigen::Matrix4d moved = nearest_look_alike(b.cloud, found, off40, turns, b.depth, k_);
      EXPECT_GT(rotation_angle_deg(rigid_inverse(b.T) * moved), 45.0) << t;
      EXPECT_LE(rotation_angle_deg(rigid_inverse(off40) * moved), rotation_angle_deg(rigid_inverse(off40) * found) + 1e-9);
      continue;
    }
    ++look_alikes;
    const Eigen::Matrix4d back = nearest_look_alike(b.cloud, found, off40, turns, b.depth, k_);
    EXPECT_LT(translation_norm_m(rigid_inverse(b.T) * back), 1e-9) << t;
    EXPECT_LT(rotation_angle_deg(rigid_inverse(b.T) * back), 1e-6) << t;
  }
  EXPECT_EQ(look_alikes, 3);
  for (const Eigen::Matrix4d& guess : {b.T, off40})
    EXPECT_TRUE(nearest_look_alike(b.cloud, b.T, guess, turns, b.depth, k_).isApprox(b.T, 1e-12));
  EXPECT_TRUE(box_turns(ModelCloud{}).empty());
}

TEST_F(SyntheticDepthTest, TrackingHoldsTheBoxWhereColourPlacedIt) {
  // The face-on box of the test above. Its noisy depth is rendered 2.5 mm along its face from where
  // its colour is (as the shop's depth pulls its box 2 mm along the face): the follower's search, with
  // the colour image, moves it to the colour and tracking holds it there, where depth alone slides back.
  // (That it lets go when the box is moved: TourTest.AHeldBoxThatIsMovedIsFollowed.) A wall 0.9 m
  // behind the box gives the free-space check something to see.
  auto box = projbot::assets::load_gltf(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF" / "BoxTextured.gltf");
  auto wall = box;
  projbot::assets::scale_and_recenter(box, 0.3, true);
  projbot::assets::scale_and_recenter(wall, 4.0, true);
  const std::size_t id = renderer_->add_model(box), wall_id = renderer_->add_model(wall);
  const Eigen::Matrix4d T_wall = projbot::config::pose_from_xyz_rpy({0.0, 0.0, 4.5}, {0, 0, 0});  // its face at 2.5 m
  const Eigen::Matrix4d T = projbot::config::pose_from_xyz_rpy({0.02, 0.05, 1.6}, {-10, 8, 0});
  const auto along_face = [&](Eigen::Matrix4d pose, double x_m) {
    pose.topRightCorner<3, 1>() += T.topLeftCorner<3, 3>() * Eigen::Vector3d(x_m, 0.0, 0.0);
    return pose;
  };
  std::uint32_t seed = 40;
  const auto frame_at = [&](const Eigen::Matrix4d& pose, double t_s) {
    renderer_->draw_frame(*camera_, as_pinhole(k_),
                          std::vector<projbot::engine::DrawItem>{{id, along_face(pose, 0.0025)}, {wall_id, T_wall}});
    const auto map = camera_->read_back_depth();
    DepthImage d = apply_kinect_v1_noise(DepthImage{map.width, map.height, map.z_m, t_s}, k_, KinectNoiseConfig{}, seed++);
    d.capture_time_s = t_s;
    return d;
  };
  const auto colour_target = renderer_->make_offscreen(k_.width_px, k_.height_px);
  renderer_->draw_frame(*colour_target, as_pinhole(k_), std::vector<projbot::engine::DrawItem>{{id, T}, {wall_id, T_wall}});
  const projbot::assets::Image colour = colour_target->read_back();
  TargetFollower follower(model_cloud_from(box, 50000), k_);
  const auto error_m = [&](const Eigen::Matrix4d& truth, const Eigen::Matrix4d& pose) {
    return translation_norm_m(rigid_inverse(truth) * pose);
  };
  follower.set_initial_guess(along_face(T, 0.0025));
  const auto first = follower.step(frame_at(T, 0.0), &colour);
  ASSERT_TRUE(first && !first->lost);
  EXPECT_TRUE(follower.holding());
  EXPECT_GT(follower.search_stats().colour_shift_mm, 1.0);
  EXPECT_LT(error_m(T, first->T_camera_target), 0.0008);
  for (int i = 1; i <= 10; ++i) {  // still: held
    const auto s = follower.step(frame_at(T, i / 30.0));
    ASSERT_TRUE(s && !s->lost);
    EXPECT_LT(error_m(T, s->T_camera_target), 0.0008) << "frame " << i;
  }
  EXPECT_TRUE(follower.holding());
}

TEST_F(SyntheticDepthTest, AccurateWithoutNoise) {
  Aligner aligner(*model_);
  std::mt19937 rng(1);
  for (const auto& T : poses()) {
    const PointCloud scan = depth_to_cloud(render(T), k_);
    const AlignmentResult r = aligner.align(scan, perturb(T, 5.0, 0.02, rng));
    const Eigen::Matrix4d err = rigid_inverse(T) * r.T_scan_model;
    EXPECT_TRUE(r.converged);
    EXPECT_LT(translation_norm_m(err), 0.001) << "z " << T(2, 3);
    EXPECT_LT(rotation_angle_deg(err), 0.2) << "z " << T(2, 3);
  }
}

TEST_F(SyntheticDepthTest, AccurateWithKinectNoise) {
  // The goal, 3 mm / 0.5 degrees with the noise model, judged per pose over four noise
  // realisations: the rotation error at 2 m depends on the draw (12 draws at 2 m: mean 0.35 degrees,
  // single draws 0.2-0.8), so its mean must meet 0.5 degrees and no draw may exceed 1 degree.
  Aligner aligner(*model_);
  std::mt19937 rng(2);
  std::uint32_t seed = 10;
  for (const auto& T : poses()) {
    const DepthImage clean = render(T);
    double sum_deg = 0.0;
    for (int draw = 0; draw < 4; ++draw) {
      const DepthImage noisy = apply_kinect_v1_noise(clean, k_, KinectNoiseConfig{}, seed++);
      const AlignmentResult r = aligner.align(depth_to_cloud(noisy, k_), perturb(T, 5.0, 0.02, rng));
      const Eigen::Matrix4d err = rigid_inverse(T) * r.T_scan_model;
      EXPECT_TRUE(r.converged) << "inliers " << r.inlier_ratio << " rmse " << r.rmse_mm;
      EXPECT_LT(translation_norm_m(err), 0.003) << "z " << T(2, 3);
      EXPECT_LT(rotation_angle_deg(err), 1.0) << "z " << T(2, 3);
      sum_deg += rotation_angle_deg(err);
    }
    EXPECT_LT(sum_deg / 4.0, 0.5) << "z " << T(2, 3);
  }
}

TEST_F(SyntheticDepthTest, ConvergesFromPoorInitialGuesses) {
  // The goal: from errors up to 10 cm / 20 degrees, at least 95% of trials converge.
  Aligner aligner(*model_);
  std::mt19937 rng(3);
  int trials = 0, good = 0;
  std::uint32_t seed = 100;
  for (const auto& T : poses()) {
    const PointCloud scan = depth_to_cloud(apply_kinect_v1_noise(render(T), k_, KinectNoiseConfig{}, seed++), k_);
    for (int i = 0; i < 6; ++i) {
      const AlignmentResult r = aligner.align(scan, perturb(T, 20.0, 0.10, rng));
      const Eigen::Matrix4d err = rigid_inverse(T) * r.T_scan_model;
      ++trials;
      const bool ok = r.converged && translation_norm_m(err) < 0.005 && rotation_angle_deg(err) < 1.0;
      good += ok ? 1 : 0;
      if (!ok)
        std::cout << "miss at z " << T(2, 3) << ": converged " << r.converged << " reinit " << r.reinitialised << " err "
                  << translation_norm_m(err) * 1000 << " mm " << rotation_angle_deg(err) << " deg, inliers " << r.inlier_ratio
                  << " rmse " << r.rmse_mm << "\n";
    }
  }
  std::cout << good << " of " << trials << " converged\n";
  EXPECT_GE(good * 100, trials * 95) << "fewer than 95% converged";
}

namespace {

// A 200 x 200 px square 1 m away in front of a wall at 1.5 m, and what a noise model makes of it.
struct SquareOnAWall {
  static constexpr int kLeft = 220, kTop = 140, kSize = 200;
  CameraIntrinsics k = CameraIntrinsics::kinect_v1();
  DepthImage clean{k.width_px, k.height_px, std::vector<float>(static_cast<std::size_t>(k.width_px* k.height_px), 1.5F), 0.0};
  SquareOnAWall() {
    for (int y = kTop; y < kTop + kSize; ++y)
      for (int x = kLeft; x < kLeft + kSize; ++x) clean.depth_m[static_cast<std::size_t>(y * k.width_px + x)] = 1.0F;
  }
  float at(const DepthImage& d, int x, int y) const { return d.depth_m[static_cast<std::size_t>(y * k.width_px + x)]; }
  // Share of the wall's pixels 1..band px beside the square's left or right edge (dx < 0: left of it) that are lost.
  double lost_beside(const DepthImage& d, int side, int band) const {
    int lost = 0, all = 0;
    for (int y = kTop + 10; y < kTop + kSize - 10; ++y)
      for (int s = 1; s <= band; ++s) {
        const int x = side < 0 ? kLeft - s : kLeft + kSize - 1 + s;
        ++all;
        lost += at(d, x, y) > 0.0F ? 0 : 1;
      }
    return static_cast<double>(lost) / all;
  }
};

// Pearson correlation of the square's depth error with that of the pixel `lag` px to its right, the
// error's standard deviation, the share of its inner pixels missing and the median nonzero step.
struct InsideSquare {
  double correlation = 0.0, sd_m = 0.0, missing = 0.0, median_step_m = 0.0;
};

InsideSquare inside_square(const SquareOnAWall& s, const DepthImage& d, int lag) {
  double ab = 0.0, aa = 0.0, sum = 0.0, sum2 = 0.0;
  int n = 0, pairs = 0, all = 0, missing = 0;
  std::vector<double> steps;
  for (int y = SquareOnAWall::kTop + 8; y < SquareOnAWall::kTop + SquareOnAWall::kSize - 8; ++y)
    for (int x = SquareOnAWall::kLeft + 8; x < SquareOnAWall::kLeft + SquareOnAWall::kSize - 8 - lag; ++x) {
      const float a = s.at(d, x, y), b = s.at(d, x + lag, y), next = s.at(d, x + 1, y);
      ++all;
      if (!(a > 0.0F)) {
        ++missing;
        continue;
      }
      sum += a - 1.0;
      sum2 += (a - 1.0) * (a - 1.0);
      ++n;
      if (next > 0.0F && std::abs(next - a) > 1e-6) steps.push_back(std::abs(next - a));
      if (!(b > 0.0F)) continue;
      ab += (a - 1.0) * (b - 1.0);
      aa += 0.5 * ((a - 1.0) * (a - 1.0) + (b - 1.0) * (b - 1.0));
      ++pairs;
    }
  InsideSquare out;
  out.correlation = pairs > 0 && aa > 0.0 ? ab / aa : 0.0;
  out.sd_m = n > 0 ? std::sqrt(sum2 / n - (sum / n) * (sum / n)) : 0.0;
  out.missing = static_cast<double>(missing) / all;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  out.median_step_m = steps.empty() ? 0.0 : steps[steps.size() / 2];
  return out;
}

}  // namespace

// The model fitted to real PrimeSense frames (bench sensor on YCB-V) against the published one, on a flat
// square before a wall: its noise smooth (neighbours alike) where the published one's is per pixel, finer
// steps, holes inside, a band beside the edge lost more on the right than on the left, the square's depth
// bled onto some of the wall's pixels beside it; the published one loses exactly the pixel beside it.
TEST(KinectNoise, TheFittedModelHasTheRealSensorsShape) {
  const SquareOnAWall s;
  const DepthImage published = apply_kinect_v1_noise(s.clean, s.k, KinectNoiseConfig{}, 5);
  const DepthImage fitted = apply_kinect_v1_noise(s.clean, s.k, KinectNoiseConfig::fitted(), 5);
  const InsideSquare p = inside_square(s, published, 1), f = inside_square(s, fitted, 1);
  EXPECT_LT(p.correlation, 0.5);
  EXPECT_GT(f.correlation, 0.9);
  EXPECT_GT(inside_square(s, fitted, 8).correlation, 0.3);
  EXPECT_NEAR(p.sd_m, 1.425e-3, 0.5e-3);  // with the 1/8 px steps' own 0.8 mm
  EXPECT_NEAR(f.sd_m, 3.8e-3, 1.2e-3);    // one frame's smooth field: few independent cells
  EXPECT_NEAR(p.median_step_m, 2.87e-3, 0.2e-3);
  EXPECT_NEAR(f.median_step_m, 1.82e-3, 0.2e-3);
  EXPECT_EQ(p.missing, 0.0);
  EXPECT_GT(f.missing, 0.005);
  EXPECT_LT(f.missing, 0.06);
  EXPECT_EQ(s.lost_beside(published, -1, 1), 1.0);
  EXPECT_EQ(s.lost_beside(published, -1, 4), 0.25);  // only the pixel beside the edge
  const double left = s.lost_beside(fitted, -1, 4), right = s.lost_beside(fitted, +1, 4);
  EXPECT_GT(left, 0.25);
  EXPECT_LT(left, 0.6);
  EXPECT_GT(right, left + 0.1) << "the IR projector's shadow falls right of the foreground";
  int bled = 0;
  for (int y = SquareOnAWall::kTop + 10; y < SquareOnAWall::kTop + SquareOnAWall::kSize - 10; ++y)
    bled += std::abs(s.at(fitted, SquareOnAWall::kLeft - 1, y) - 1.0F) < 0.02F ? 1 : 0;
  EXPECT_GT(bled, 20);  // of 180: the bleed's 30 %
  EXPECT_LT(bled, 90);
}

TEST_F(SyntheticDepthTest, NoiseModelShape) {
  const DepthImage clean = render(poses()[1]);
  const DepthImage noisy = apply_kinect_v1_noise(clean, k_, KinectNoiseConfig{}, 7);
  std::size_t clean_n = 0, noisy_n = 0;
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < clean.depth_m.size(); ++i) {
    clean_n += clean.depth_m[i] > 0 ? 1 : 0;
    if (noisy.depth_m[i] > 0) {
      ++noisy_n;
      const double e = noisy.depth_m[i] - clean.depth_m[i];
      sum += e;
      sum2 += e * e;
    }
  }
  ASSERT_GT(noisy_n, 1000U);
  EXPECT_LT(noisy_n, clean_n);  // edges and grazing surfaces are dropped
  EXPECT_GT(noisy_n, clean_n * 7 / 10);
  // At about 1.2 m: sigma_z = 1.425e-3 * 1.2^2 = 2.1 mm, plus quantisation (step b f / d^2 ~ 4 mm / sqrt(12)).
  const double sd = std::sqrt(sum2 / static_cast<double>(noisy_n) - std::pow(sum / static_cast<double>(noisy_n), 2));
  EXPECT_GT(sd, 0.0015);
  EXPECT_LT(sd, 0.0035);
  EXPECT_LT(std::abs(sum / static_cast<double>(noisy_n)), 0.0005);  // unbiased
  const DepthImage none = apply_kinect_v1_noise(clean, k_, KinectNoiseConfig::none(), 7);
  EXPECT_EQ(none.depth_m, clean.depth_m);
}

// The 1.45 m figure of the shop, 2 m away and face-on, half a metre in front of a wall, noise-free.
// Depth alone leaves it nearly free to turn in the image plane: the tracker's own optimum (no pull
// towards its start) lies aside at its feet. The outline's left and right sides hold it nearer.
TEST_F(SyntheticDepthTest, TheOutlineHoldsAFigureSeenFaceOnThatDepthLetsTurn) {
  const auto figure =
      projbot::assets::load_gltf(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "RiggedFigure" / "glTF-Binary" / "RiggedFigure.glb");
  auto wall = projbot::assets::load_gltf(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF" / "BoxTextured.gltf");
  projbot::assets::scale_and_recenter(wall, 3.0, true);
  const ModelCloud cloud = model_cloud_from(figure, 50000);
  const Eigen::Matrix4d T =
      projbot::config::pose_from_xyz_rpy({0.0, 0.7, 2.0}, {193, 0, 0});  // feet 0.7 m below the axis, seen from above
  const std::vector<projbot::engine::DrawItem> items{
      {renderer_->add_model(figure), T},
      {renderer_->add_model(wall), projbot::config::pose_from_xyz_rpy({0.0, 0.0, 4.0}, {0, 0, 0})}};  // its face at 2.5 m
  renderer_->draw_frame(*camera_, as_pinhole(k_), items);
  const auto map = camera_->read_back_depth();
  KinectNoiseConfig drops_only;  // the Kinect's lost pixels at steps and grazing angles, without its noise
  drops_only.sigma_z_coeff = 0.0;
  drops_only.disparity_step_px = 0.0;
  const DepthImage depth = apply_kinect_v1_noise(DepthImage{map.width, map.height, map.z_m, 0.0}, k_, drops_only, 1U);

  const auto settled = [&](double edge_weight, std::size_t& edges) {
    TrackerConfig c;
    c.start_prior = 0.0;  // the tracker's own optimum
    c.edge_weight = edge_weight;
    const ProjectiveTracker tracker(cloud, k_, c);
    Eigen::Matrix4d P = T;
    for (int pass = 0; pass < 10; ++pass) {
      const TrackResult r = tracker.track(depth, P);
      EXPECT_TRUE(r.accepted);
      P = r.T_camera_target;
      edges = r.edge_points;
    }
    return 1000.0 * translation_norm_m(rigid_inverse(T) * P);  // at its feet, mm
  };
  std::size_t edges = 0;
  const double depth_only_mm = settled(0.0, edges);
  EXPECT_EQ(edges, 0U);
  const double outline_mm = settled(1.0, edges);
  std::printf("figure's feet off: depth alone %.2f mm, with the outline %.2f mm (%zu outline points)\n", depth_only_mm,
              outline_mm, edges);
  // Measured: 0.36 mm by depth alone, 0.10 with the outline (in the shop, with its floor and wall and
  // the figure turned, 1.4 and 0.4 mm).
  EXPECT_GT(depth_only_mm, 0.25);
  EXPECT_LT(outline_mm, 0.5 * depth_only_mm);
  EXPECT_GT(edges, 200U);
  TrackerConfig too_far;  // the step search's reach is bounded
  too_far.edge_weight = 1.0;
  too_far.edge_search_px = 33;
  EXPECT_THROW(ProjectiveTracker(cloud, k_, too_far), AlignmentError);
}

TEST_F(SyntheticDepthTest, TrackerFollowsAMovingTarget) {
  // 30 frames, each moving the duck 1 cm and turning it 2 degrees (30 cm/s and 60 deg/s at 30 Hz).
  const projbot::alignment::ProjectiveTracker tracker(*model_, k_);
  Eigen::Matrix4d truth = projbot::config::pose_from_xyz_rpy({-0.05, 0.0, 1.2}, {180, 10, 30});
  Eigen::Matrix4d estimate = truth;
  double worst_mm = 0, worst_deg = 0, total_ms = 0;
  for (int f = 0; f < 30; ++f) {
    Eigen::Matrix4d step = projbot::config::pose_from_xyz_rpy({0.01 * std::cos(f * 0.2), 0.005, 0.003}, {1.0, 0.5, 2.0});
    truth.topLeftCorner<3, 3>() = step.topLeftCorner<3, 3>() * truth.topLeftCorner<3, 3>();
    truth.topRightCorner<3, 1>() += step.topRightCorner<3, 1>();
    const DepthImage frame = apply_kinect_v1_noise(render(truth), k_, KinectNoiseConfig{}, static_cast<std::uint32_t>(f));
    const auto r = tracker.track(frame, estimate);
    ASSERT_TRUE(r.accepted) << "frame " << f << ": inliers " << r.inlier_ratio << " rmse " << r.rmse_mm;
    estimate = r.T_camera_target;
    const Eigen::Matrix4d err = rigid_inverse(truth) * estimate;
    worst_mm = std::max(worst_mm, translation_norm_m(err) * 1000);
    worst_deg = std::max(worst_deg, rotation_angle_deg(err));
    total_ms += r.time_ms;
  }
  std::cout << "tracked 30 frames: worst " << worst_mm << " mm, " << worst_deg << " deg, mean " << total_ms / 30 << " ms\n";
  EXPECT_LT(worst_mm, 3.0);
  EXPECT_LT(worst_deg, 0.5);
}

// The tracker reads the frame in place (no sanitised copy): a driver's invalid pixels, NaN or infinite,
// are missing depth exactly as zeros are.
TEST_F(SyntheticDepthTest, TrackerTreatsNonFiniteDepthAsMissing) {
  const projbot::alignment::ProjectiveTracker tracker(*model_, k_);
  const Eigen::Matrix4d truth = poses()[1];
  DepthImage zeros = apply_kinect_v1_noise(render(truth), k_, KinectNoiseConfig{}, 3U);
  DepthImage invalid = zeros;
  for (std::size_t i = 0; i < zeros.depth_m.size(); i += 3) {  // a third of the pixels, the target's too
    zeros.depth_m[i] = 0.0F;
    invalid.depth_m[i] = (i % 2 == 0) ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  }
  const Eigen::Matrix4d start = projbot::config::pose_from_xyz_rpy({0.01, -0.005, 0.0}, {0, 0, 2}) * truth;
  const auto a = tracker.track(zeros, start), b = tracker.track(invalid, start);
  ASSERT_TRUE(a.accepted);
  ASSERT_TRUE(b.accepted);
  EXPECT_TRUE(b.T_camera_target.allFinite());
  EXPECT_EQ(a.correspondences, b.correspondences);
  EXPECT_LT((a.T_camera_target - b.T_camera_target).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(translation_norm_m(rigid_inverse(truth) * b.T_camera_target) * 1000.0, 2.0);
}

TEST_F(SyntheticDepthTest, TrackerRejectsAFrameWithoutTheTarget) {
  const projbot::alignment::ProjectiveTracker tracker(*model_, k_);
  const Eigen::Matrix4d T = poses()[1];
  DepthImage empty = render(T);
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), 0.0F);
  EXPECT_FALSE(tracker.track(empty, T).accepted);
  // A wall 30 cm behind where the target was: no support for the model.
  std::fill(empty.depth_m.begin(), empty.depth_m.end(), static_cast<float>(T(2, 3) + 0.3));
  EXPECT_FALSE(tracker.track(empty, T).accepted);
  EXPECT_THROW(tracker.track(DepthImage{}, T), AlignmentError);
}
