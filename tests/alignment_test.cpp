// Depth input, Eq. 1 / Eq. 2 and acquisition on real data: the Stanford bunny pair from PCL's tests and
// the real Kinect-class frames in ../shared/data/rgbd.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <random>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/scan_alignment.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/scene.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

namespace {

const fs::path kData = PROJBOT_SHARED_DATA;

Eigen::Matrix4d ground_truth_bun0_to_bun4() {
  std::ifstream in(kData / "bunny" / "bun0_to_bun4_groundtruth.txt");
  Eigen::Matrix4d T;
  int n = 0;
  for (std::string line; std::getline(in, line) && n < 16;) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream row(line);
    for (int c = 0; c < 4; ++c) row >> T(n / 4, c);
    n += 4;
  }
  EXPECT_EQ(n, 16);
  return T;
}

Eigen::Matrix4d perturb(const Eigen::Matrix4d& T, double angle_deg, double shift_m, std::mt19937& rng) {
  std::normal_distribution<double> g;
  const Eigen::Vector3d axis = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
  Eigen::Matrix4d D = Eigen::Matrix4d::Identity();
  D.topLeftCorner<3, 3>() = Eigen::AngleAxisd(projbot::config::radians(angle_deg), axis).toRotationMatrix();
  D.topRightCorner<3, 1>() = shift_m * dir;
  return D * T;
}

}  // namespace

TEST(EquationsTest, Eq1MatchesHandComputedCase) {
  // Camera at (1, 2, 0) in the world, looking along world +x (camera z = world x, camera x = world -y,
  // camera y = world -z); target at world (3, 2, 0.5), turned 90 degrees about world z.
  Eigen::Matrix4d T_world_camera = Eigen::Matrix4d::Identity();
  T_world_camera.topLeftCorner<3, 3>() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_world_camera.topRightCorner<3, 1>() << 1, 2, 0;
  const Eigen::Matrix4d T_world_target = projbot::config::pose_from_xyz_rpy({3, 2, 0.5}, {0, 0, 90});
  const Eigen::Matrix4d T = camera_from_target_initial(T_world_camera, T_world_target);
  // The target is 2 m ahead along the optical axis and 0.5 m up (camera -y).
  EXPECT_LT((T.topRightCorner<3, 1>() - Eigen::Vector3d(0, -0.5, 2)).norm(), 1e-12);
  // Its x axis (world +y after the yaw) points to camera -x.
  EXPECT_LT((T.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitX() - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-12);
  // And it agrees with the frame-algebra form inverse(T_world_camera) * T_world_target.
  EXPECT_LT((T - T_world_camera.inverse() * T_world_target).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(EquationsTest, Eq2MatchesHandComputedCase) {
  // Projector 10 cm to the camera's right (camera +x), same orientation: X_p = X_c - (0.1, 0, 0).
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();
  T_projector_camera(0, 3) = -0.1;
  const Eigen::Matrix4d T_camera_target = projbot::config::pose_from_xyz_rpy({0.2, 0, 1.5}, {0, 30, 0});
  const Eigen::Matrix4d T = projector_from_target(T_projector_camera, T_camera_target);
  EXPECT_LT((T.topRightCorner<3, 1>() - Eigen::Vector3d(0.1, 0, 1.5)).norm(), 1e-12);
  EXPECT_LT((T.topLeftCorner<3, 3>() - T_camera_target.topLeftCorner<3, 3>()).cwiseAbs().maxCoeff(), 1e-12);
  // A rotated rig: R_p = R_cp R_c.
  const Eigen::Matrix4d T_pc = projbot::config::pose_from_xyz_rpy({0.05, -0.02, 0.01}, {2, -3, 5});
  EXPECT_LT((projector_from_target(T_pc, T_camera_target) - T_pc * T_camera_target).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((rigid_inverse(T_pc) * T_pc - Eigen::Matrix4d::Identity()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(DepthTest, TumPngBackProjects) {
  const DepthImage d = read_depth_png(kData / "rgbd" / "tum_single_frame" / "TUM_depth.png", 5000.0);
  ASSERT_EQ(d.width, 640);
  ASSERT_EQ(d.height, 480);
  float lo = 1e9F, hi = 0;
  for (float z : d.depth_m)
    if (z > 0) lo = std::min(lo, z), hi = std::max(hi, z);
  EXPECT_NEAR(lo, 7320 / 5000.0, 1e-4);  // the data README's range: 1.46 - 9.33 m
  EXPECT_NEAR(hi, 46655 / 5000.0, 1e-4);
  const PointCloud c = depth_to_cloud(d, CameraIntrinsics::kinect_v1(), 0.3, 8.0);
  EXPECT_TRUE(c.organised());
  std::size_t beyond = 0;
  for (float z : d.depth_m) beyond += z > 8.0F ? 1 : 0;
  EXPECT_GT(beyond, 0U);
  float max_z = 0.0F;  // out-of-range pixels are dropped
  for (const auto& p : c.points) max_z = p.allFinite() ? std::max(max_z, p.z()) : max_z;
  EXPECT_LE(max_z, 8.0F);
  EXPECT_GT(max_z, 7.0F);
}

TEST(DepthTest, GrabberTiffMatchesTheOrganisedPcdReference) {
  const fs::path dir = kData / "rgbd" / "pcl_grabber_sequence";
  const auto cal = read_pcl_grabber_xml(dir / "frame_20121214T142255.814212.xml", 640, 480);
  EXPECT_DOUBLE_EQ(cal.intrinsics.fx_px, 525.0);
  EXPECT_DOUBLE_EQ(cal.intrinsics.cx_px, 320.0);
  EXPECT_DOUBLE_EQ(cal.metres_per_unit, 0.001);
  const DepthImage d = read_depth_tiff(dir / "frame_20121214T142255.814212_depth.tiff", cal.metres_per_unit);
  const PointCloud mine = depth_to_cloud(d, cal.intrinsics, 0.0, 100.0);
  const PointCloud ref = read_cloud(dir / "frame_20121214T142255.814212.pcd");
  ASSERT_EQ(ref.width, 640);
  ASSERT_EQ(ref.height, 480);
  std::size_t both = 0, only_one = 0;
  double worst = 0;
  for (std::size_t i = 0; i < ref.points.size(); ++i) {
    const bool a = mine.points[i].allFinite(), b = ref.points[i].allFinite();
    if (a && b) {
      ++both;
      worst = std::max(worst, static_cast<double>((mine.points[i] - ref.points[i]).norm()));
    } else if (a != b) {
      ++only_one;
    }
  }
  EXPECT_GT(both, 200000U);
  EXPECT_EQ(only_one, 0U);
  EXPECT_LT(worst, 1e-4) << "metres";  // same pixels, same back-projection
}

TEST(DepthTest, BadInputIsNamed) {
  const auto expect_error = [](const auto& call, const std::string& part) {
    try {
      call();
      ADD_FAILURE() << "no error, expected one mentioning " << part;
    } catch (const AlignmentError& e) {
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  expect_error([] { read_depth_png("/nonexistent/d.png", 1000); }, "/nonexistent/d.png");
  expect_error([] { read_depth_png(kData / "rgbd" / "tum_single_frame" / "TUM_color.png", 1000); }, "16-bit single-channel");
  expect_error([] { read_depth_png(kData / "rgbd" / "tum_single_frame" / "TUM_depth.png", 0); }, "depth scale");
  expect_error([] { read_depth_tiff(kData / "rgbd" / "pcl_grabber_sequence" / "frame_20121214T142255.814212_rgb.tiff", 0.001); },
               "16-bit single-channel");
  expect_error([] { read_cloud("/nonexistent/c.pcd"); }, "no such point cloud file");
  expect_error([] { read_cloud(kData / "bunny" / "bun.conf"); }, "unknown point cloud format");
  const fs::path garbage = fs::temp_directory_path() / "projbot_garbage.pcd";
  std::ofstream(garbage) << "# .PCD v0.7\nFIELDS x y z\nnot a cloud\n";
  expect_error([&] { read_cloud(garbage); }, "projbot_garbage.pcd");
  fs::remove(garbage);
  expect_error([] { read_pcl_grabber_xml(kData / "bunny" / "bun0.pcd", 640, 480); }, "not a PCL grabber calibration");
  DepthImage small;
  small.width = 4, small.height = 3, small.depth_m.assign(12, 1.0F);
  expect_error([&] { depth_to_cloud(small, CameraIntrinsics::kinect_v1()); }, "4x3");
}

class BunnyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    AcquisitionConfig cfg;
    cfg.crop = false;  // the scans hold only the bunny
    cfg.voxel_m = 0.003;
    cfg.inlier_distance_m = 0.005;
    cfg.icp_distances_m = {0.05, 0.015, 0.005};
    cfg.min_inlier_ratio = 0.75;  // the scans overlap only in part: 93% of bun4 is explained at the estimate
    cfg.max_rmse_mm = 3.0;
    cfg.feature_radius_m = 0.025;
    cfg_ = cfg;
    aligner_ = std::make_unique<Aligner>(load_model_cloud(kData / "bunny" / "bun0.pcd"), cfg);
    scan_ = read_cloud(kData / "bunny" / "bun4.pcd");
  }
  static void TearDownTestSuite() { aligner_.reset(); }
  static inline AcquisitionConfig cfg_;
  static inline std::unique_ptr<Aligner> aligner_;
  static inline PointCloud scan_;
};

TEST_F(BunnyTest, Bun0OntoBun4FromPerturbedStarts) {
  const Eigen::Matrix4d gt = ground_truth_bun0_to_bun4();
  std::mt19937 rng(42);
  int converged = 0;
  const int trials = 12;
  for (int t = 0; t < trials; ++t) {
    const Eigen::Matrix4d start = perturb(gt, 10.0, 0.02, rng);  // 10 degrees, 2 cm
    const AlignmentResult r = aligner_->align(scan_, start);
    const Eigen::Matrix4d err = rigid_inverse(gt) * r.T_scan_model;
    if (r.converged) ++converged;
    // The ground truth itself is good to about 2 degrees (README); 5 mm on a 15 cm bunny.
    EXPECT_LT(rotation_angle_deg(err), 2.0) << "trial " << t << " inliers " << r.inlier_ratio << " rmse " << r.rmse_mm;
    EXPECT_LT(translation_norm_m(err), 0.005) << "trial " << t;
  }
  EXPECT_EQ(converged, trials);
  const AlignmentResult at_gt = aligner_->score(scan_, gt);
  const AlignmentResult ours = aligner_->align(scan_, gt);
  std::cout << "at the reference pose: inliers " << at_gt.inlier_ratio << ", rmse " << at_gt.rmse_mm << " mm; estimate: inliers "
            << ours.inlier_ratio << ", rmse " << ours.rmse_mm << " mm, "
            << rotation_angle_deg(rigid_inverse(gt) * ours.T_scan_model) << " deg from it\n";
}

// The acquisition's own searches (a k-d tree queried without OpenMP, the outlier filter written out)
// give PCL's answers: the same neighbours, so the same filtered points, normals, correspondences and
// gate, pose for pose, from starts ICP settles from and from one it does not.
TEST_F(BunnyTest, OurSearchesGiveThePclAnswers) {
  AcquisitionConfig stock = cfg_;
  stock.pcl_search = true;
  const Aligner pcl(load_model_cloud(kData / "bunny" / "bun0.pcd"), stock);
  const Eigen::Matrix4d gt = ground_truth_bun0_to_bun4();
  std::mt19937 rng(7);
  for (const double deg : {5.0, 10.0, 35.0}) {
    const Eigen::Matrix4d start = perturb(gt, deg, 0.02, rng);
    const AlignmentResult a = aligner_->align(scan_, start, SearchStage::icp_only);
    const AlignmentResult b = pcl.align(scan_, start, SearchStage::icp_only);
    // Element by element: the angle of a pose composed with its own inverse is not 0 when ICP's pose is
    // single precision (its rotation is orthonormal to 1e-7, which acos makes 0.02 degrees).
    EXPECT_LT((a.T_scan_model - b.T_scan_model).cwiseAbs().maxCoeff(), 1e-9) << deg << " degrees";
    EXPECT_EQ(a.iterations, b.iterations) << deg << " degrees";
    EXPECT_EQ(a.scan_points, b.scan_points) << deg << " degrees";
    EXPECT_NEAR(a.inlier_ratio, b.inlier_ratio, 1e-9) << deg << " degrees";
    EXPECT_EQ(a.converged, b.converged) << deg << " degrees";
    EXPECT_GT(a.scan_points, 300u);
  }
}

TEST_F(BunnyTest, ReinitialisationRecoversFromAWrongYaw) {
  const Eigen::Matrix4d gt = ground_truth_bun0_to_bun4();
  Eigen::Matrix4d start = gt;
  start.topLeftCorner<3, 3>() =
      Eigen::AngleAxisd(M_PI * 0.8, Eigen::Vector3d::UnitY()).toRotationMatrix() * gt.topLeftCorner<3, 3>();
  const AlignmentResult r = aligner_->align(scan_, start);  // restarts, then FPFH, as needed
  EXPECT_TRUE(r.converged);
  EXPECT_LT(rotation_angle_deg(rigid_inverse(gt) * r.T_scan_model), 2.0);
  // The global re-initialisation alone (no local restarts) recovers too.
  AcquisitionConfig global_only = cfg_;
  global_only.restart_angle_deg = 0.0;
  const Aligner fpfh(load_model_cloud(kData / "bunny" / "bun0.pcd"), global_only);
  const AlignmentResult g = fpfh.align(scan_, start);
  EXPECT_TRUE(g.converged);
  EXPECT_TRUE(g.reinitialised);
  EXPECT_LT(rotation_angle_deg(rigid_inverse(gt) * g.T_scan_model), 2.0);
}

TEST_F(BunnyTest, BadScansAreErrors) {
  PointCloud nan_cloud;
  nan_cloud.points.assign(500, Eigen::Vector3f::Constant(std::nanf("")));
  nan_cloud.width = 500, nan_cloud.height = 1;
  EXPECT_THROW(aligner_->align(nan_cloud, Eigen::Matrix4d::Identity()), AlignmentError);
  EXPECT_THROW(aligner_->align(PointCloud{}, Eigen::Matrix4d::Identity()), AlignmentError);
  PointCloud few;
  few.points.assign(5, Eigen::Vector3f::Ones());
  EXPECT_THROW(aligner_->align(few, Eigen::Matrix4d::Identity()), AlignmentError);
  Eigen::Matrix4d bad = Eigen::Matrix4d::Identity();
  bad(0, 3) = std::nan("");
  EXPECT_THROW(aligner_->align(scan_, bad), AlignmentError);
  EXPECT_THROW(Aligner(ModelCloud{}), AlignmentError);
}

// A scan from a file: a depth image's camera must fit it (the Kinect's defaults only a 640x480 image; given
// intrinsics must put the principal point inside), and the image is back-projected through it.
TEST(LoadScan, ADepthImagesCameraMustFitIt) {
  const fs::path png = fs::path(PROJBOT_SOURCE_DIR) / "tests" / "fuzz" / "corpus" / "depth_png" / "gray16_4x3.png";
  try {
    load_scan(png, 1000.0, std::nullopt);
    ADD_FAILURE() << "a 4x3 image taken with the Kinect's 640x480 intrinsics";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("640x480"), std::string::npos) << e.what();
  }
  CameraIntrinsics k{4, 3, 5.0, 5.0, 10.0, 1.0};
  EXPECT_THROW(load_scan(png, 1000.0, k), AlignmentError);  // cx 10 outside a 4 pixel wide image
  k.cx_px = 1.5;
  const Scan scan = load_scan(png, 1000.0, k);
  ASSERT_TRUE(scan.depth.has_value());
  EXPECT_EQ(scan.k.width_px, 4);
  EXPECT_EQ(scan.cloud.points.size(), 12U);
  EXPECT_TRUE(is_cloud_file("a.PLY"));
  EXPECT_TRUE(is_depth_image_file("a.TIFF"));
  EXPECT_FALSE(is_depth_image_file("a.jpg"));
}
