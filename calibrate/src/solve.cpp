// `solve`: corners in the camera (the mean of the pattern images), their projector positions through the
// decoded Gray code, then OpenCV's calibrateCamera for each device and stereoCalibrate for R_cp, T_cp.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "capture_io.hpp"
#include "projbot/calibrate/procam.hpp"
#include "projbot/config/angles.hpp"
#include "solve_views.hpp"

namespace projbot::calibrate {

// One view: its corners found in `lit` and mapped into the projector. Appended to `points` when used.
ViewResult measure_view(const CaptureManifest& m, const cv::Mat& lit, const std::vector<cv::Mat>& images, const SolveOptions& o,
                        Correspondences& points) {
  ViewResult r;
  const BoardView board = detect_board(m.board, lit);
  r.corners = static_cast<int>(board.image.size());
  if (r.corners < o.min_corners) {
    r.refused =
        r.corners == 0 ? "no board found in the white image" : "only " + std::to_string(r.corners) + " board corners found";
    return r;
  }
  const cv::Mat decoded = decode_gray_code(images, m.projector_width, m.projector_height);
  std::vector<cv::Point3f> shared_object;
  std::vector<cv::Point2f> shared_camera, projector;
  for (std::size_t k = 0; k < board.image.size(); ++k)
    if (const auto p = corner_to_projector(decoded, board.image[k])) {
      shared_object.push_back(board.object[k]);
      shared_camera.push_back(board.image[k]);
      projector.emplace_back(static_cast<float>(p->x), static_cast<float>(p->y));
    }
  r.projector_corners = static_cast<int>(projector.size());
  if (r.projector_corners < o.min_corners) {
    r.refused = "only " + std::to_string(r.projector_corners) + " of " + std::to_string(r.corners) +
                " corners lit by decodable patterns (is the board inside the projector's image?)";
    return r;
  }
  points.object.push_back(board.object);
  points.camera.push_back(board.image);
  points.shared_object.push_back(std::move(shared_object));
  points.shared_camera.push_back(std::move(shared_camera));
  points.projector.push_back(std::move(projector));
  return r;
}

namespace {

Camera lens_from(const cv::Mat& K, const cv::Mat& D, cv::Size size) {
  Camera l;
  static_cast<config::Pinhole&>(l) =
      config::Pinhole{size.width, size.height, K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2)};
  for (int i = 0; i < 5 && i < static_cast<int>(D.total()); ++i) l.distortion[static_cast<std::size_t>(i)] = D.at<double>(i);
  return l;
}

double coverage(const std::vector<std::vector<cv::Point2f>>& projector, cv::Size size) {
  std::vector<cv::Point2f> all, hull;
  for (const auto& v : projector) all.insert(all.end(), v.begin(), v.end());
  if (all.size() < 3) return 0.0;
  cv::convexHull(all, hull);
  return cv::contourArea(hull) / (static_cast<double>(size.width) * size.height);
}

void add_warnings(Calibration& c, int used, int total) {
  auto fixed = [](double v, int digits) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(digits);
    s << v;
    return s.str();
  };
  if (used < 8)
    c.warnings.push_back("only " + std::to_string(used) + " usable views: take 8 or more for a calibration you can trust");
  if (used < total)
    c.warnings.push_back(std::to_string(total - used) + " of " + std::to_string(total) + " views refused (see views)");
  if (c.projector_coverage < 0.3)
    c.warnings.push_back("the corners covered " + fixed(100.0 * c.projector_coverage, 0) +
                         " % of the projector's image: hold the board near its edges and corners too");
  if (c.projector_rms_px > 0.5)
    c.warnings.push_back("projector reprojection RMS " + fixed(c.projector_rms_px, 2) + " px is high (> 0.5)");
  if (c.camera_rms_px > 0.3) c.warnings.push_back("camera reprojection RMS " + fixed(c.camera_rms_px, 2) + " px is high (> 0.3)");
}

// Both devices' intrinsics and R_cp, T_cp from the used views; per-view and total RMS into `c`.
void calibrate_devices(const Correspondences& p, cv::Size camera_size, cv::Size projector_size, bool projector_distortion,
                       Calibration& c) {
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12);
  cv::Mat Kc, Dc, Kp, Dp;
  std::vector<cv::Mat> rv, tv;
  cv::calibrateCamera(p.object, p.camera, camera_size, Kc, Dc, rv, tv, cv::CALIB_FIX_K3, criteria);
  const int projector_flags =
      cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3 | (projector_distortion ? 0 : cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2);
  cv::calibrateCamera(p.shared_object, p.projector, projector_size, Kp, Dp, rv, tv, projector_flags, criteria);
  // The camera's lens is fixed from its own calibration, its corners undistorted to ideal pixels, so the
  // joint fit refines both focal lengths and principal points (and the projector's k1, k2 when fitted)
  // with the board poses shared. The flags are both devices': the camera's ideal corners keep its k1, k2
  // near zero.
  std::vector<std::vector<cv::Point2f>> ideal(p.shared_camera.size());
  for (std::size_t i = 0; i < ideal.size(); ++i) cv::undistortPoints(p.shared_camera[i], ideal[i], Kc, Dc, cv::noArray(), Kc);
  const int joint = cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_ZERO_TANGENT_DIST | cv::CALIB_FIX_K3 |
                    (projector_distortion ? 0 : cv::CALIB_FIX_K1 | cv::CALIB_FIX_K2);
  cv::Mat no_lens = cv::Mat::zeros(5, 1, CV_64F);
  cv::Mat R, T, E, F, per_view;
  cv::stereoCalibrate(p.shared_object, ideal, p.projector, Kc, no_lens, Kp, Dp, camera_size, R, T, E, F, per_view, joint,
                      criteria);
  c.camera = lens_from(Kc, Dc, camera_size);
  c.projector = lens_from(Kp, Dp, projector_size);
  c.T_projector_camera = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c.T_projector_camera(r, k) = R.at<double>(r, k);
    c.T_projector_camera(r, 3) = T.at<double>(r);
  }
  double sum_c = 0.0, sum_p = 0.0, n = 0.0;
  std::size_t u = 0;
  for (ViewResult& v : c.views) {
    if (!v.refused.empty()) continue;
    v.camera_rms_px = per_view.at<double>(static_cast<int>(u), 0);
    v.projector_rms_px = per_view.at<double>(static_cast<int>(u), 1);
    const double count = static_cast<double>(p.projector[u].size());
    sum_c += count * v.camera_rms_px * v.camera_rms_px;
    sum_p += count * v.projector_rms_px * v.projector_rms_px;
    n += count;
    ++u;
  }
  c.camera_rms_px = std::sqrt(sum_c / n);
  c.projector_rms_px = std::sqrt(sum_p / n);
}

}  // namespace

Calibration solve(const std::filesystem::path& dir, const SolveOptions& o,
                  const std::function<void(int, int, const ViewResult&)>& progress) {
  const CaptureManifest m = read_manifest(dir, o);
  const auto expected = static_cast<std::size_t>(images_per_pose(m.projector_width, m.projector_height));
  const cv::Size projector_size(m.projector_width, m.projector_height);
  Calibration c;
  c.notes = m.notes;
  c.board_square_m = m.board.square_m;
  cv::Size camera_size;
  Correspondences used;
  for (std::size_t i = 0; i < m.folders.size(); ++i) {
    const std::vector<cv::Mat> images = read_pose(dir / m.folders[i], expected);
    if (i == 0) camera_size = images.front().size();
    if (images.front().size() != camera_size)
      throw CalibrationError("'" + (dir / m.folders[i]).string() + "': its images are " + std::to_string(images.front().cols) +
                             "x" + std::to_string(images.front().rows) + ", the first pose's " +
                             std::to_string(camera_size.width) + "x" + std::to_string(camera_size.height));
    ViewResult r = measure_view(m, lit_image(images), images, o, used);
    r.folder = m.folders[i];
    c.views.push_back(r);
    if (progress) progress(static_cast<int>(i + 1), static_cast<int>(m.folders.size()), r);
  }
  if (used.projector.size() < 3) {
    std::string why;
    for (const ViewResult& v : c.views)
      if (!v.refused.empty()) why += "; " + v.folder + ": " + v.refused;
    throw CalibrationError("'" + dir.string() + "': " + std::to_string(used.projector.size()) + " usable views of " +
                           std::to_string(m.folders.size()) + ", 3 is the least a calibration needs" + why);
  }
  calibrate_devices(used, camera_size, projector_size, o.projector_distortion, c);
  c.projector_coverage = coverage(used.projector, projector_size);
  add_warnings(c, static_cast<int>(used.projector.size()), static_cast<int>(c.views.size()));
  return c;
}

namespace {

// How far apart two lenses put the same ray on the panel, at most over the image (in the truth's pixels).
double lens_difference_px(const Camera& fit, const Camera& truth) {
  const config::Pinhole& k = truth;
  double worst = 0.0;
  for (int j = 0; j <= 20; ++j)
    for (int i = 0; i <= 20; ++i) {
      const Eigen::Vector2d x = k.back_project(k.width_px * i / 20.0, k.height_px * j / 20.0, 1.0).head<2>();
      const Eigen::Vector2d d = config::distort(fit.distortion, x) - config::distort(truth.distortion, x);
      worst = std::max(worst, std::hypot(k.fx_px * d.x(), k.fy_px * d.y()));
    }
  return worst;
}

}  // namespace

TruthComparison compare(const Calibration& c, const Calibration& t) {
  const auto pct = [](double a, double b) { return 100.0 * std::abs(a - b) / b; };
  const config::Pinhole& p = c.projector;
  const config::Pinhole& q = t.projector;
  const config::Pinhole& k = c.camera;
  const config::Pinhole& l = t.camera;
  TruthComparison r;
  r.projector_fx_pct = pct(p.fx_px, q.fx_px);
  r.projector_fy_pct = pct(p.fy_px, q.fy_px);
  r.projector_principal_px = std::hypot(p.cx_px - q.cx_px, p.cy_px - q.cy_px);
  r.camera_fx_pct = pct(k.fx_px, l.fx_px);
  r.camera_fy_pct = pct(k.fy_px, l.fy_px);
  r.camera_principal_px = std::hypot(k.cx_px - l.cx_px, k.cy_px - l.cy_px);
  const Eigen::Matrix3d dR = c.T_projector_camera.block<3, 3>(0, 0) * t.T_projector_camera.block<3, 3>(0, 0).transpose();
  r.rotation_deg = config::degrees(std::acos(std::clamp((dR.trace() - 1.0) / 2.0, -1.0, 1.0)));
  r.translation_mm = 1000.0 * (c.T_projector_camera.block<3, 1>(0, 3) - t.T_projector_camera.block<3, 1>(0, 3)).norm();
  r.projector_lens = config::has_distortion(c.projector.distortion) || config::has_distortion(t.projector.distortion);
  if (r.projector_lens) r.projector_lens_px = lens_difference_px(c.projector, t.projector);
  return r;
}

}  // namespace projbot::calibrate
