// A scene's `calibration:` file (A_p, R_cp, T_cp, the lens, the photometry) and the lens model it carries.

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "projbot/config/scene.hpp"

using projbot::config::ConfigError;

// `calibration: calib.yaml` (issue 13's output) gives A_p and R_cp, T_cp in place of the scene's.
class CalibrationFileTest : public ::testing::Test {
 protected:
  void TearDown() override { std::filesystem::remove_all(dir); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir / name) << text; }
  // The error loading a scene that names calib2.yaml holding `calib` gives; empty when it loads.
  std::string error(const std::string& scene, const std::string& calib) {
    write("calib2.yaml", calib);
    write("scene2.yaml", scene + targets);
    try {
      projbot::config::load_scene(dir / "scene2.yaml");
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  const std::filesystem::path dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("projbot_calib_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::string targets = "targets:\n  - {name: a, model: a.glb, pose: {translation: [0, 0, 1.5]}}\n";
  const std::string good_pose = "projector_from_camera: {translation: [0, 0, 0]}\n";
  const std::string intrinsics = "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512, cy: 384}\n";
};

TEST_F(CalibrationFileTest, ItReplacesTheProjectorModel) {
  write("calib.yaml",
        "projector: {width: 1024, height: 768, fx: 1500.5, fy: 1499.5, cx: 511.2, cy: 383.9, distortion: [0, 0, 0, 0, 0]}\n"
        "projector_from_camera: {translation: [0.05, -0.1, 0.02], rpy_deg: [1, 2, 3]}\n"
        "reprojection_rms_px: {camera: 0.21, projector: 0.34}\n");
  write("scene.yaml", "calibration: calib.yaml\nprojector: {near: 0.2, far: 6, refresh_hz: 120}\n" + targets);
  const auto s = projbot::config::load_scene(dir / "scene.yaml");
  EXPECT_EQ(s.projector.width_px, 1024);
  EXPECT_DOUBLE_EQ(s.projector.fx_px, 1500.5);
  EXPECT_DOUBLE_EQ(s.projector.cy_px, 383.9);
  EXPECT_DOUBLE_EQ(s.projector.near_m, 0.2);  // what a calibration does not measure stays the scene's
  EXPECT_DOUBLE_EQ(s.projector.refresh_hz, 120.0);
  EXPECT_NEAR(s.pan_tilt.T_projector_camera(0, 3), 0.05, 1e-12);
  EXPECT_NEAR(s.pan_tilt.T_projector_camera(1, 3), -0.1, 1e-12);
}

TEST_F(CalibrationFileTest, ItMayCarryThePhotometry) {
  // Issue 43: a calibration may carry `photometry:` (calibrate photometric's file, pasted in): its gamma and
  // black level replace the scene's, which may then not give them too; its mixing is checked.
  const std::string photometry =
      "photometry: {gamma: 2.31, gamma_rgb: [2.3, 2.31, 2.32], black_level: 0.001, mixing: [0.94, 0.05, 0.01, 0.04, 0.92, "
      "0.04, 0.01, 0.06, 0.93], camera_gamma: 2.2}\n";
  EXPECT_EQ(error("calibration: calib2.yaml\n", intrinsics + good_pose + photometry), "");
  const auto measured = projbot::config::load_scene(dir / "scene2.yaml");
  EXPECT_DOUBLE_EQ(measured.projector.photometry.gamma, 2.31);
  EXPECT_DOUBLE_EQ(measured.projector.photometry.black_level, 0.001);
  EXPECT_DOUBLE_EQ(measured.projector.photometry.brightness_lm, 3000.0);  // not measured: the scene's
  EXPECT_DOUBLE_EQ(measured.projector.photometry.gamma_rgb[2], 2.32);
  EXPECT_DOUBLE_EQ(measured.projector.photometry.mixing(0, 1), 0.05);
  EXPECT_DOUBLE_EQ(measured.projector.photometry.mixing(2, 1), 0.06);
  EXPECT_NE(error("calibration: calib2.yaml\nprojector: {gamma: 2.2}\n", intrinsics + good_pose + photometry)
                .find("projector.gamma is the calibration's photometry; leave it out of the scene"),
            std::string::npos);
  EXPECT_NE(error("calibration: calib2.yaml\n", intrinsics + good_pose + "photometry: {mixing: [1, 0, 0]}\n")
                .find("photometry.mixing: expected a list of 9 numbers"),
            std::string::npos);
  EXPECT_NE(error("calibration: calib2.yaml\n", intrinsics + good_pose + "photometry: {gamma: 9}\n").find("photometry.gamma"),
            std::string::npos);
}

TEST_F(CalibrationFileTest, ItCarriesTheLensAndIsRefusedNamingWhatIsWrong) {
  // The projector's lens comes with the calibration (the renderer pre-distorts by it); OpenCV's rational
  // terms k4..k6 are accepted only as zeros, and a lens that folds the image over is refused.
  EXPECT_EQ(error("calibration: calib2.yaml\n",
                  "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512, cy: 384, "
                  "distortion: [0.1, -0.05, 0.001, 0, 0.01, 0, 0, 0]}\n" +
                      good_pose),
            "");
  EXPECT_EQ(projbot::config::load_scene(dir / "scene2.yaml").projector.distortion,
            (projbot::config::Distortion{0.1, -0.05, 0.001, 0, 0.01}));
  EXPECT_NE(error("calibration: calib2.yaml\n",
                  "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512, cy: 384, "
                  "distortion: [0.1, 0, 0, 0, 0, 0.2]}\n" +
                      good_pose)
                .find("calib2.yaml:1: projector.distortion: only OpenCV's 5-term lens"),
            std::string::npos);
  EXPECT_NE(error("calibration: calib2.yaml\n",
                  "projector: {width: 1024, height: 768, fx: 500, fy: 500, cx: 512, cy: 384, "
                  "distortion: [-0.5, 0, 0, 0, 0]}\n" +
                      good_pose)
                .find("calib2.yaml:1: projector: distortion folds the image over at panel pixel (0, 0)"),
            std::string::npos);
  EXPECT_NE(
      error("calibration: calib2.yaml\n", "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512}\n" + good_pose)
          .find("calib2.yaml:1: projector.cy: missing required key"),
      std::string::npos);
  EXPECT_NE(error("calibration: calib2.yaml\n", "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512, cy: 384}\n")
                .find("calib2.yaml:1: projector_from_camera: missing required key"),
            std::string::npos);
  EXPECT_NE(error("calibration: calib2.yaml\nprojector: {fx: 900}\n",
                  "projector: {width: 1024, height: 768, fx: 1500, fy: 1500, cx: 512, cy: 384}\n" + good_pose)
                .find("scene2.yaml:1: calibration: projector.fx is the calibration's; leave it out of the scene"),
            std::string::npos);
  EXPECT_NE(error("calibration: none.yaml\n", "").find("scene2.yaml:1: calibration: cannot open"), std::string::npos);
}

// OpenCV's lens model: undistort inverts distort, and the Jacobian is distort's derivative.
TEST(LensTest, UndistortInvertsDistortAndTheJacobianIsItsDerivative) {
  const projbot::config::Distortion k{-0.22, 0.06, 0.002, -0.0015, 0.01};
  for (double x = -0.6; x <= 0.6; x += 0.15)
    for (double y = -0.45; y <= 0.45; y += 0.15) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector2d d = projbot::config::distort(k, p);
      const auto back = projbot::config::undistort(k, d);
      ASSERT_TRUE(back) << p.transpose();
      EXPECT_LT((*back - p).norm(), 1e-10) << p.transpose();
      const double h = 1e-6;
      for (int c = 0; c < 2; ++c) {
        Eigen::Vector2d e = Eigen::Vector2d::Zero();
        e[c] = h;
        const Eigen::Vector2d numeric = (projbot::config::distort(k, p + e) - projbot::config::distort(k, p - e)) / (2 * h);
        EXPECT_LT((projbot::config::distort_jacobian(k, p).col(c) - numeric).norm(), 1e-8);
      }
    }
  // r (1 + k1 r^2) has its largest value 0.54 at r = 0.82 with k1 = -0.5: nothing reaches radius 0.6.
  EXPECT_FALSE(projbot::config::undistort({-0.5, 0, 0, 0, 0}, {0.6, 0.0}));
  // The projector's lens: the panel pixel lighting a point and the ray a panel pixel sends are inverses.
  projbot::config::ProjectorConfig p;
  p.distortion = k;
  const Eigen::Vector3d X(0.31, -0.2, 1.4);
  const Eigen::Vector2d px = p.project_lit(X);
  EXPECT_GT((px - p.project(X)).norm(), 5.0);
  const auto ray = p.panel_ray(px.x(), px.y());
  ASSERT_TRUE(ray);
  EXPECT_LT((*ray * X.z() - X).norm(), 1e-9);
}
