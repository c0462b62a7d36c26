#include "projbot/twin/appearance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "projbot/alignment/equations.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/twin/world.hpp"

namespace projbot::twin {

Eigen::Vector3d srgb_to_lab(const Eigen::Vector3d& srgb) {
  const Eigen::Vector3d lin(engine::srgb_to_linear(srgb[0]), engine::srgb_to_linear(srgb[1]), engine::srgb_to_linear(srgb[2]));
  Eigen::Matrix3d M;  // linear sRGB -> XYZ (D65), IEC 61966-2-1
  M << 0.4124564, 0.3575761, 0.1804375, 0.2126729, 0.7151522, 0.0721750, 0.0193339, 0.1191920, 0.9503041;
  const Eigen::Vector3d xyz = (M * lin).cwiseQuotient(Eigen::Vector3d(0.95047, 1.0, 1.08883));
  const auto f = [](double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16.0) / 116.0; };
  const double fx = f(xyz[0]), fy = f(xyz[1]), fz = f(xyz[2]);
  return {116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)};
}

double ciede2000(const Eigen::Vector3d& lab1, const Eigen::Vector3d& lab2) {
  constexpr double kPi = std::numbers::pi, kDeg = kPi / 180.0;
  const double C1 = std::hypot(lab1[1], lab1[2]), C2 = std::hypot(lab2[1], lab2[2]);
  const double Cm7 = std::pow((C1 + C2) / 2.0, 7.0);
  const double G = 0.5 * (1.0 - std::sqrt(Cm7 / (Cm7 + std::pow(25.0, 7.0))));
  const double a1 = (1.0 + G) * lab1[1], a2 = (1.0 + G) * lab2[1];
  const double c1 = std::hypot(a1, lab1[2]), c2 = std::hypot(a2, lab2[2]);
  const auto hue = [&](double b, double a) {
    if (a == 0.0 && b == 0.0) return 0.0;
    const double h = std::atan2(b, a);
    return h < 0.0 ? h + 2.0 * kPi : h;
  };
  const double h1 = hue(lab1[2], a1), h2 = hue(lab2[2], a2);
  const double dL = lab2[0] - lab1[0], dC = c2 - c1;
  double dh = 0.0;
  if (c1 * c2 != 0.0) {
    dh = h2 - h1;
    if (dh > kPi) dh -= 2.0 * kPi;
    if (dh < -kPi) dh += 2.0 * kPi;
  }
  const double dH = 2.0 * std::sqrt(c1 * c2) * std::sin(dh / 2.0);
  const double Lm = (lab1[0] + lab2[0]) / 2.0, Cm = (c1 + c2) / 2.0;
  double hm = h1 + h2;
  if (c1 * c2 != 0.0) {
    hm = std::abs(h1 - h2) <= kPi ? (h1 + h2) / 2.0
                                  : (h1 + h2 < 2.0 * kPi ? (h1 + h2 + 2.0 * kPi) / 2.0 : (h1 + h2 - 2.0 * kPi) / 2.0);
  }
  const double T = 1.0 - 0.17 * std::cos(hm - 30.0 * kDeg) + 0.24 * std::cos(2.0 * hm) + 0.32 * std::cos(3.0 * hm + 6.0 * kDeg) -
                   0.20 * std::cos(4.0 * hm - 63.0 * kDeg);
  const double dTheta = 30.0 * kDeg * std::exp(-std::pow((hm / kDeg - 275.0) / 25.0, 2.0));
  const double Cm7b = std::pow(Cm, 7.0);
  const double Rc = 2.0 * std::sqrt(Cm7b / (Cm7b + std::pow(25.0, 7.0)));
  const double Sl = 1.0 + 0.015 * (Lm - 50.0) * (Lm - 50.0) / std::sqrt(20.0 + (Lm - 50.0) * (Lm - 50.0));
  const double Sc = 1.0 + 0.045 * Cm, Sh = 1.0 + 0.015 * Cm * T;
  const double Rt = -std::sin(2.0 * dTheta) * Rc;
  const double l = dL / Sl, c = dC / Sc, h = dH / Sh;
  return std::sqrt(l * l + c * c + h * h + Rt * c * h);
}

namespace {

// A pixel whose best input is this far (CIEDE2000) from the content is beyond the projector's reach: about
// the difference an observer starts to notice side by side.
constexpr double kReachableDe = 2.0;

double luma(const std::uint8_t* p) { return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]; }

// SSIM's map averaged over the masked pixels: an 11 x 11 Gaussian window (sigma 1.5), C1 = (0.01 255)^2,
// C2 = (0.03 255)^2, on luma.
double mean_ssim(const assets::Image& a, const assets::Image& b, const std::vector<std::uint8_t>& mask) {
  constexpr int kR = 5;
  double w[2 * kR + 1], sum = 0.0;
  for (int i = -kR; i <= kR; ++i) sum += (w[i + kR] = std::exp(-i * i / (2.0 * 1.5 * 1.5)));
  for (double& x : w) x /= sum;
  const double C1 = std::pow(0.01 * 255, 2), C2 = std::pow(0.03 * 255, 2);
  double total = 0.0;
  std::size_t n = 0;
  for (int y = kR; y < a.height - kR; ++y)
    for (int x = kR; x < a.width - kR; ++x) {
      if (!mask[static_cast<std::size_t>(y) * a.width + x]) continue;
      double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
      for (int dy = -kR; dy <= kR; ++dy)
        for (int dx = -kR; dx <= kR; ++dx) {
          const double g = w[dy + kR] * w[dx + kR], la = luma(a.pixel(x + dx, y + dy)), lb = luma(b.pixel(x + dx, y + dy));
          ma += g * la, mb += g * lb, saa += g * la * la, sbb += g * lb * lb, sab += g * la * lb;
        }
      const double va = saa - ma * ma, vb = sbb - mb * mb, cov = sab - ma * mb;
      total += ((2 * ma * mb + C1) * (2 * cov + C2)) / ((ma * ma + mb * mb + C1) * (va + vb + C2));
      ++n;
    }
  return n ? total / static_cast<double>(n) : 0.0;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  const auto nth = v.begin() + static_cast<std::ptrdiff_t>(std::lround(p * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), nth, v.end());
  return *nth;
}

}  // namespace

AppearanceScore score_appearance(const SpectatorPicture& seen, const ContentView& view, double k, double ambient_lux,
                                 const config::Photometry& photometry) {
  AppearanceScore s;
  assets::Image wanted = seen.image;  // off the target the two pictures agree, so SSIM's windows see only it
  std::vector<std::uint8_t> scored(seen.white_lux.size(), 0);
  std::vector<double> de;
  double squared = 0.0;
  std::size_t clipped = 0, unreachable = 0;
  const Eigen::Matrix3d unmix = photometry.mixing.inverse();
  for (std::size_t i = 0; i < scored.size(); ++i) {
    const double white = seen.white_lux[i];
    if (!view.mask[i] || !(white > 0.0)) continue;
    scored[i] = 1;
    ++s.pixels;
    std::uint8_t* w = wanted.rgba.data() + 4 * i;
    const std::uint8_t* got = seen.image.rgba.data() + 4 * i;
    const std::uint8_t* c = view.content.rgba.data() + 4 * i;
    Eigen::Vector3d want, needed, rho;  // sRGB wanted; the lux the projector must add per colour channel
    for (int ch = 0; ch < 3; ++ch) {
      const double target = k * engine::srgb_to_linear(c[ch] / 255.0);
      w[ch] = static_cast<std::uint8_t>(std::lround(255.0 * engine::linear_to_srgb(target)));
      want[ch] = w[ch] / 255.0;
      rho[ch] = std::max(engine::srgb_to_linear(seen.albedo.rgba[4 * i + ch] / 255.0), 1e-4);
      needed[ch] = target * engine::kReferenceLux / rho[ch] - ambient_lux;
      squared += std::pow(static_cast<double>(w[ch]) - got[ch], 2);
    }
    // The channels' drives that light needs, and the nearest any input gets: each clamped between black
    // and full, mixed back.
    const Eigen::Vector3d drives = unmix * needed / white;
    const bool over = drives.maxCoeff() > 1.0 + 1e-6;
    const Eigen::Vector3d added = white * photometry.mixing * drives.cwiseMax(photometry.black_level).cwiseMin(1.0);
    Eigen::Vector3d best;
    for (int ch = 0; ch < 3; ++ch) best[ch] = engine::linear_to_srgb(rho[ch] * (ambient_lux + added[ch]) / engine::kReferenceLux);
    // Unreachable: even the best input leaves a visible difference (the room's light on a colour with
    // no blue, a surface too dark for the content).
    const bool reachable = ciede2000(srgb_to_lab(want), srgb_to_lab(best)) <= kReachableDe;
    clipped += over ? 1 : 0;
    unreachable += reachable ? 0 : 1;
    if (reachable) de.push_back(ciede2000(srgb_to_lab(want), srgb_to_lab(Eigen::Vector3d(got[0], got[1], got[2]) / 255.0)));
  }
  if (s.pixels == 0) return s;
  const double mse = squared / (3.0 * static_cast<double>(s.pixels));
  s.psnr_db = mse > 0.0 ? 10.0 * std::log10(255.0 * 255.0 / mse) : 99.0;
  s.ssim = mean_ssim(seen.image, wanted, scored);
  s.de2000_median = percentile(de, 0.5);
  s.de2000_p95 = percentile(de, 0.95);
  s.clipped_share = static_cast<double>(clipped) / static_cast<double>(s.pixels);
  s.unreachable_share = static_cast<double>(unreachable) / static_cast<double>(s.pixels);
  return s;
}

double saturated_share(const assets::Image& on, const assets::Image& off) {
  if (on.rgba.size() != off.rgba.size()) throw std::invalid_argument("saturated_share: frames of different sizes");
  std::size_t target = 0, saturated = 0;
  for (std::size_t i = 0; i + 3 < on.rgba.size(); i += 4) {
    const std::uint8_t* a = on.rgba.data() + i;
    const std::uint8_t* b = off.rgba.data() + i;
    if (!(a[0] | a[1] | a[2] | b[0] | b[1] | b[2])) continue;
    ++target;
    saturated += std::max({a[0], a[1], a[2]}) >= 254 ? 1 : 0;
  }
  return target ? static_cast<double>(saturated) / static_cast<double>(target) : 0.0;
}

std::vector<engine::ReflectancePoint> measured_reflectance(SpectatorView& camera, Twin& twin, std::size_t target,
                                                           const Eigen::Matrix4d& T_world_camera,
                                                           const Eigen::Matrix4d& T_world_projector,
                                                           const Eigen::Matrix4d& T_camera_target,
                                                           const config::ProjectorConfig& believed,
                                                           const Eigen::Matrix4d& T_projector_target) {
  constexpr std::uint8_t kGrey = 128;
  const config::ProjectorConfig& p = twin.scene().projector;
  const SpectatorScene seen = camera.look(twin, T_world_camera, T_world_projector);
  const assets::Image black = camera.light(seen, uniform_frame(p, {0, 0, 0})).image;
  const assets::Image grey = camera.light(seen, uniform_frame(p, {kGrey, kGrey, kGrey})).image;
  return engine::reflectance_points(twin.targets().at(target).model, twin.camera_pinhole(), T_camera_target, believed,
                                    T_projector_target, black, grey, kGrey / 255.0);
}

ReflectanceSurvey::ReflectanceSurvey(Twin& twin, engine::Renderer& renderer)
    : twin_(twin), camera_(renderer, twin.scene().projector, twin.camera_pinhole()) {}

std::size_t ReflectanceSurvey::measure(const std::string& name, const Eigen::Matrix4d& T_camera_target) {
  const config::Scene& scene = twin_.scene();
  const robot::HeadPoses truth = twin_.true_head();
  const Eigen::Matrix4d T_projector_target = alignment::projector_from_target(scene.pan_tilt.T_projector_camera, T_camera_target);
  const std::vector<engine::ReflectancePoint> points =
      measured_reflectance(camera_, twin_, twin_.target_index(name), truth.T_world_camera.matrix(),
                           truth.T_world_projector.matrix(), T_camera_target, scene.projector, T_projector_target);
  maps_[name].add(points);
  return points.size();
}

std::map<std::string, ReflectanceSurvey::Learnt> ReflectanceSurvey::learnt() const {
  std::map<std::string, Learnt> out;
  for (const auto& [name, map] : maps_) {
    const std::optional<Eigen::Vector3d> albedo = map.median();
    if (!albedo) continue;
    Learnt& l = out[name];
    l.albedo = *albedo;
    if (assets::has_texture_coordinates(twin_.targets().at(twin_.target_index(name)).model)) l.map = map.image();
  }
  return out;
}

}  // namespace projbot::twin
