#pragma once
// Projector-camera calibration (issue 13): Gray-code structured light on a planar board, solved with
// OpenCV. A capture folder holds one sub-folder per board pose, each with the Gray-code images in the
// order OpenCV's GrayCodePattern::generate() gives them (each bit's pattern then its inverse, columns
// first, then rows), then a white and a black image. `simulate` writes such a folder from the twin's
// geometry, `solve` turns one into the projector's intrinsics A_p and the camera-to-projector pose
// (R_cp, T_cp of Eq. 2). OpenCV stays behind this header; projbot/calibrate/procam.hpp has the steps.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"

namespace projbot::calibrate {

/// A capture that cannot be solved or written (missing images, no board, bad spec): names what is wrong.
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The planar board. `charuco:10x7:0.06:0.045:DICT_4X4_50` is a ChArUco board of 10 x 7 squares of 6 cm
/// with 4.5 cm markers (robust to partial views); `checkerboard:9x7:0.03` is a plain checkerboard with
/// 9 x 7 inner corners 3 cm apart (OpenCV's pattern size: it must be seen whole).
struct Board {
  enum class Kind { charuco, checkerboard };
  Kind kind = Kind::charuco;
  int squares_x = 10;  ///< charuco: squares across; checkerboard: inner corners across
  int squares_y = 7;   ///< charuco: squares down; checkerboard: inner corners down
  double square_m = 0.06;
  double marker_m = 0.045;                 ///< charuco only
  std::string dictionary = "DICT_4X4_50";  ///< charuco only: an OpenCV predefined ArUco dictionary

  /// Parses the spec above; throws CalibrationError naming what is wrong.
  static Board parse(const std::string& spec);
  std::string spec() const;
  /// Width and height of the squares' area, metres.
  double width_m() const;
  double height_m() const;
};

/// A pinhole with OpenCV's lens distortion (k1, k2, p1, p2, k3): config's one lens type.
using config::Camera;

/// How many images a pose of a projector this size takes: 2 per Gray-code bit of each axis, then white
/// and black.
int images_per_pose(int projector_width, int projector_height);

/// A board pose a person's script gives: the middle of the board's squares in the colour camera's frame
/// (x right, y down, z forward; metres) and its tilt away from facing the camera, degrees about the
/// camera's x, y and z axes (R = Rx Ry Rz).
struct BoardPose {
  Eigen::Vector3d centre_m = Eigen::Vector3d(0, 0, 1);
  Eigen::Vector3d tilt_deg = Eigen::Vector3d::Zero();
};
/// Reads `poses: [{centre: [x, y, z], tilt_deg: [a, b, c]}, ...]`. Throws CalibrationError naming the file.
std::vector<BoardPose> read_board_poses(const std::filesystem::path& path);

/// The twin's calibration session: a board held at `poses` poses in front of the camera and projector
/// (a deterministic spread over the projector's image, 0.8-1.3 m, tilted up to 30 degrees), the
/// projector's patterns falling on it (inverse-square and incidence falloff over room light), seen by
/// the colour camera through its lens distortion, with blur and sensor noise.
struct SimulationConfig {
  int poses = 10;
  std::vector<BoardPose> scripted;  ///< when given, the board is held at these (and `poses` is ignored)
  std::uint64_t seed = 1;
  Board board;
  Camera camera;                                                     ///< the colour camera's truth (pinhole + distortion)
  config::ProjectorConfig projector;                                 ///< A_p's truth, with its lens
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  ///< R_cp, T_cp's truth
  double ambient = 0.10;       ///< room light, as a fraction of the projector's white at 1 m
  double blur_sigma_px = 0.7;  ///< the camera's optical blur (Gaussian), pixels
  double noise_sigma = 1.5;    ///< sensor noise, grey levels (of 255)
};

/// The twin's colour camera: the depth camera's pinhole (colour registered to it) with a webcam-class
/// barrel distortion, so that a solve has one to find.
Camera twin_colour_camera(const config::Camera& depth_camera);

/// Writes a capture folder (capture.yaml, pose_NN/NN.png, truth.yaml with the values it was made
/// with); returns the poses written. `progress(pose)` is called after each pose; when `stop()` says so
/// the poses finished so far are written as the capture (none: nothing is). Throws CalibrationError.
int simulate(const SimulationConfig& config, const std::filesystem::path& out,
             const std::function<void(int pose, int poses)>& progress = {}, const std::function<bool()>& stop = {});

/// What `solve` needs beyond the folder: given on the command line for captures made with other
/// tools (no capture.yaml), else read from capture.yaml.
struct SolveOptions {
  std::optional<std::pair<int, int>> projector_size;  ///< width, height in pixels
  std::optional<Board> board;
  bool projector_distortion = false;  ///< fit k1, k2 for the projector (the renderer draws a pinhole)
  int min_corners = 6;                ///< a view with fewer corners mapped to the projector is refused
};

struct ViewResult {
  std::string folder;
  int corners = 0;            ///< board corners found in the camera
  int projector_corners = 0;  ///< of those, mapped to the projector through the decoded patterns
  double camera_rms_px = 0.0, projector_rms_px = 0.0;
  std::string refused;  ///< why the view was not used; empty when used
};

struct Calibration {
  Camera camera;
  Camera projector;
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();  ///< X_p = R_cp X_c + T_cp (Eq. 2)
  double camera_rms_px = 0.0, projector_rms_px = 0.0;                ///< over all used views, after the joint fit
  double projector_coverage = 0.0;                                   ///< area of the corners' convex hull / the projector's image
  std::vector<ViewResult> views;
  std::vector<std::string> warnings;
  std::vector<std::string> notes;  ///< what solve skipped in the capture folder, and why (not written)
  double board_square_m = 0.0;     ///< the board's square as given: T_cp is in its unit
  /// A simulated capture's truth only: each pose's board in the camera frame (OpenCV's board frame).
  std::vector<Eigen::Matrix4d> T_camera_board;
};

/// A solve against the truth a simulated capture carries: focal lengths in % of the truth's, principal
/// points in pixels, T_cp in mm, R_cp in degrees.
struct TruthComparison {
  double projector_fx_pct = 0.0, projector_fy_pct = 0.0, projector_principal_px = 0.0;
  double camera_fx_pct = 0.0, camera_fy_pct = 0.0, camera_principal_px = 0.0;
  double translation_mm = 0.0, rotation_deg = 0.0;
  bool projector_lens = false;     ///< either has a projector distortion
  double projector_lens_px = 0.0;  ///< then: how far apart the two lenses put one ray, at most over the image
};
TruthComparison compare(const Calibration& solved, const Calibration& truth);

/// Decodes, finds corners, maps them to the projector and calibrates. Throws CalibrationError for a
/// folder that cannot be read or has too few usable views. `progress(view)` after each view.
Calibration solve(const std::filesystem::path& dir, const SolveOptions& options,
                  const std::function<void(int view, int views, const ViewResult&)>& progress = {});

/// Writes the calibration as `calibration:` in a scene file reads it, atomically (temp file, rename).
void write_calibration(const Calibration& c, const std::filesystem::path& path, const std::string& comment);
/// Reads back what write_calibration wrote (the fields above; views and warnings are not read back).
Calibration read_calibration(const std::filesystem::path& path);

}  // namespace projbot::calibrate
