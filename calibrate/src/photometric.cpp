#include "projbot/calibrate/photometric.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <vector>

#include "projbot/calibrate/calibrate.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/engine/photometry.hpp"

namespace projbot::calibrate {
namespace {

constexpr double kExposures[] = {1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125};
constexpr double kLeastCameraGamma = 0.5, kMostCameraGamma = 3.5;  // the colours' search
// The camera's gamma from the colours adding up: at the best gamma they must add up within this share of
// white (RMS), and 10 % off that gamma they must fail by this much more.
constexpr double kMostAdditivityRms = 0.01;
constexpr double kLeastAdditivityRise = 0.002;

// The ramps' misfit against their fitted curves beyond which the gammas are refused. In the twin's shop,
// brightening the room from 50 to 100000 lux at 0-2 levels of camera noise, every fit under 1.5 % was
// within 5.2 % of the true gammas and every one over 2.5 % more than 11 % off (34 % at 100000 lux).
constexpr double kMaxRampResidual = 0.02;

// The camera's gamma from white at the bracketed exposures: value = 255 (e L)^(1 / g) per channel, so
// log(value) against log(e) has slope 1 / g; values near black or saturation are left out.
double camera_gamma(PhotometricRig& rig, int& captures) {
  double sxy = 0.0, sxx = 0.0, sx = 0.0, sy = 0.0;
  int n = 0;
  for (const double e : kExposures) {
    const Eigen::Vector3d v = rig.show_and_measure(Eigen::Vector3d::Ones(), e);
    ++captures;
    for (int ch = 0; ch < 3; ++ch) {
      if (v[ch] < 12.0 || v[ch] > 243.0) continue;
      const double x = std::log(e), y = std::log(v[ch] / 255.0);
      sxy += x * y, sxx += x * x, sx += x, sy += y, ++n;
    }
  }
  const double slope = n >= 4 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0.0;
  if (!(slope > 0.1 && slope < 2.0))
    throw CalibrationError("photometric: the camera's values do not follow its exposure (white at 6 exposures: " +
                           std::to_string(n) + " usable values); is the projector's white in view and not saturating?");
  return 1.0 / slope;
}

std::string levels(const Eigen::Vector3d& v) {
  char text[64];
  std::snprintf(text, sizeof text, "%.0f %.0f %.0f", v[0], v[1], v[2]);
  return text;
}

// The ramps' inputs: step k of 8 as the 8-bit level nearest k/8 (what a device shows).
double ramp_level(int step) { return std::round(255.0 * step / 8.0) / 255.0; }

// What the fit reads: the camera's mean values (8-bit levels) under each colour the projector showed.
struct Captures {
  Eigen::Vector3d black, white;
  std::array<Eigen::Vector3d, 3> full;                 // each primary at full
  std::array<std::array<Eigen::Vector3d, 7>, 3> ramp;  // each primary at ramp_level(1..7)
  std::array<Eigen::Vector3d, 7> grey;                 // all three at ramp_level(1..7): only to measure the camera
};

// Black and white first (a projector out of the camera's view is refused before the rest), each primary
// at full and its ramp, and with `grey` the grey ramp; every capture checked for saturation.
Captures capture(PhotometricRig& rig, bool grey, int& captures) {
  const auto take = [&](const Eigen::Vector3d& input) {
    ++captures;
    const Eigen::Vector3d v = rig.show_and_measure(input, 1.0);
    if (v.maxCoeff() > 250.0)
      throw CalibrationError("photometric: the camera saturates under input " + levels(input * 255.0) + " (it reads " +
                             levels(v) + "): lower its exposure, or aim the projector at a darker surface");
    return v;
  };
  Captures c;
  c.black = take(Eigen::Vector3d::Zero());
  c.white = take(Eigen::Vector3d::Ones());
  if (!((c.white - c.black).minCoeff() >= 1.0))
    throw CalibrationError("photometric: the projector's white is no brighter than its black in the camera (" + levels(c.white) +
                           " against " + levels(c.black) + "): is its light in the camera's view?");
  for (int j = 0; j < 3; ++j) {
    c.full[j] = take(Eigen::Vector3d::Unit(j));
    for (int step = 1; step < 8; ++step) c.ramp[j][step - 1] = take(ramp_level(step) * Eigen::Vector3d::Unit(j));
  }
  if (grey)
    for (int step = 1; step < 8; ++step) c.grey[step - 1] = take(Eigen::Vector3d::Constant(ramp_level(step)));
  return c;
}

Eigen::Vector3d linear(const Eigen::Vector3d& v, double camera_gamma) {
  Eigen::Vector3d l;
  for (int ch = 0; ch < 3; ++ch) l[ch] = std::pow(std::clamp(v[ch], 0.0, 255.0) / 255.0, camera_gamma);
  return l;
}

// How far light fails to add up at camera gamma g: at each ramp level and full, in each camera channel,
// the grey's light above black less the three primaries' at that level, as a share of white's; the RMS.
double additivity_rms(const Captures& c, double g) {
  const Eigen::Vector3d black = linear(c.black, g), white = linear(c.white, g) - black;
  double sum = 0.0;
  for (int step = 1; step <= 8; ++step) {
    Eigen::Vector3d rest = linear(step == 8 ? c.white : c.grey[step - 1], g) - black;
    for (int j = 0; j < 3; ++j) rest -= linear(step == 8 ? c.full[j] : c.ramp[j][step - 1], g) - black;
    sum += rest.cwiseQuotient(white).squaredNorm();
  }
  return std::sqrt(sum / 24.0);
}

// The camera's gamma from the same captures: the projector's light adds up (grey = red + green + blue
// at the same input, in light), and only the right gamma makes the camera's values add up too. Its
// primaries' crosstalk into the camera's other channels is what tells: a projector whose primaries the
// camera sees each in one channel only cannot. Refused when light does not add up at any gamma (a
// colour wheel's white segment; exposure or white balance moving) or the fit cannot tell.
double camera_gamma_from_colours(const Captures& c) {
  double best = kLeastCameraGamma, best_rms = additivity_rms(c, best);
  for (double g = kLeastCameraGamma + 0.01; g <= kMostCameraGamma + 1e-9; g += 0.01)
    if (const double rms = additivity_rms(c, g); rms < best_rms) best = g, best_rms = rms;
  if (best < kLeastCameraGamma + 0.005 || best > kMostCameraGamma - 0.005) {
    char edge[160];
    std::snprintf(edge, sizeof edge,
                  "photometric: the camera's values add up best at gamma %.2f, the edge of what a camera's response can "
                  "be: give the camera's gamma",
                  best);
    throw CalibrationError(edge);
  }
  double lo = best - 0.01, hi = best + 0.01;
  for (int i = 0; i < 40; ++i) {  // golden section on the scan's bracket
    const double a = hi - 0.618 * (hi - lo), b = lo + 0.618 * (hi - lo);
    if (additivity_rms(c, a) < additivity_rms(c, b))
      hi = b;
    else
      lo = a;
  }
  best = 0.5 * (lo + hi), best_rms = additivity_rms(c, best);
  char said[96];
  std::snprintf(said, sizeof said, " (at best %.2f %% of white off, at gamma %.2f)", 100.0 * best_rms, best);
  if (best_rms > kMostAdditivityRms)
    throw CalibrationError(std::string("photometric: the projector's colours do not add up to its grey and white in the camera") +
                           said +
                           ": a colour wheel with a white segment, the camera's exposure or white balance moving, or a "
                           "camera too noisy; give the camera's gamma");
  const double rise = std::min(additivity_rms(c, 0.9 * best), additivity_rms(c, 1.1 * best)) - best_rms;
  if (!(rise > kLeastAdditivityRise))
    throw CalibrationError(std::string("photometric: the camera sees each of the projector's primaries in one channel only, so "
                                       "how its colours add up cannot tell the camera's response") +
                           said + ": give the camera's gamma");
  return best;
}

struct RampFit {
  double gamma = 0.0;
  double residual = 0.0;  // RMS of share - level^gamma over the ramp's steps, in shares of full light
};

// Gamma from one channel's ramp, its light as a share of full at each step: log(share) = gamma log(level),
// through the origin (black's light is subtracted with the black capture, so the curve has no offset).
RampFit fit_ramp(const std::array<double, 7>& shares, int channel) {
  double num = 0.0, den = 0.0;
  for (int step = 1; step < 8; ++step) {
    const double share = shares[static_cast<std::size_t>(step - 1)];
    if (!(share > 1e-3)) continue;
    num += std::log(share) * std::log(ramp_level(step)), den += std::log(ramp_level(step)) * std::log(ramp_level(step));
  }
  if (!(den > 0.0) || !(num / den > 0.5 && num / den < 5.0))
    throw CalibrationError("photometric: channel " + std::to_string(channel) + "'s ramp gives no response to fit");
  RampFit fit{num / den, 0.0};
  double sq = 0.0;
  for (int step = 1; step < 8; ++step)
    sq += std::pow(shares[static_cast<std::size_t>(step - 1)] - std::pow(ramp_level(step), fit.gamma), 2);
  fit.residual = std::sqrt(sq / 7.0);
  return fit;
}

}  // namespace

PhotometricResult calibrate_photometric(PhotometricRig& rig, double black_level, const CameraResponseOptions& camera) {
  PhotometricResult r;
  if (camera.from_colours) {
    if (camera.gamma > 0.0) throw std::invalid_argument("calibrate_photometric: a camera gamma given and to be measured");
  } else if (camera.gamma > 0.0) {
    r.camera_gamma = camera.gamma;
  } else if (rig.brackets()) {
    r.camera_gamma = camera_gamma(rig, r.captures);
    r.camera_response = CameraResponse::exposure_brackets;
  } else {
    throw CalibrationError(
        "photometric: this camera cannot set its exposure, so its response cannot be measured from brackets: give it, or "
        "measure it from the projector's colours adding up");
  }
  const Captures c = capture(rig, camera.from_colours, r.captures);
  if (camera.from_colours) {
    r.camera_gamma = camera_gamma_from_colours(c);
    r.camera_response = CameraResponse::colours_adding_up;
  }
  const Eigen::Vector3d black = linear(c.black, r.camera_gamma);
  const Eigen::Vector3d white = linear(c.white, r.camera_gamma) - black;
  if (!(white.minCoeff() > 1e-3))
    throw CalibrationError("photometric: the projector's white is no brighter than its black in the camera (light " +
                           levels(255.0 * white) + " above black): is its light in the camera's view?");
  r.projector.black_level = black_level;
  for (int j = 0; j < 3; ++j) {
    // Mixing: channel j's light in each camera channel, as a share of white's there (rows sum to 1).
    const Eigen::Vector3d full = linear(c.full[j], r.camera_gamma) - black;
    r.projector.mixing.col(j) = full.cwiseQuotient(white);
    std::array<double, 7> shares{};
    for (int step = 1; step < 8; ++step)
      shares[static_cast<std::size_t>(step - 1)] = (linear(c.ramp[j][step - 1], r.camera_gamma) - black)[j] / full[j];
    const RampFit fit = fit_ramp(shares, j);
    r.projector.gamma_rgb[static_cast<std::size_t>(j)] = fit.gamma;
    r.ramp_residual = std::max(r.ramp_residual, fit.residual);
  }
  r.projector.gamma = (r.projector.gamma_rgb[0] + r.projector.gamma_rgb[1] + r.projector.gamma_rgb[2]) / 3.0;
  if (r.ramp_residual > kMaxRampResidual) {
    char said[256];
    std::snprintf(said, sizeof said,
                  "photometric: the ramps miss their fitted curves by %.1f %% of full light (RMS, worst channel; allowed "
                  "%.0f %%): white is only %s camera levels above black. The room's light drowns the projector's: darken "
                  "the room, or bring the projector nearer the surface",
                  100.0 * r.ramp_residual, 100.0 * kMaxRampResidual, levels(c.white - c.black).c_str());
    throw CalibrationError(said);
  }
  return r;
}

const char* to_string(CameraResponse from) {
  switch (from) {
    case CameraResponse::given:
      return "as given";
    case CameraResponse::exposure_brackets:
      return "from exposure brackets";
    case CameraResponse::colours_adding_up:
      return "from the colours adding up";
  }
  return "?";
}

Eigen::Matrix3d typical_mixing() {
  Eigen::Matrix3d m;
  m << 0.94, 0.05, 0.01, 0.04, 0.92, 0.04, 0.01, 0.06, 0.93;
  return m;
}

namespace {

class TwinPhotometricRig final : public PhotometricRig {
 public:
  explicit TwinPhotometricRig(const PhotometricSim& sim) : sim_(sim), rng_(sim.seed) {
    // The patch on the projector's axis 1.5 m away, facing it: full white's lux there; the camera exposed
    // so that white fills 90 % of its range at exposure 1.
    white_lux_ = engine::white_lux(sim.projector, {0.0, 0.0, 1.5}, {0.0, 0.0, -1.0});
    scale_ = 0.9 / (kAlbedo * (sim.ambient_lux + white_lux_ * (1.0 + sim.white_segment)));
  }
  bool brackets() const override { return sim_.brackets; }
  Eigen::Vector3d show_and_measure(const Eigen::Vector3d& input, double exposure) override {
    const config::Photometry& truth = sim_.projector.photometry;
    double dimmest = 1.0;  // a white segment's light: as much as the dimmest channel asks for
    for (int ch = 0; ch < 3; ++ch)
      dimmest = std::min(dimmest, std::pow(input[ch], truth.gamma_rgb[static_cast<std::size_t>(ch)]));
    const Eigen::Vector3d lux =
        Eigen::Vector3d::Constant(sim_.ambient_lux) +
        white_lux_ * (engine::light(truth, input) + Eigen::Vector3d::Constant(sim_.white_segment * dimmest));
    std::normal_distribution<double> noise(0.0, sim_.noise_levels);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    constexpr int kPixels = 32 * 32;
    for (int p = 0; p < kPixels; ++p)
      for (int ch = 0; ch < 3; ++ch) {
        const double x = std::clamp(exposure * scale_ * kAlbedo * lux[ch], 0.0, 1.0);
        mean[ch] += std::clamp(std::round(255.0 * std::pow(x, 1.0 / sim_.camera_gamma) + noise(rng_)), 0.0, 255.0);
      }
    return mean / kPixels;
  }

 private:
  static constexpr double kAlbedo = 0.8;
  PhotometricSim sim_;
  std::mt19937_64 rng_;
  double white_lux_ = 0.0, scale_ = 1.0;
};

}  // namespace

std::unique_ptr<PhotometricRig> make_twin_photometric_rig(const PhotometricSim& sim) {
  return std::make_unique<TwinPhotometricRig>(sim);
}

void write_photometric(const PhotometricResult& r, const std::filesystem::path& path, const std::string& comment) {
  std::ostringstream y;
  y.precision(6);
  const auto& p = r.projector;
  y << "# " << comment << "\n"
    << "# The projector's response per channel (input c gives black + (1 - black) c^gamma of its light) and its\n"
    << "# colour mixing (column j: channel j's light in the camera's R, G, B; rows sum to 1).\n"
    << "photometry:\n"
    << "  gamma: " << p.gamma << "\n"
    << "  gamma_rgb: [" << p.gamma_rgb[0] << ", " << p.gamma_rgb[1] << ", " << p.gamma_rgb[2] << "]\n"
    << "  black_level: " << p.black_level << "\n"
    << "  mixing: [";
  for (int i = 0; i < 9; ++i) y << (i ? ", " : "") << p.mixing(i / 3, i % 3);
  y << "]\n  camera_gamma: " << r.camera_gamma << "\n";
  config::write_file_atomically(path, y.str());
}

PhotometricDifference compare(const PhotometricResult& r, const PhotometricSim& sim) {
  const config::Photometry& truth = sim.projector.photometry;
  PhotometricDifference d;
  for (std::size_t j = 0; j < 3; ++j)
    d.gamma_share = std::max(d.gamma_share, std::abs(r.projector.gamma_rgb[j] / truth.gamma_rgb[j] - 1.0));
  d.mixing = (r.projector.mixing - truth.mixing).cwiseAbs().maxCoeff();
  return d;
}

}  // namespace projbot::calibrate
