#pragma once
// The steps of `solve`, on OpenCV images, for the tests and the simulator: the Gray-code patterns,
// per-pixel decoding, board detection, and the mapping of a camera corner into the projector.

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "projbot/calibrate/calibrate.hpp"

namespace projbot::calibrate {

/// OpenCV's Gray-code patterns for a projector of this size, in generate()'s order, then white, black.
std::vector<cv::Mat> gray_code_images(int projector_width, int projector_height);

/// Per camera pixel, the projector pixel it saw (CV_32FC2; NaN where the white/black difference is under
/// `min_contrast` grey levels or the code decodes off the projector). `images` as gray_code_images()
/// lists them, 8-bit grey, all one size.
cv::Mat decode_gray_code(const std::vector<cv::Mat>& images, int projector_width, int projector_height, int min_contrast = 12);

/// The board as the patterns light it on average (each pattern with its inverse lights every pixel
/// once): evenly lit, with the noise of the 2n exposures averaged away. 8-bit, for detect_board.
cv::Mat lit_image(const std::vector<cv::Mat>& images);

/// Board corners found in a grey image: pixel positions and the matching board points (z = 0), metres.
struct BoardView {
  std::vector<cv::Point2f> image;
  std::vector<cv::Point3f> object;
};
BoardView detect_board(const Board& board, const cv::Mat& grey);

/// The board as printed, `pixels_per_m` across (8-bit grey), and the affine map from board points
/// (x, y in metres) to its pixel positions, from detecting the drawing itself (so the simulator and
/// detect_board agree on OpenCV's board frame whatever its convention).
struct BoardImage {
  cv::Mat image;
  cv::Matx23d board_to_pixel;
};
BoardImage draw_board(const Board& board, double pixels_per_m);

/// Where camera position `corner` falls in the projector: a quadratic fitted, with outliers reweighted
/// away (Tukey), to the decoded pixels within `radius_px`, evaluated at the corner. Empty when too few
/// pixels decode around it or they do not surround it. A local regression of the decoded map, not a
/// homography.
std::optional<cv::Point2d> corner_to_projector(const cv::Mat& decoded, cv::Point2f corner, int radius_px = 14);

}  // namespace projbot::calibrate
