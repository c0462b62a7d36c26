#pragma once
// Capture folders on disk: writing one (atomically: a hidden sibling folder renamed into place) and
// reading ours (capture.yaml) or another tool's (folders of images, sizes from the command line).

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "projbot/calibrate/calibrate.hpp"

namespace projbot::calibrate {

struct CaptureManifest {
  int projector_width = 0, projector_height = 0;
  Board board;
  std::vector<std::string> folders;  ///< one per board pose, relative to the capture folder
  std::vector<std::string> notes;    ///< what reading it skipped, and why
};

class CaptureWriter {
 public:
  /// Refuses an `out` that exists and is not an empty folder, or whose parent cannot take a folder.
  explicit CaptureWriter(std::filesystem::path out);
  ~CaptureWriter();  ///< removes the unfinished folder
  CaptureWriter(const CaptureWriter&) = delete;
  CaptureWriter& operator=(const CaptureWriter&) = delete;
  /// Writes pose `index`'s images as pose_NN/NN.png; the folder's name.
  std::string write_pose(int index, const std::vector<cv::Mat>& images);
  /// Writes capture.yaml (and truth.yaml when `truth` is given) and moves the folder into place.
  void finish(const CaptureManifest& manifest, const std::optional<Calibration>& truth);

 private:
  std::filesystem::path out_, temp_;
  bool done_ = false;
};

/// The manifest of capture folder `dir`: capture.yaml's, or for a folder without one the sub-folders
/// that hold images, with the projector size and board from `options` (those holding images at the
/// projector's size, the patterns themselves, skipped with a note). Throws CalibrationError.
CaptureManifest read_manifest(const std::filesystem::path& dir, const SolveOptions& options);
/// A pose's images, 8-bit grey, in order (file names sorted with numbers compared as numbers).
std::vector<cv::Mat> read_pose(const std::filesystem::path& folder, std::size_t expected);

}  // namespace projbot::calibrate
