#pragma once
// A calibration session (`projbot calibrate capture`): the projector shows each Gray-code pattern, the
// colour camera takes it, for each pose a person holds the board at; a pose whose board or decoded
// light is too little is refused on the spot and asked for again. The rig is the real projector and
// camera, or the twin's.

#include <filesystem>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "projbot/calibrate/calibrate.hpp"

namespace projbot::calibrate {

/// The projector and colour camera a session drives.
class CaptureRig {
 public:
  virtual ~CaptureRig() = default;
  /// Waits until the board is held at the next pose (`pose` of `poses`, 1-based); false ends the session.
  virtual bool ready(int pose, int poses) = 0;
  /// Shows `pattern` (8-bit grey, the projector's size; number `index` of gray_code_images(), for rigs
  /// that load them ahead) full screen and returns the colour camera's 8-bit grey image of it, taken once
  /// the light has settled.
  virtual cv::Mat show_and_capture(std::size_t index, const cv::Mat& pattern) = 0;
  /// The pose just taken was kept.
  virtual void accepted() {}
  /// The values the images were made with, for the twin's rig (with the kept poses' T_camera_board).
  virtual std::optional<Calibration> truth() const { return std::nullopt; }
};

struct CaptureOptions {
  int projector_width = 1280, projector_height = 800;
  Board board;
  int poses = 10;        ///< poses to keep
  int min_corners = 12;  ///< a pose with fewer corners mapped into the projector is refused on the spot
};

struct CaptureSummary {
  int kept = 0;
  int refused = 0;
};

/// Runs the session into capture folder `out` (the layout `solve` reads; written as the twin's simulate
/// writes it, renamed into place at the end). `say` gets each line for the person holding the board:
/// progress and what to do next. When `stop()` says so, the poses kept so far are written (none:
/// nothing is). Throws CalibrationError.
CaptureSummary capture(CaptureRig& rig, const CaptureOptions& options, const std::filesystem::path& out,
                       const std::function<void(const std::string&)>& say, const std::function<bool()>& stop = {});

/// The twin's rig: `config`'s board held at its poses (spread or scripted; ready() is false when they
/// run out), lit by what `display(index, pattern)` makes of each pattern (the projector's output as a
/// renderer draws it; the pattern itself when empty), seen by the twin's colour camera.
using PatternDisplay = std::function<cv::Mat(std::size_t index, const cv::Mat& pattern)>;
std::unique_ptr<CaptureRig> make_twin_rig(const SimulationConfig& config, PatternDisplay display = {});

}  // namespace projbot::calibrate
