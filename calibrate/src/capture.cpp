// The calibration session: patterns shown and taken per pose, each pose checked before it is kept.

#include "projbot/calibrate/capture.hpp"

#include <opencv2/imgproc.hpp>

#include "capture_io.hpp"
#include "projbot/calibrate/procam.hpp"
#include "solve_views.hpp"

namespace projbot::calibrate {
namespace {

// Whether a pose's images hold enough board lit by decodable patterns; the reason when not.
std::string check_pose(const CaptureManifest& m, const std::vector<cv::Mat>& images, const CaptureOptions& o) {
  SolveOptions so;
  so.min_corners = o.min_corners;
  Correspondences unused;
  const ViewResult r = measure_view(m, lit_image(images), images, so, unused);
  return r.refused;
}

}  // namespace

CaptureSummary capture(CaptureRig& rig, const CaptureOptions& o, const std::filesystem::path& out,
                       const std::function<void(const std::string&)>& say, const std::function<bool()>& stop) {
  if (o.poses < 1 || o.poses > 100) throw CalibrationError("capture: poses must be 1..100");
  const std::vector<cv::Mat> patterns = gray_code_images(o.projector_width, o.projector_height);
  CaptureWriter writer(out);  // checks `out` before any image is shown
  CaptureManifest manifest{o.projector_width, o.projector_height, o.board, {}, {}};
  CaptureSummary s;
  const auto stopped = [&] { return stop && stop(); };
  while (s.kept < o.poses && !stopped()) {
    const int pose = s.kept + 1;
    if (!rig.ready(pose, o.poses)) break;
    std::vector<cv::Mat> images;
    for (std::size_t i = 0; i < patterns.size() && !stopped(); ++i) {
      cv::Mat image = rig.show_and_capture(i, patterns[i]);
      if (image.empty() || image.type() != CV_8UC1)
        throw CalibrationError("capture: the camera gave no 8-bit grey image for pattern " + std::to_string(i));
      if (!images.empty() && image.size() != images.front().size())
        throw CalibrationError("capture: the camera's image size changed during pose " + std::to_string(pose));
      images.push_back(std::move(image));
    }
    if (images.size() < patterns.size()) break;  // stopped within the pose: it is not kept
    if (const std::string why = check_pose(manifest, images, o); !why.empty()) {
      ++s.refused;
      say("pose " + std::to_string(pose) + " refused: " + why +
          "; hold the board again, wholly in the camera's view and the "
          "projector's light");
      continue;
    }
    manifest.folders.push_back(writer.write_pose(s.kept, images));
    rig.accepted();
    ++s.kept;
    say("pose " + std::to_string(pose) + " of " + std::to_string(o.poses) + " kept" +
        (s.kept < o.poses ? "; move the board: another distance, tilt and place in the projector's image" : ""));
  }
  if (s.kept > 0) writer.finish(manifest, rig.truth());
  return s;
}

}  // namespace projbot::calibrate
