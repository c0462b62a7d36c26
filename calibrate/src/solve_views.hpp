#pragma once
// What `solve` measures of one view, shared with `capture` (which checks each pose with it on the spot).

#include <opencv2/core.hpp>
#include <vector>

#include "capture_io.hpp"

namespace projbot::calibrate {

// The used views' correspondences, one entry per view in each list, as OpenCV's calibration takes them.
struct Correspondences {
  std::vector<std::vector<cv::Point3f>> object;  // every corner the camera found
  std::vector<std::vector<cv::Point2f>> camera;
  std::vector<std::vector<cv::Point3f>> shared_object;  // those also mapped to the projector
  std::vector<std::vector<cv::Point2f>> shared_camera, projector;
};

/// One view: its corners found in `lit` and mapped into the projector; appended to `points` when used,
/// else ViewResult::refused says why.
ViewResult measure_view(const CaptureManifest& m, const cv::Mat& lit, const std::vector<cv::Mat>& images, const SolveOptions& o,
                        Correspondences& points);

}  // namespace projbot::calibrate
