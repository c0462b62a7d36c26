// The twin's calibration session: a board held in front of the camera and projector, the Gray-code
// patterns falling on it, the colour camera's images. Ray-cast per camera sample (4 x 4 per pixel)
// against two planes, the board's paper and a wall behind it.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <random>

#include "capture_io.hpp"
#include "projbot/calibrate/capture.hpp"
#include "projbot/calibrate/procam.hpp"
#include "projbot/config/angles.hpp"

namespace projbot::calibrate {
namespace {

constexpr double kWallZ = 2.5;         // a wall facing the camera behind the board, metres
constexpr double kPaperMargin = 0.03;  // white paper around the printed squares, metres
constexpr double kPixelsPerM = 2500.0;
constexpr int kSub = 4;  // samples per pixel along each axis: a pixel integrates its area (2 x 2 left edges aliased)

cv::Matx33d camera_matrix(const config::Pinhole& p) { return {p.fx_px, 0, p.cx_px, 0, p.fy_px, p.cy_px, 0, 0, 1}; }

// The undistorted viewing ray (x, y, 1) of each camera sample, kSub x kSub per pixel, row-major. Undistorting
// them all takes seconds: done in bands of rows, asking `stop` between them (empty when it said stop).
std::vector<cv::Point2d> sample_rays(const Camera& camera, const std::function<bool()>& stop) {
  constexpr int kBandRows = 16;
  const int w = camera.width_px, h = camera.height_px;
  std::vector<cv::Point2d> rays;
  rays.reserve(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * kSub * kSub);
  for (int y0 = 0; y0 < h; y0 += kBandRows) {
    if (stop && stop()) return {};
    std::vector<cv::Point2d> pixels, band;
    for (int y = y0; y < std::min(h, y0 + kBandRows); ++y)
      for (int x = 0; x < w; ++x)
        for (int sy = 0; sy < kSub; ++sy)
          for (int sx = 0; sx < kSub; ++sx) pixels.emplace_back(x + (sx + 0.5) / kSub - 0.5, y + (sy + 0.5) / kSub - 0.5);
    cv::undistortPoints(pixels, band, camera_matrix(camera), cv::Mat(camera.distortion), cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-12));
    rays.insert(rays.end(), band.begin(), band.end());
  }
  return rays;
}

struct Sample {
  float albedo = 0.0f;
  float falloff = 0.0f;               // projector irradiance at full white, relative to head-on at 1 m
  std::int32_t projector_index = -1;  // pixel of the projector lighting it, -1 none
};

struct Geometry {
  BoardImage board;
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  // board frame as a camera sees its front face-on
  Eigen::Vector2d centre;                            // the squares' centre, board frame
  Eigen::Vector2d paper_min, paper_max;              // the paper, in drawing pixels
};

Geometry board_geometry(const Board& board) {
  Geometry g;
  g.board = draw_board(board, kPixelsPerM);
  const cv::Matx23d& A = g.board.board_to_pixel;
  // OpenCV's board frame may have y up (origin bottom left): then the printed face is seen with z
  // toward the camera, a half turn about x.
  if (A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0) < 0.0) g.R0 = Eigen::Vector3d(1, -1, -1).asDiagonal();
  Eigen::Matrix2d L;
  L << A(0, 0), A(0, 1), A(1, 0), A(1, 1);
  const Eigen::Vector2d mid((g.board.image.cols - 1) / 2.0, (g.board.image.rows - 1) / 2.0);
  g.centre = L.inverse() * (mid - Eigen::Vector2d(A(0, 2), A(1, 2)));
  const double m = kPaperMargin * kPixelsPerM;
  g.paper_min = Eigen::Vector2d(-0.5 - m, -0.5 - m);
  g.paper_max = Eigen::Vector2d(g.board.image.cols - 0.5 + m, g.board.image.rows - 0.5 + m);
  return g;
}

// The drawing's reflectance at drawing pixel position p: bilinear, printed black 0.05, paper 0.85.
float board_albedo(const Geometry& g, const Eigen::Vector2d& p) {
  const cv::Mat& img = g.board.image;
  const double x = std::clamp(p.x(), 0.0, img.cols - 1.0), y = std::clamp(p.y(), 0.0, img.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), img.cols - 2), y0 = std::min(static_cast<int>(y), img.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const double v = (1 - fy) * ((1 - fx) * img.at<uchar>(y0, x0) + fx * img.at<uchar>(y0, x0 + 1)) +
                   fy * ((1 - fx) * img.at<uchar>(y0 + 1, x0) + fx * img.at<uchar>(y0 + 1, x0 + 1));
  return static_cast<float>(0.05 + 0.80 * v / 255.0);
}

// Where the segment from `from` along `dir` (scaled: 0 < s < max_s) meets the board's paper, in
// drawing pixels; empty when it does not.
std::optional<Eigen::Vector2d> hit_paper(const Geometry& g, const Eigen::Matrix4d& T_camera_board, const Eigen::Vector3d& from,
                                         const Eigen::Vector3d& dir, double max_s, double& s_hit) {
  const Eigen::Matrix3d R = T_camera_board.block<3, 3>(0, 0);
  const Eigen::Vector3d t = T_camera_board.block<3, 1>(0, 3), n = R.col(2);
  const double along = n.dot(dir);
  if (std::abs(along) < 1e-12) return std::nullopt;
  s_hit = n.dot(t - from) / along;
  if (!(s_hit > 1e-9 && s_hit < max_s)) return std::nullopt;
  const Eigen::Vector3d b = R.transpose() * (from + dir * s_hit - t);
  const cv::Matx23d& A = g.board.board_to_pixel;
  const Eigen::Vector2d px(A(0, 0) * b.x() + A(0, 1) * b.y() + A(0, 2), A(1, 0) * b.x() + A(1, 1) * b.y() + A(1, 2));
  if (!((px.array() >= g.paper_min.array()).all() && (px.array() <= g.paper_max.array()).all())) return std::nullopt;
  return px;
}

std::vector<Sample> trace(const SimulationConfig& c, const Geometry& g, const std::vector<cv::Point2d>& rays,
                          const Eigen::Matrix4d& T_camera_board) {
  const Eigen::Vector3d n = T_camera_board.block<3, 1>(0, 2);
  const Eigen::Matrix3d R_pc = c.T_projector_camera.block<3, 3>(0, 0);
  const Eigen::Vector3d t_pc = c.T_projector_camera.block<3, 1>(0, 3);
  const Eigen::Vector3d projector_centre = R_pc.transpose() * (-t_pc);
  std::vector<Sample> out(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d d(rays[i].x, rays[i].y, 1.0);
    Sample& s = out[i];
    Eigen::Vector3d P = d * kWallZ, normal(0, 0, -1);
    s.albedo = 0.5f;
    double s_board = 0.0;
    bool on_board = false;
    if (const auto px = hit_paper(g, T_camera_board, Eigen::Vector3d::Zero(), d, kWallZ, s_board)) {
      P = d * s_board;
      normal = n;
      on_board = true;
      const bool printed =
          px->x() >= -0.5 && px->y() >= -0.5 && px->x() <= g.board.image.cols - 0.5 && px->y() <= g.board.image.rows - 0.5;
      s.albedo = printed ? board_albedo(g, *px) : 0.85f;
    }
    const Eigen::Vector3d Pp = R_pc * P + t_pc;
    if (Pp.z() <= 0.0) continue;
    const Eigen::Vector2d x = c.projector.project_lit(Pp);  // through the projector's lens
    const int u = static_cast<int>(std::lround(x.x())), v = static_cast<int>(std::lround(x.y()));
    if (u < 0 || v < 0 || u >= c.projector.width_px || v >= c.projector.height_px) continue;
    double s_shadow = 0.0;  // the board's shadow on the wall: the light to this point passes through the paper
    if (!on_board && hit_paper(g, T_camera_board, P, projector_centre - P, 1.0, s_shadow)) continue;
    const Eigen::Vector3d to_projector = (projector_centre - P).normalized();
    s.falloff = static_cast<float>(std::abs(normal.dot(to_projector)) / Pp.squaredNorm());
    s.projector_index = v * c.projector.width_px + u;
  }
  return out;
}

// One camera image of one projected pattern: samples averaged per pixel, optical blur, noise, 8 bits.
cv::Mat expose(const SimulationConfig& c, const std::vector<Sample>& samples, const cv::Mat& pattern, std::mt19937_64& rng) {
  const int w = c.camera.width_px, h = c.camera.height_px;
  cv::Mat radiance(h, w, CV_32F);
  const uchar* light = pattern.ptr<uchar>(0);
  const float ambient = static_cast<float>(c.ambient), direct = 1.0f - ambient;
  for (int y = 0; y < h; ++y) {
    float* row = radiance.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      float sum = 0.0f;
      for (int k = 0; k < kSub * kSub; ++k) {
        const Sample& s = samples[static_cast<std::size_t>((y * w + x) * kSub * kSub + k)];
        const float lit = s.projector_index < 0 ? 0.0f : light[s.projector_index] / 255.0f;
        sum += s.albedo * (ambient + direct * s.falloff * lit);
      }
      row[x] = 255.0f * sum / (kSub * kSub);
    }
  }
  if (c.blur_sigma_px > 0.0) cv::GaussianBlur(radiance, radiance, cv::Size(0, 0), c.blur_sigma_px);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(c.noise_sigma));
  cv::Mat out(h, w, CV_8U);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      out.at<uchar>(y, x) = cv::saturate_cast<uchar>(radiance.at<float>(y, x) + (c.noise_sigma > 0.0 ? noise(rng) : 0.0f));
  return out;
}

Eigen::Matrix3d tilt(double rx_deg, double ry_deg, double rz_deg) {
  const double k = config::radians(1.0);
  return (Eigen::AngleAxisd(rx_deg * k, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(ry_deg * k, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rz_deg * k, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

// Whether the whole paper is on the camera's image and the whole printed board in the projector's.
bool pose_fits(const SimulationConfig& c, const Geometry& g, const Eigen::Matrix4d& T_camera_board) {
  const cv::Matx23d& A = g.board.board_to_pixel;
  Eigen::Matrix2d L;
  L << A(0, 0), A(0, 1), A(1, 0), A(1, 1);
  const Eigen::Matrix2d Li = L.inverse();
  const Eigen::Vector2d o(A(0, 2), A(1, 2));
  const Eigen::Vector2d pmin = g.paper_min, pmax = g.paper_max;
  const Eigen::Vector2d smin(-0.5, -0.5), smax(g.board.image.cols - 0.5, g.board.image.rows - 0.5);
  for (int k = 0; k < 4; ++k) {
    for (const bool paper : {true, false}) {
      const Eigen::Vector2d lo = paper ? pmin : smin, hi = paper ? pmax : smax;
      const Eigen::Vector2d px((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y());
      const Eigen::Vector2d b = Li * (px - o);
      const Eigen::Vector3d P = (T_camera_board * Eigen::Vector4d(b.x(), b.y(), 0, 1)).head<3>();
      if (P.z() <= 0.2) return false;
      if (paper) {
        std::vector<cv::Point3d> in{{P.x(), P.y(), P.z()}};
        std::vector<cv::Point2d> out;
        cv::projectPoints(in, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(c.camera), cv::Mat(c.camera.distortion), out);
        if (out[0].x < 4 || out[0].y < 4 || out[0].x > c.camera.width_px - 5 || out[0].y > c.camera.height_px - 5) return false;
      } else {
        const Eigen::Vector3d Pp = (c.T_projector_camera * P.homogeneous()).head<3>();
        if (Pp.z() <= 0.2 || !c.projector.contains(c.projector.project_lit(Pp))) return false;
      }
    }
  }
  return true;
}

}  // namespace

// A scripted board's squares must be at least this big in the camera (the default poses' are 24-40).
constexpr int kMinSquarePx = 8;

// Pose i of n: the board's centre over a 3 x 3 spread of the projector's image at 0.8-1.3 m, tilted
// up to 30 degrees about varied axes; pulled nearer face-on and further away until it fits both views.
// A scripted pose that does not fit is refused by its number, unless `as_held` (the capture session's
// twin: a person may hold the board badly, and the session refuses the pose on the spot).
static std::vector<Eigen::Matrix4d> board_poses(const SimulationConfig& c, const Geometry& g, bool as_held = false) {
  static constexpr double kSpread[9][2] = {{0, 0}, {-1, -1}, {1, 1}, {1, -1}, {-1, 1}, {0, -1}, {0, 1}, {-1, 0}, {1, 0}};
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  std::vector<Eigen::Matrix4d> poses;
  for (std::size_t i = 0; i < c.scripted.size(); ++i) {
    const BoardPose& p = c.scripted[i];
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.block<3, 3>(0, 0) = tilt(p.tilt_deg.x(), p.tilt_deg.y(), p.tilt_deg.z()) * g.R0;
    T.block<3, 1>(0, 3) = p.centre_m - T.block<3, 3>(0, 0) * Eigen::Vector3d(g.centre.x(), g.centre.y(), 0.0);
    const std::string which = "board pose " + std::to_string(i + 1) + " of " + std::to_string(c.scripted.size());
    // So far away that it shrinks to a point still "fits" the views: its squares must be seen.
    const double square_px = c.camera.fx_px * c.board.square_m / p.centre_m.z();
    if (!(square_px >= kMinSquarePx)) {
      char said[160];
      std::snprintf(said, sizeof said,
                    ": at %.3g m the board's squares would be %.2g pixels in the camera (at least %d are needed)", p.centre_m.z(),
                    square_px, kMinSquarePx);
      throw CalibrationError(which + said);
    }
    if (!as_held && !pose_fits(c, g, T))
      throw CalibrationError(which + ": the board " + c.board.spec() +
                             " is not wholly inside both the camera's and the projector's views");
    poses.push_back(T);
  }
  if (!c.scripted.empty()) return poses;
  for (int i = 0; i < c.poses; ++i) {
    const double* s = kSpread[i % 9];
    double z = 0.8 + 0.5 * ((i * 7) % 10) / 9.0;
    double scale = 1.0;
    const double rx = 30.0 * std::sin(i * 2.1 + 0.3) + 3.0 * jitter(rng), ry = 30.0 * std::cos(i * 1.7) + 3.0 * jitter(rng),
                 rz = 12.0 * std::sin(i * 0.9) + 3.0 * jitter(rng);
    const double ox = 0.25 * s[0] + 0.03 * jitter(rng), oy = 0.25 * s[1] + 0.03 * jitter(rng);
    bool fits = false;
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    for (int attempt = 0; attempt < 40 && !fits; ++attempt) {
      const config::Pinhole& p = c.projector;
      const Eigen::Vector3d centre_p = p.back_project(p.cx_px + ox * scale * p.width_px, p.cy_px + oy * scale * p.height_px, z);
      const Eigen::Vector3d centre_c = (c.T_projector_camera.inverse() * centre_p.homogeneous()).head<3>();
      const Eigen::Matrix3d R = tilt(rx * scale, ry * scale, rz * scale) * g.R0;
      T.block<3, 3>(0, 0) = R;
      T.block<3, 1>(0, 3) = centre_c - R * Eigen::Vector3d(g.centre.x(), g.centre.y(), 0.0);
      fits = pose_fits(c, g, T);
      if (!fits) {
        scale *= 0.9;
        z += 0.03;
      }
    }
    if (!fits)
      throw CalibrationError("simulate: the board " + c.board.spec() +
                             " does not fit the camera's and the projector's views together; use a smaller board");
    poses.push_back(T);
  }
  return poses;
}

int simulate(const SimulationConfig& c, const std::filesystem::path& out, const std::function<void(int, int)>& progress,
             const std::function<bool()>& stop) {
  if (c.scripted.empty() && (c.poses < 1 || c.poses > 100)) throw CalibrationError("simulate: poses must be 1..100");
  if (c.scripted.size() > 100) throw CalibrationError("simulate: at most 100 board poses");
  const Geometry g = board_geometry(c.board);
  const std::vector<Eigen::Matrix4d> poses = board_poses(c, g);
  const int count = static_cast<int>(poses.size());
  const std::vector<cv::Mat> patterns = gray_code_images(c.projector.width_px, c.projector.height_px);
  const std::vector<cv::Point2d> rays = sample_rays(c.camera, stop);
  if (stop && stop()) return 0;
  CaptureWriter writer(out);
  CaptureManifest manifest{c.projector.width_px, c.projector.height_px, c.board, {}, {}};
  for (int i = 0; i < count && !(stop && stop()); ++i) {
    const std::vector<Sample> samples = trace(c, g, rays, poses[static_cast<std::size_t>(i)]);
    std::mt19937_64 rng(c.seed * 1000003u + static_cast<std::uint64_t>(i));
    std::vector<cv::Mat> images;
    for (const cv::Mat& pattern : patterns) {
      if (stop && stop()) break;  // a pose takes a second or two: one half exposed is dropped
      images.push_back(expose(c, samples, pattern, rng));
    }
    if (images.size() < patterns.size()) break;
    manifest.folders.push_back(writer.write_pose(i, images));
    if (progress) progress(i + 1, count);
  }
  const int written = static_cast<int>(manifest.folders.size());
  if (written == 0) return 0;  // stopped before the first pose: the writer removes its folder
  Calibration truth;
  truth.camera = c.camera;
  truth.projector = Camera{c.projector};
  truth.T_projector_camera = c.T_projector_camera;
  truth.T_camera_board.assign(poses.begin(), poses.begin() + written);
  writer.finish(manifest, truth);
  return written;
}

namespace {

class TwinRig final : public CaptureRig {
 public:
  TwinRig(const SimulationConfig& c, PatternDisplay display)
      : c_(c),
        g_(board_geometry(c.board)),
        poses_(board_poses(c, g_, true)),
        rays_(sample_rays(c.camera, nullptr)),
        display_(std::move(display)) {}

  bool ready(int, int) override {
    if (next_ >= poses_.size()) return false;
    current_ = next_++;
    samples_ = trace(c_, g_, rays_, poses_[current_]);
    rng_.seed(c_.seed * 1000003u + current_);
    return true;
  }
  cv::Mat show_and_capture(std::size_t index, const cv::Mat& pattern) override {
    if (samples_.empty()) throw CalibrationError("twin rig: a pattern shown before the board was held");
    const cv::Mat shown = display_ ? display_(index, pattern) : pattern;
    if (shown.size() != cv::Size(c_.projector.width_px, c_.projector.height_px) || shown.type() != CV_8UC1)
      throw CalibrationError("twin rig: the projector's output is not a " + std::to_string(c_.projector.width_px) + "x" +
                             std::to_string(c_.projector.height_px) + " grey image");
    return expose(c_, samples_, shown.isContinuous() ? shown : shown.clone(), rng_);
  }
  void accepted() override { kept_.push_back(poses_[current_]); }
  std::optional<Calibration> truth() const override {
    Calibration t;
    t.camera = c_.camera;
    t.projector = Camera{c_.projector};
    t.T_projector_camera = c_.T_projector_camera;
    t.T_camera_board = kept_;
    return t;
  }

 private:
  SimulationConfig c_;
  Geometry g_;
  std::vector<Eigen::Matrix4d> poses_;
  std::vector<cv::Point2d> rays_;
  PatternDisplay display_;
  std::vector<Sample> samples_;
  std::mt19937_64 rng_;
  std::size_t next_ = 0, current_ = 0;
  std::vector<Eigen::Matrix4d> kept_;
};

}  // namespace

std::unique_ptr<CaptureRig> make_twin_rig(const SimulationConfig& config, PatternDisplay display) {
  return std::make_unique<TwinRig>(config, std::move(display));
}

Camera twin_colour_camera(const config::Camera& depth_camera) {
  Camera c;
  static_cast<config::Pinhole&>(c) = depth_camera;
  c.distortion = {0.10, -0.20, 0.0005, -0.0005, 0.0};
  return c;
}

}  // namespace projbot::calibrate
