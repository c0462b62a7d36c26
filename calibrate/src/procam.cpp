// The Gray-code and board steps of the calibration, on OpenCV's structured_light and aruco modules.

#include "projbot/calibrate/procam.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/structured_light/graycodepattern.hpp>
#include <sstream>

namespace projbot::calibrate {
namespace {

const std::map<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME>& dictionaries() {
  using namespace cv::aruco;
  static const std::map<std::string, PREDEFINED_DICTIONARY_NAME> all{{"DICT_4X4_50", DICT_4X4_50},
                                                                     {"DICT_4X4_100", DICT_4X4_100},
                                                                     {"DICT_4X4_250", DICT_4X4_250},
                                                                     {"DICT_4X4_1000", DICT_4X4_1000},
                                                                     {"DICT_5X5_50", DICT_5X5_50},
                                                                     {"DICT_5X5_100", DICT_5X5_100},
                                                                     {"DICT_5X5_250", DICT_5X5_250},
                                                                     {"DICT_5X5_1000", DICT_5X5_1000},
                                                                     {"DICT_6X6_50", DICT_6X6_50},
                                                                     {"DICT_6X6_100", DICT_6X6_100},
                                                                     {"DICT_6X6_250", DICT_6X6_250},
                                                                     {"DICT_6X6_1000", DICT_6X6_1000},
                                                                     {"DICT_7X7_50", DICT_7X7_50},
                                                                     {"DICT_7X7_100", DICT_7X7_100},
                                                                     {"DICT_7X7_250", DICT_7X7_250},
                                                                     {"DICT_7X7_1000", DICT_7X7_1000},
                                                                     {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL}};
  return all;
}

cv::Ptr<cv::aruco::CharucoBoard> charuco(const Board& b) {
  const cv::Ptr<cv::aruco::Dictionary> dict = cv::aruco::getPredefinedDictionary(dictionaries().at(b.dictionary));
  return cv::aruco::CharucoBoard::create(b.squares_x, b.squares_y, static_cast<float>(b.square_m), static_cast<float>(b.marker_m),
                                         dict);
}

cv::Ptr<cv::structured_light::GrayCodePattern> gray_code(int width, int height) {
  cv::structured_light::GrayCodePattern::Params params;
  params.width = width;
  params.height = height;
  return cv::structured_light::GrayCodePattern::create(params);
}

double parse_number(const std::string& text, const std::string& spec, const char* what) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(v) || v <= 0.0)
    throw CalibrationError("board '" + spec + "': " + what + " '" + text + "' is not a positive number");
  return v;
}

}  // namespace

Board Board::parse(const std::string& spec) {
  std::vector<std::string> parts;
  std::stringstream in(spec);
  for (std::string p; std::getline(in, p, ':');) parts.push_back(p);
  const std::string usage = " (expected charuco:10x7:SQUARE_M:MARKER_M[:DICT_4X4_50] or checkerboard:9x7:SQUARE_M)";
  if (parts.size() < 3) throw CalibrationError("board '" + spec + "': too few fields" + usage);
  Board b;
  if (parts[0] == "charuco") {
    if (parts.size() != 4 && parts.size() != 5) throw CalibrationError("board '" + spec + "': wrong number of fields" + usage);
    b.kind = Kind::charuco;
  } else if (parts[0] == "checkerboard") {
    if (parts.size() != 3) throw CalibrationError("board '" + spec + "': wrong number of fields" + usage);
    b.kind = Kind::checkerboard;
  } else {
    throw CalibrationError("board '" + spec + "': unknown kind '" + parts[0] + "'" + usage);
  }
  const std::size_t x = parts[1].find('x');
  try {
    std::size_t u1 = 0, u2 = 0;
    b.squares_x = std::stoi(parts[1].substr(0, x), &u1);
    b.squares_y = std::stoi(parts[1].substr(x + 1), &u2);
    if (x == std::string::npos || u1 != x || u2 != parts[1].size() - x - 1) throw std::invalid_argument("size");
  } catch (const std::exception&) {
    throw CalibrationError("board '" + spec + "': size '" + parts[1] + "' is not COLUMNSxROWS" + usage);
  }
  const int min_size = b.kind == Kind::charuco ? 3 : 2;
  if (b.squares_x < min_size || b.squares_y < min_size || b.squares_x > 100 || b.squares_y > 100)
    throw CalibrationError("board '" + spec + "': size " + parts[1] + " is out of range (" + std::to_string(min_size) +
                           " to 100 each way)");
  b.square_m = parse_number(parts[2], spec, "square size");
  if (b.kind == Kind::charuco) {
    b.marker_m = parse_number(parts[3], spec, "marker size");
    if (b.marker_m >= b.square_m) throw CalibrationError("board '" + spec + "': the marker must be smaller than the square");
    if (parts.size() == 5) b.dictionary = parts[4];
    if (!dictionaries().contains(b.dictionary))
      throw CalibrationError("board '" + spec + "': unknown ArUco dictionary '" + b.dictionary +
                             "' (DICT_4X4_50 ... DICT_7X7_1000)");
    // A ChArUco board carries a marker in every other square, each a different one of the dictionary's.
    const int markers = b.squares_x * b.squares_y / 2;
    const int available = cv::aruco::getPredefinedDictionary(dictionaries().at(b.dictionary))->bytesList.rows;
    if (markers > available)
      throw CalibrationError("board '" + spec + "': " + std::to_string(markers) + " markers, " + b.dictionary + " has " +
                             std::to_string(available) + "; name a larger dictionary (DICT_4X4_1000)");
  }
  return b;
}

std::string Board::spec() const {
  std::ostringstream out;
  out.precision(10);
  if (kind == Kind::charuco)
    out << "charuco:" << squares_x << 'x' << squares_y << ':' << square_m << ':' << marker_m << ':' << dictionary;
  else
    out << "checkerboard:" << squares_x << 'x' << squares_y << ':' << square_m;
  return out.str();
}

double Board::width_m() const { return (kind == Kind::charuco ? squares_x : squares_x + 1) * square_m; }
double Board::height_m() const { return (kind == Kind::charuco ? squares_y : squares_y + 1) * square_m; }

int images_per_pose(int projector_width, int projector_height) {
  return static_cast<int>(gray_code(projector_width, projector_height)->getNumberOfPatternImages()) + 2;
}

std::vector<cv::Mat> gray_code_images(int projector_width, int projector_height) {
  const auto pattern = gray_code(projector_width, projector_height);
  std::vector<cv::Mat> images;
  pattern->generate(images);
  cv::Mat white, black;
  pattern->getImagesForShadowMasks(black, white);
  images.push_back(white);
  images.push_back(black);
  return images;
}

cv::Mat decode_gray_code(const std::vector<cv::Mat>& images, int projector_width, int projector_height, int min_contrast) {
  const auto pattern = gray_code(projector_width, projector_height);
  const std::size_t n = pattern->getNumberOfPatternImages();
  if (images.size() != n + 2)
    throw CalibrationError("decode: " + std::to_string(images.size()) + " images, a " + std::to_string(projector_width) + "x" +
                           std::to_string(projector_height) + " projector's patterns take " + std::to_string(n + 2));
  // Every bit is decoded whatever its contrast: the finest stripes are narrower than a camera pixel and
  // a Gray code's misread bit moves a pixel only across the stripe edge it sits on, which the local fit
  // of corner_to_projector averages away. Pixels without projector light (white - black) are dropped.
  pattern->setWhiteThreshold(0);
  const std::vector<cv::Mat> patterns(images.begin(), images.begin() + static_cast<std::ptrdiff_t>(n));
  const cv::Mat& white = images[n];
  const cv::Mat& black = images[n + 1];
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat decoded(white.size(), CV_32FC2, cv::Scalar(nan, nan));
  for (int y = 0; y < white.rows; ++y)
    for (int x = 0; x < white.cols; ++x) {
      if (int(white.at<uchar>(y, x)) - int(black.at<uchar>(y, x)) < min_contrast) continue;
      cv::Point p;
      if (pattern->getProjPixel(patterns, x, y, p)) continue;  // decodes off the projector
      decoded.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(p.x), static_cast<float>(p.y));
    }
  return decoded;
}

cv::Mat lit_image(const std::vector<cv::Mat>& images) {
  cv::Mat sum(images.front().size(), CV_32F, cv::Scalar(0));
  const std::size_t n = images.size() - 2;
  for (std::size_t i = 0; i < n; ++i) cv::accumulate(images[i], sum);
  cv::Mat out;
  sum.convertTo(out, CV_8U, 1.0 / static_cast<double>(n));
  return out;
}

namespace {

// OpenCV 4.6's interpolateCornersCharuco returns corners half a pixel down and right of the saddle
// (measured on drawn boards: +0.5 px on both axes, where cornerSubPix and findChessboardCornersSB are
// unbiased); 2.7 projector pixels per camera pixel turned that into a 1.4 px shift of every projector
// corner. Each corner is refined again with cornerSubPix, its window kept off the markers.
void refine_saddles(const Board& board, const cv::Mat& grey, std::vector<cv::Point2f>& corners) {
  if (corners.size() < 2) return;
  std::vector<cv::Point2f> refined;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    double nearest = std::numeric_limits<double>::max();
    for (std::size_t j = 0; j < corners.size(); ++j)
      if (j != i) nearest = std::min(nearest, static_cast<double>(cv::norm(corners[i] - corners[j])));
    const double gap_px = nearest * (board.square_m - board.marker_m) / (2.0 * board.square_m);
    const int half = std::clamp(static_cast<int>(0.8 * gap_px), 2, 6);
    std::vector<cv::Point2f> one{corners[i]};
    cv::cornerSubPix(grey, one, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-4));
    refined.push_back(one[0]);
  }
  corners = refined;
}

}  // namespace

BoardView detect_board(const Board& board, const cv::Mat& grey) {
  BoardView view;
  if (board.kind == Board::Kind::checkerboard) {
    const cv::Size size(board.squares_x, board.squares_y);
    if (!cv::findChessboardCornersSB(grey, size, view.image, cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY)) return {};
    for (int j = 0; j < size.height; ++j)
      for (int i = 0; i < size.width; ++i)
        view.object.emplace_back(static_cast<float>(i * board.square_m), static_cast<float>(j * board.square_m), 0.0f);
    return view;
  }
  const auto b = charuco(board);
  std::vector<std::vector<cv::Point2f>> markers, rejected;
  std::vector<int> ids;
  cv::aruco::detectMarkers(grey, b->dictionary, markers, ids, cv::aruco::DetectorParameters::create(), rejected);
  if (ids.empty()) return {};
  cv::aruco::refineDetectedMarkers(grey, b, markers, ids, rejected);
  std::vector<int> corner_ids;
  cv::aruco::interpolateCornersCharuco(markers, ids, grey, b, view.image, corner_ids);
  for (const int id : corner_ids) view.object.push_back(b->chessboardCorners[static_cast<std::size_t>(id)]);
  refine_saddles(board, grey, view.image);
  return view;
}

namespace {

// Least-squares affine map from board points to pixel positions; its largest residual, pixels.
double fit_affine(const BoardView& v, cv::Matx23d& out) {
  Eigen::MatrixXd A(static_cast<Eigen::Index>(v.image.size()), 3);
  Eigen::MatrixXd B(A.rows(), 2);
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    A.row(i) << v.object[k].x, v.object[k].y, 1.0;
    B.row(i) << v.image[k].x, v.image[k].y;
  }
  const Eigen::MatrixXd X = A.colPivHouseholderQr().solve(B);
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = X(c, r);
  return (A * X - B).rowwise().norm().maxCoeff();
}

}  // namespace

BoardImage draw_board(const Board& board, double pixels_per_m) {
  const int w = static_cast<int>(std::lround(board.width_m() * pixels_per_m));
  const int h = static_cast<int>(std::lround(board.height_m() * pixels_per_m));
  BoardImage out;
  if (board.kind == Board::Kind::charuco) {
    charuco(board)->draw(cv::Size(w, h), out.image, 0, 1);
  } else {
    out.image = cv::Mat(h, w, CV_8U, cv::Scalar(255));
    const int nx = board.squares_x + 1, ny = board.squares_y + 1;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        if ((i + j) % 2 == 0)
          out.image(cv::Range(j * h / ny, (j + 1) * h / ny), cv::Range(i * w / nx, (i + 1) * w / nx)).setTo(0);
  }
  // Detect the drawing on white paper (a quiet zone) to learn OpenCV's board frame.
  const int pad = static_cast<int>(board.square_m * pixels_per_m);
  cv::Mat padded;
  cv::copyMakeBorder(out.image, padded, pad, pad, pad, pad, cv::BORDER_CONSTANT, cv::Scalar(255));
  cv::Mat small;
  const double shrink = std::min(1.0, 1600.0 / padded.cols);
  cv::resize(padded, small, cv::Size(), shrink, shrink, cv::INTER_AREA);
  BoardView v = detect_board(board, small);
  if (v.image.size() < 4) throw CalibrationError("board " + board.spec() + ": OpenCV does not find the board in its own drawing");
  for (cv::Point2f& p : v.image)
    p = cv::Point2f(static_cast<float>((p.x + 0.5) / shrink - 0.5 - pad), static_cast<float>((p.y + 0.5) / shrink - 0.5 - pad));
  if (fit_affine(v, out.board_to_pixel) > 2.0 / shrink)
    throw CalibrationError("board " + board.spec() + ": its drawing does not match its corner positions");
  return out;
}

std::optional<cv::Point2d> corner_to_projector(const cv::Mat& decoded, cv::Point2f corner, int radius_px) {
  std::vector<Eigen::Matrix<double, 6, 1>> basis;
  std::vector<Eigen::Vector2d> target;
  int quadrant[4] = {0, 0, 0, 0};
  const double r = radius_px;
  for (int y = static_cast<int>(std::floor(corner.y - r)); y <= static_cast<int>(std::ceil(corner.y + r)); ++y)
    for (int x = static_cast<int>(std::floor(corner.x - r)); x <= static_cast<int>(std::ceil(corner.x + r)); ++x) {
      if (x < 0 || y < 0 || x >= decoded.cols || y >= decoded.rows) continue;
      const double du = (x - static_cast<double>(corner.x)) / r, dv = (y - static_cast<double>(corner.y)) / r;
      if (du * du + dv * dv > 1.0) continue;
      const cv::Vec2f p = decoded.at<cv::Vec2f>(y, x);
      if (std::isnan(p[0])) continue;
      basis.push_back((Eigen::Matrix<double, 6, 1>() << 1.0, du, dv, du * du, du * dv, dv * dv).finished());
      target.emplace_back(p[0], p[1]);
      ++quadrant[(du >= 0 ? 1 : 0) + (dv >= 0 ? 2 : 0)];
    }
  if (basis.size() < 40 || *std::min_element(quadrant, quadrant + 4) < 5) return std::nullopt;
  // Iteratively reweighted least squares with Tukey's biweight: misdecoded pixels (a wrong coarse bit
  // puts a pixel far away) get no weight, stripe-edge noise a little.
  std::vector<double> weight(basis.size(), 1.0);
  Eigen::Matrix<double, 6, 2> coef = Eigen::Matrix<double, 6, 2>::Zero();
  for (int iteration = 0; iteration < 8; ++iteration) {
    Eigen::Matrix<double, 6, 6> N = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 2> b = Eigen::Matrix<double, 6, 2>::Zero();
    for (std::size_t i = 0; i < basis.size(); ++i) {
      N += weight[i] * basis[i] * basis[i].transpose();
      b += weight[i] * basis[i] * target[i].transpose();
    }
    coef = N.ldlt().solve(b);
    std::vector<double> residual(basis.size());
    for (std::size_t i = 0; i < basis.size(); ++i) residual[i] = (coef.transpose() * basis[i] - target[i]).norm();
    std::vector<double> sorted = residual;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double c = 4.685 * std::max(0.25, 1.4826 * sorted[sorted.size() / 2]);
    for (std::size_t i = 0; i < basis.size(); ++i) {
      const double u = residual[i] / c;
      weight[i] = u < 1.0 ? (1.0 - u * u) * (1.0 - u * u) : 0.0;
    }
  }
  if (!coef.allFinite()) return std::nullopt;
  return cv::Point2d(coef(0, 0), coef(0, 1));
}

}  // namespace projbot::calibrate
