#pragma once
// Photometric calibration (issue 43): the projector's response per channel and its colour mixing, from
// uniform colours it shows on a light surface and the colour camera's images of them. The camera's own
// response comes from exposure brackets of the projector's white, or from the same captures (its values
// must add up as light does), or is given, so that its values can be linearised. Black level and the
// room's light cannot be told apart with the projector on: the scene's black_level stays.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "projbot/config/scene.hpp"

namespace projbot::calibrate {

/// A session stopped on request (Ctrl-C) before it had every capture: nothing to fit.
class SessionStopped : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What a photometric session drives: the projector showing one colour over its whole image (each channel
/// 0..1; a device shows the nearest 8-bit level), and the colour camera's mean R, G, B (8-bit levels,
/// 0..255) over the patch of surface it lights, at an exposure relative to the session's first.
class PhotometricRig {
 public:
  virtual ~PhotometricRig() = default;
  virtual Eigen::Vector3d show_and_measure(const Eigen::Vector3d& input, double exposure) = 0;
  /// Whether the camera's exposure can be set (exposure other than 1 in show_and_measure); without, the
  /// camera's response is given, not measured.
  virtual bool brackets() const { return true; }
};

/// Where the camera's response came from.
enum class CameraResponse {
  given,
  exposure_brackets,  ///< white at six exposures
  colours_adding_up,  ///< the grey ramp against the sum of the primaries' at the same inputs
};
const char* to_string(CameraResponse from);

/// The projector's colour is a config::Photometry: each channel's gamma (`gamma_rgb`), its black level and
/// its `mixing` (column j: channel j's light in the camera's R, G, B; rows sum to 1, so white is white).
struct PhotometricResult {
  config::Photometry projector;  ///< gamma_rgb (gamma their mean) and mixing measured; black_level as given
  double camera_gamma = 0.0;     ///< the camera's response: value = 255 (exposure x light)^(1 / camera_gamma)
  CameraResponse camera_response = CameraResponse::given;
  int captures = 0;
  /// How far the ramps lie from the fitted curves: the worst channel's RMS, over its ramp steps, of the
  /// measured share of full light less level^gamma.
  double ramp_residual = 0.0;
};

/// How the camera's response is had: `gamma` given (> 0); else from the colours adding up when
/// `from_colours`; else from exposure brackets (a rig that cannot bracket is refused).
struct CameraResponseOptions {
  double gamma = 0.0;
  /// The grey ramp is shown too: the projector's light adds up (grey = red + green + blue at the same
  /// input), and the camera's gamma is the one that makes its values add up as well (within 1 % of white;
  /// the primaries' crosstalk into the camera's other channels is what tells). Only for a projector whose
  /// light adds up: LCD, LCoS, three-chip DLP, a colour wheel without a white segment (often a DLP's sRGB
  /// mode). A white segment adding 2 % of white passes unseen and biases the camera's gamma by 8 % (10 %:
  /// 28 %; the twin's, with a typical DLP's crosstalk); one of 30 % is refused.
  bool from_colours = false;
};

/// The session: white at six exposures (the camera's response from brackets), black, white and each
/// primary, an eight-step ramp per channel (each step the 8-bit level nearest k/8), and with
/// `camera.from_colours` the grey ramp at the same steps. `black_level`: the projector's, from its scene
/// (not measurable here). Throws CalibrationError when the captures cannot be fitted (saturated, too dark,
/// not monotonic; light that does not add up, or too little crosstalk to tell the camera's response), or
/// a rig that cannot bracket has no other way to the camera's response.
PhotometricResult calibrate_photometric(PhotometricRig& rig, double black_level, const CameraResponseOptions& camera = {});

/// The twin's rig: a light grey patch (reflectance 0.8) facing the projector 1.5 m away, lit by the
/// room's `ambient_lux` and the projector (its lumens and photometry, the truth), seen by an 8-bit camera whose response
/// is x^(1 / camera_gamma), exposed so that white fills 90 % of its range, with Gaussian noise of
/// `noise_levels` per pixel over a 32 x 32 patch.
struct PhotometricSim {
  config::ProjectorConfig projector;  ///< its lumens light the patch; its photometry is the truth to recover
  double ambient_lux = 20.0;
  double camera_gamma = 2.2;
  double noise_levels = 2.0;
  std::uint64_t seed = 1;
  bool brackets = true;        ///< the camera's exposure can be set; false: its response from the colours adding up
  double white_segment = 0.0;  ///< a colour wheel's white segment: this share of white's light more, times the dimmest channel's
};
std::unique_ptr<PhotometricRig> make_twin_photometric_rig(const PhotometricSim& sim);
/// A result against the twin's truth: the worst channel's gamma off by this share (0.01: 1 %), and the
/// largest mixing entry off by this much.
struct PhotometricDifference {
  double gamma_share = 0.0, mixing = 0.0;
};
PhotometricDifference compare(const PhotometricResult& result, const PhotometricSim& truth);
/// The crosstalk of a typical DLP's colour wheel, the twin's truth: a few percent of each channel's light
/// in its neighbours.
Eigen::Matrix3d typical_mixing();

/// Writes `photometry:` (gamma, the per-channel gammas, black_level, mixing, the camera's gamma) as a
/// calibration file carries it, atomically.
void write_photometric(const PhotometricResult& r, const std::filesystem::path& path, const std::string& comment);

}  // namespace projbot::calibrate
