#include "projbot/calibrate/photometric.hpp"

#include <algorithm>
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

}  // namespace

PhotometricResult calibrate_photometric(PhotometricRig& rig, double black_level, double given_camera_gamma) {
  PhotometricResult r;
  if (given_camera_gamma > 0.0) {
    r.camera_gamma = given_camera_gamma;
  } else if (!rig.brackets()) {
    throw CalibrationError("photometric: this camera cannot set its exposure, so its response cannot be measured: give it");
  } else {
    r.camera_gamma = camera_gamma(rig, r.captures);
    r.camera_gamma_measured = true;
  }
  const auto linear = [&](const Eigen::Vector3d& input) {
    ++r.captures;
    const Eigen::Vector3d v = rig.show_and_measure(input, 1.0);
    if (v.maxCoeff() > 250.0)
      throw CalibrationError("photometric: the camera saturates under input " + levels(input * 255.0) + " (it reads " +
                             levels(v) + "): lower its exposure, or aim the projector at a darker surface");
    Eigen::Vector3d l;
    for (int ch = 0; ch < 3; ++ch) l[ch] = std::pow(std::clamp(v[ch], 0.0, 255.0) / 255.0, r.camera_gamma);
    return l;
  };
  const Eigen::Vector3d black = linear(Eigen::Vector3d::Zero());
  const Eigen::Vector3d white = linear(Eigen::Vector3d::Ones()) - black;
  if (!(white.minCoeff() > 1e-3))
    throw CalibrationError("photometric: the projector's white is no brighter than its black in the camera (light " +
                           levels(255.0 * white) + " above black): is its light in the camera's view?");
  r.projector.black_level = black_level;
  for (int j = 0; j < 3; ++j) {
    // Mixing: channel j's light in each camera channel, as a share of white's there (rows sum to 1).
    const Eigen::Vector3d full = linear(Eigen::Vector3d::Unit(j)) - black;
    r.projector.mixing.col(j) = full.cwiseQuotient(white);
    // Gamma: the ramp in the channel's own camera channel, log(share) = gamma log(c), through the origin.
    double num = 0.0, den = 0.0;
    for (int step = 1; step < 8; ++step) {
      const double c = std::round(255.0 * step / 8.0) / 255.0;  // what an 8-bit projector input shows
      const double share = (linear(c * Eigen::Vector3d::Unit(j)) - black)[j] / full[j];
      if (!(share > 1e-3)) continue;
      // The response's black offset: share = (c^gamma (1 - black) ) / (1 - black) exactly, since black's
      // light is subtracted with the black capture.
      num += std::log(share) * std::log(c), den += std::log(c) * std::log(c);
    }
    if (!(den > 0.0) || !(num / den > 0.5 && num / den < 5.0))
      throw CalibrationError("photometric: channel " + std::to_string(j) + "'s ramp gives no response to fit");
    r.projector.gamma_rgb[static_cast<std::size_t>(j)] = num / den;
  }
  r.projector.gamma = (r.projector.gamma_rgb[0] + r.projector.gamma_rgb[1] + r.projector.gamma_rgb[2]) / 3.0;
  return r;
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
    scale_ = 0.9 / (kAlbedo * (sim.ambient_lux + white_lux_));
  }
  Eigen::Vector3d show_and_measure(const Eigen::Vector3d& input, double exposure) override {
    const Eigen::Vector3d lux =
        Eigen::Vector3d::Constant(sim_.ambient_lux) + white_lux_ * engine::light(sim_.projector.photometry, input);
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
