#include "projbot/engine/photometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace projbot::engine {

double srgb_to_linear(double c) {
  c = std::clamp(c, 0.0, 1.0);
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

double linear_to_srgb(double l) {
  l = std::clamp(l, 0.0, 1.0);
  return l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
}

double white_gain(const config::ProjectorConfig& p) {
  return p.photometry.brightness_lm * p.fx_px * p.fy_px / (static_cast<double>(p.width_px) * p.height_px);
}

double white_lux(const config::ProjectorConfig& p, const Eigen::Vector3d& q, const Eigen::Vector3d& n) {
  const double r = q.norm(), nn = n.norm();
  if (!(q.z() > 0.0) || !(r > 0.0) || !(nn > 0.0)) return 0.0;
  // A pixel's footprint on the plane z = const is (z/fx)(z/fy); a surface tilted to the ray gets the
  // pixel's flux over that footprint times cos(incidence) / cos(ray to the axis).
  const double cos_incidence = std::abs(q.dot(n)) / (r * nn), cos_axis = q.z() / r;
  return white_gain(p) * cos_incidence / (q.z() * q.z() * cos_axis);
}

Eigen::Vector3d drive(const config::Photometry& ph, const Eigen::Vector3d& c) {
  Eigen::Vector3d d;
  for (int i = 0; i < 3; ++i)
    d[i] =
        ph.black_level + (1.0 - ph.black_level) * std::pow(std::clamp(c[i], 0.0, 1.0), ph.gamma_rgb[static_cast<std::size_t>(i)]);
  return d;
}

Eigen::Vector3d light(const config::Photometry& ph, const Eigen::Vector3d& c) { return ph.mixing * drive(ph, c); }

Compensation compensation(const Eigen::Vector3d& albedo, double ambient_lux, double k) {
  Compensation comp;
  comp.on = true;
  for (int i = 0; i < 3; ++i)
    comp.scale_lux[static_cast<std::size_t>(i)] = static_cast<float>(k * kReferenceLux / std::max(albedo[i], 1e-3));
  comp.ambient_lux = static_cast<float>(ambient_lux);
  return comp;
}

Eigen::Vector3d compensated_input(const config::ProjectorConfig& p, const Compensation& comp, const Eigen::Vector3d& c,
                                  const Eigen::Vector3d& q, const Eigen::Vector3d& n, bool* clipped) {
  const double white = white_lux(p, q, n);
  const config::Photometry& ph = p.photometry;
  // The light wanted per colour channel less the room's, as a share of full white here; unmixed into the
  // channels' drives; through the inverse response.
  Eigen::Vector3d wanted;
  for (int i = 0; i < 3; ++i) {
    const double needed = comp.scale_lux[static_cast<std::size_t>(i)] * srgb_to_linear(c[i]) - comp.ambient_lux;
    wanted[i] = white > 0.0 ? needed / white : (needed > 0.0 ? 2.0 : 0.0);
  }
  const Eigen::Vector3d d = ph.mixing.inverse() * wanted;
  Eigen::Vector3d out;
  bool clip = false;
  for (int i = 0; i < 3; ++i) {
    const double x = (d[i] - ph.black_level) / (1.0 - ph.black_level);
    clip = clip || x > 1.0 + 1e-6 || x < -1e-6;
    out[i] = std::pow(std::clamp(x, 0.0, 1.0), 1.0 / ph.gamma_rgb[static_cast<std::size_t>(i)]);
  }
  if (clipped) *clipped = clip;
  return out;
}

namespace {

// A vertex's content: what the renderer draws there (assets::surface_colour at its UV and colour).
Eigen::Vector3d vertex_content(const assets::Model& model, int material, const assets::Vertex& v) {
  return assets::surface_colour(model, material, v.uv[0], v.uv[1], Eigen::Vector3f(v.color[0], v.color[1], v.color[2]))
      .cast<double>();
}

// A vertex's surface reflectance, linear, from the surface texture at its UV.
Eigen::Vector3d surface_reflectance(const assets::Image& surface, const assets::Vertex& v) {
  const Eigen::Vector3f c = assets::texel_colour(surface, v.uv[0], v.uv[1]);
  return {srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2])};
}

}  // namespace

namespace {

// A point of a triangle at barycentric weights (1 - u - v, u, v) of its corners a, b, c: the vertex the
// renderer interpolates there (texture coordinates and colour).
assets::Vertex vertex_between(const assets::Vertex& a, const assets::Vertex& b, const assets::Vertex& c, double u, double v) {
  const auto mix = [&](float x, float y, float z) { return static_cast<float>((1.0 - u - v) * x + u * y + v * z); };
  assets::Vertex out;
  for (std::size_t k = 0; k < 2; ++k) out.uv[k] = mix(a.uv[k], b.uv[k], c.uv[k]);
  for (std::size_t k = 0; k < 4; ++k) out.color[k] = mix(a.color[k], b.color[k], c.color[k]);
  return out;
}

// Points spread over a triangle that covers `area_px` pixels, one per `px_per_point` of them, at most
// `most_per_side` along a side: the middles of an m x m subdivision's upright cells, as barycentric
// weights of its second and third corner.
std::vector<Eigen::Vector2d> cell_middles(double area_px, double px_per_point, int most_per_side) {
  const int m = std::clamp(static_cast<int>(std::ceil(std::sqrt(area_px / px_per_point))), 1, most_per_side);
  std::vector<Eigen::Vector2d> out;
  for (int i = 0; i < m; ++i)
    for (int j = 0; i + j < m; ++j) out.emplace_back((i + 1.0 / 3.0) / m, (j + 1.0 / 3.0) / m);
  return out;
}

}  // namespace

std::vector<SurfaceSample> surface_samples(const assets::Model& model, const config::ProjectorConfig& p,
                                           const Eigen::Matrix4d& T_projector_target, const assets::Image* surface) {
  std::vector<SurfaceSample> out;
  const Eigen::Matrix3d R = T_projector_target.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T_projector_target.topRightCorner<3, 1>();
  for (const assets::Primitive& prim : model.primitives) {
    const assets::Material& m = model.materials.at(static_cast<std::size_t>(prim.material));
    const auto at = [&](std::uint32_t k) {
      const auto& x = prim.vertices.at(k).position;
      return Eigen::Vector3d(R * Eigen::Vector3d(x[0], x[1], x[2]) + t);
    };
    for (std::size_t f = 0; f + 2 < prim.indices.size(); f += 3) {
      const std::uint32_t a = prim.indices[f], b = prim.indices[f + 1], c = prim.indices[f + 2];
      const Eigen::Vector3d qa = at(a), qb = at(b), qc = at(c), q = (qa + qb + qc) / 3.0;
      const Eigen::Vector3d n = (qb - qa).cross(qc - qa);  // twice the area, facing out (counter-clockwise)
      if (!(q.z() > p.near_m) || (!m.double_sided && n.dot(q) >= 0.0)) continue;  // behind, or facing away
      const Eigen::Vector2d x = p.project(q);
      if (x.x() < -0.5 || x.y() < -0.5 || x.x() > p.width_px - 0.5 || x.y() > p.height_px - 0.5) continue;
      const double solid_angle = std::abs(n.dot(q)) / (2.0 * q.norm() * q.squaredNorm());  // the projector's pixels on it
      if (!(solid_angle > 0.0)) continue;
      // Its content and print where the renderer samples them, spread over it (a texture varies inside a
      // triangle: its corners alone miss what a large one shows).
      // About one per 11 x 11 projector pixels (m = sqrt(area / 64) a side, upright cells), at most 36.
      const std::vector<Eigen::Vector2d> points = cell_middles(solid_angle * p.fx_px * p.fy_px, 64.0, 8);
      for (const Eigen::Vector2d& w : points) {
        const assets::Vertex v = vertex_between(prim.vertices[a], prim.vertices[b], prim.vertices[c], w.x(), w.y());
        SurfaceSample s;
        s.content = vertex_content(model, prim.material, v);
        if (surface) s.reflectance = surface_reflectance(*surface, v);
        s.white_lux = white_lux(p, (1.0 - w.x() - w.y()) * qa + w.x() * qb + w.y() * qc, n);
        s.weight = solid_angle / static_cast<double>(points.size());
        out.push_back(s);
      }
    }
  }
  return out;
}

double choose_gain(const std::vector<SurfaceSample>& samples, const Eigen::Vector3d& albedo, double ambient_lux,
                   double clip_share, const Eigen::Matrix3d& mixing) {
  // Per sample, the largest k it can show: the drives M^-1 (k u - ambient) / white stay <= 1, where
  // u = kReferenceLux linear(c) / albedo (without mixing: rho (ambient + white) / (kReferenceLux c)).
  const Eigen::Matrix3d unmix = mixing.inverse();
  const Eigen::Vector3d room = unmix * Eigen::Vector3d::Constant(ambient_lux);
  std::vector<std::pair<double, double>> k_max;  // (k, weight)
  double total = 0.0;
  for (const SurfaceSample& s : samples) {
    Eigen::Vector3d u;
    for (int i = 0; i < 3; ++i)
      u[i] = kReferenceLux * srgb_to_linear(s.content[i]) / std::max(albedo[i] * s.reflectance[i], 1e-3);
    const Eigen::Vector3d per_drive = unmix * u;
    double k = 1e9;
    for (int j = 0; j < 3; ++j)
      if (per_drive[j] > 1e-6) k = std::min(k, (s.white_lux + room[j]) / per_drive[j]);
    if (k < 1e9 && s.weight > 0.0) {
      k_max.emplace_back(std::max(k, 0.0), s.weight);
      total += s.weight;
    }
  }
  // The largest k that leaves at most clip_share of the weight (the projector's pixels) below it.
  std::sort(k_max.begin(), k_max.end());
  double below = 0.0, k = 1.0;
  for (const auto& [k_s, w] : k_max) {
    k = k_s;
    if ((below += w) > clip_share * total) break;
  }
  return std::min(k, 1.0);  // never brighter than the content under the reference light
}

namespace {

// Points spread over a triangle (the middles of an m x m subdivision) as barycentric weights of its second
// and third corner, m from its size in the camera's image: about one point per 4 x 4 pixels, at most 256.
std::vector<Eigen::Vector2d> spread_over(const Eigen::Vector3d (&x)[3], const config::Camera& camera,
                                         const Eigen::Matrix4d& T_camera_target) {
  Eigen::Vector2d px[3];
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d q = T_camera_target.topLeftCorner<3, 3>() * x[k] + T_camera_target.topRightCorner<3, 1>();
    px[k] = q.z() > 0.1 ? camera.project(q) : Eigen::Vector2d::Zero();
  }
  const Eigen::Vector2d a = px[1] - px[0], b = px[2] - px[0];
  return cell_middles(0.5 * std::abs(a.x() * b.y() - a.y() * b.x()), 8.0, 16);
}

}  // namespace

std::vector<ReflectancePoint> reflectance_points(const assets::Model& model, const config::Camera& camera,
                                                 const Eigen::Matrix4d& T_camera_target, const config::ProjectorConfig& projector,
                                                 const Eigen::Matrix4d& T_projector_target, const assets::Image& under_black,
                                                 const assets::Image& under_grey, double grey) {
  std::vector<ReflectancePoint> out;
  if (under_black.width != camera.width_px || under_black.height != camera.height_px || under_grey.width != camera.width_px ||
      under_grey.height != camera.height_px || !(grey > 0.0 && grey <= 1.0))
    return out;
  const Eigen::Vector3d added =
      light(projector.photometry, Eigen::Vector3d::Constant(grey)) - light(projector.photometry, Eigen::Vector3d::Zero());
  const Eigen::Matrix3d Rc = T_camera_target.topLeftCorner<3, 3>(), Rp = T_projector_target.topLeftCorner<3, 3>();
  for (const assets::Primitive& prim : model.primitives)
    for (std::size_t f = 0; f + 2 < prim.indices.size(); f += 3) {
      Eigen::Vector3d x[3];
      Eigen::Vector2d uv[3];
      for (int k = 0; k < 3; ++k) {
        const assets::Vertex& vertex = prim.vertices.at(prim.indices[f + static_cast<std::size_t>(k)]);
        x[k] = Eigen::Vector3d(vertex.position[0], vertex.position[1], vertex.position[2]);
        uv[k] = Eigen::Vector2d(vertex.uv[0], vertex.uv[1]);
      }
      const Eigen::Vector3d n = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
      const Eigen::Vector3d nc = Rc * n, np = Rp * n;
      for (const Eigen::Vector2d& w : spread_over(x, camera, T_camera_target)) {
        const Eigen::Vector3d point = x[0] + w.x() * (x[1] - x[0]) + w.y() * (x[2] - x[0]);
        const Eigen::Vector3d qc = Rc * point + T_camera_target.topRightCorner<3, 1>();
        const Eigen::Vector3d qp = Rp * point + T_projector_target.topRightCorner<3, 1>();
        if (!n.allFinite() || !(qc.z() > 0.1) || !(qp.z() > 0.1) || nc.dot(qc) >= 0.0) break;  // hidden from the camera
        if (np.dot(qp) >= 0.0 || -np.dot(qp.normalized()) < 0.5) break;                        // away from the light, or grazing
        const Eigen::Vector2d px = camera.project(qc);
        const long u = std::lround(px.x()), v = std::lround(px.y());
        if (u < 1 || v < 1 || u >= camera.width_px - 1 || v >= camera.height_px - 1) continue;
        const Eigen::Vector3d lux = white_lux(projector, qp, np) * added;
        const std::uint8_t* b = under_black.pixel(static_cast<int>(u), static_cast<int>(v));
        const std::uint8_t* g = under_grey.pixel(static_cast<int>(u), static_cast<int>(v));
        ReflectancePoint r;
        r.uv = uv[0] + w.x() * (uv[1] - uv[0]) + w.y() * (uv[2] - uv[0]);
        for (int ch = 0; ch < 3; ++ch) {
          const double lifted = srgb_to_linear(g[ch] / 255.0) - srgb_to_linear(b[ch] / 255.0);
          r.rho[ch] = lifted * kReferenceLux / lux[ch];
          r.valid[static_cast<std::size_t>(ch)] = g[ch] < 250;  // not saturated
        }
        out.push_back(r);
      }
    }
  return out;
}

std::optional<Eigen::Vector3d> median_albedo(const std::vector<ReflectancePoint>& points) {
  Eigen::Vector3d median;
  for (int ch = 0; ch < 3; ++ch) {
    std::vector<double> r;
    for (const ReflectancePoint& p : points)
      if (p.valid[static_cast<std::size_t>(ch)]) r.push_back(p.rho[ch]);
    if (r.size() < 20) return std::nullopt;
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    median[ch] = std::clamp(r[r.size() / 2], 0.0, 1.0);
  }
  return median;
}

std::optional<Eigen::Vector3d> measure_albedo(const assets::Model& model, const config::Camera& camera,
                                              const Eigen::Matrix4d& T_camera_target, const config::ProjectorConfig& projector,
                                              const Eigen::Matrix4d& T_projector_target, const assets::Image& under_black,
                                              const assets::Image& under_grey, double grey) {
  return median_albedo(
      reflectance_points(model, camera, T_camera_target, projector, T_projector_target, under_black, under_grey, grey));
}

ReflectanceMap::ReflectanceMap(int width, int height)
    : width_(width), height_(height), texels_(static_cast<std::size_t>(width) * height) {}

std::size_t ReflectanceMap::texel_of(const ReflectancePoint& p) const {
  return static_cast<std::size_t>(assets::texel_index(p.uv.y(), height_)) * width_ + assets::texel_index(p.uv.x(), width_);
}

void ReflectanceMap::add(const std::vector<ReflectancePoint>& points) {
  // How many values of this measurement fall in each texel and channel: one that brings more than
  // kPerTexel keeps every stride-th, spread over all of them (a model without texture coordinates puts
  // every point in one texel: the newest 32 alone would be one corner of it).
  std::vector<std::array<std::size_t, 3>> count(texels_.size(), {0, 0, 0}), taken(texels_.size(), {0, 0, 0});
  for (const ReflectancePoint& p : points)
    if (p.uv.allFinite() && p.rho.allFinite())
      for (std::size_t ch = 0; ch < 3; ++ch) count[texel_of(p)][ch] += p.valid[ch] ? 1 : 0;
  for (const ReflectancePoint& p : points) {
    if (!p.uv.allFinite() || !p.rho.allFinite()) continue;
    const std::size_t i = texel_of(p);
    Texel& t = texels_[i];
    for (std::size_t ch = 0; ch < 3; ++ch) {
      if (!p.valid[ch]) continue;
      const std::size_t stride = (count[i][ch] + kPerTexel - 1) / kPerTexel;
      if (taken[i][ch]++ % stride != 0) continue;
      const auto v = static_cast<float>(p.rho[static_cast<int>(ch)]);
      if (t.values[ch].size() < kPerTexel)
        t.values[ch].push_back(v);
      else
        t.values[ch][t.kept[ch] % kPerTexel] = v;  // the oldest goes
      ++t.kept[ch];
    }
    if (recent_.size() < kFillPoints)
      recent_.push_back(p);
    else
      recent_[added_ % kFillPoints] = p;
    ++added_;
  }
}

std::size_t ReflectanceMap::values_kept() const {
  std::size_t n = recent_.size();
  for (const Texel& t : texels_)
    for (const auto& v : t.values) n += v.size();
  return n;
}

namespace {

// Each texel's median per channel; known: whether any value fell in it.
template <typename Texel>
void texel_medians(const std::vector<Texel>& texels, std::vector<Eigen::Vector3d>& rho, std::vector<Eigen::Vector3i>& known) {
  rho.assign(texels.size(), Eigen::Vector3d::Zero());
  known.assign(texels.size(), Eigen::Vector3i::Zero());
  std::vector<float> v;
  for (std::size_t i = 0; i < texels.size(); ++i)
    for (int ch = 0; ch < 3; ++ch) {
      v = texels[i].values[static_cast<std::size_t>(ch)];
      if (v.empty()) continue;
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      rho[i][ch] = v[v.size() / 2];
      known[i][ch] = 1;
    }
}

// Grows the known texels into the unknown ones a ring at a time (the mean of their known 4-neighbours,
// wrapping as the UVs repeat), so that a texel takes its nearest measurements in texture space.
void grow_known(int width, int height, std::vector<Eigen::Vector3d>& rho, std::vector<Eigen::Vector3i>& known) {
  for (int ring = 0; ring < width + height; ++ring) {
    std::vector<Eigen::Vector3d> next = rho;
    std::vector<Eigen::Vector3i> grown = known;
    bool changed = false;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const auto at = [&](int xx, int yy) {
          return static_cast<std::size_t>((yy + height) % height) * width + static_cast<std::size_t>((xx + width) % width);
        };
        const std::size_t i = at(x, y), around[4] = {at(x + 1, y), at(x - 1, y), at(x, y + 1), at(x, y - 1)};
        for (int ch = 0; ch < 3; ++ch) {
          if (known[i][ch]) continue;
          double sum = 0.0;
          int n = 0;
          for (const std::size_t j : around)
            if (known[j][ch]) sum += rho[j][ch], ++n;
          if (n > 0) next[i][ch] = sum / n, grown[i][ch] = 1, changed = true;
        }
      }
    rho.swap(next);
    known.swap(grown);
    if (!changed) return;
  }
}

}  // namespace

std::optional<assets::Image> ReflectanceMap::image() const {
  const std::optional<Eigen::Vector3d> fill = median_albedo(recent_);  // where no measurement reaches
  if (!fill) return std::nullopt;
  std::vector<Eigen::Vector3d> rho;
  std::vector<Eigen::Vector3i> known;
  texel_medians(texels_, rho, known);
  grow_known(width_, height_, rho, known);
  assets::Image out;
  out.width = width_, out.height = height_;
  out.rgba.reserve(rho.size() * 4);
  for (std::size_t i = 0; i < rho.size(); ++i) {
    for (int ch = 0; ch < 3; ++ch) {
      const double r = known[i][ch] ? std::clamp(rho[i][ch], 0.0, 1.0) : (*fill)[ch];
      out.rgba.push_back(static_cast<std::uint8_t>(std::lround(255.0 * linear_to_srgb(r))));
    }
    out.rgba.push_back(255);
  }
  return out;
}

void CompensationPlan::add_measured_albedo(std::size_t target, const Eigen::Vector3d& albedo) {
  Chosen& c = chosen_.at(target);
  if (targets_.at(target).surface) return;  // its texture stays
  Eigen::Vector3d& mean = targets_.at(target).albedo;
  mean = c.measurements == 0 ? albedo : Eigen::Vector3d((mean * c.measurements + albedo) / (c.measurements + 1));
  ++c.measurements;
  c.made = false;
}

void CompensationPlan::set_surface(std::size_t target, std::shared_ptr<const assets::Image> surface) {
  Target& t = targets_.at(target);
  t.surface = std::move(surface);
  t.albedo = Eigen::Vector3d::Ones();
  chosen_.at(target).made = false;
}

CompensationPlan::CompensationPlan(std::vector<Target> targets, double ambient_lux, bool on)
    : targets_(std::move(targets)), chosen_(targets_.size()), ambient_lux_(ambient_lux), on_(on) {}

double CompensationPlan::choose(std::size_t target, const config::ProjectorConfig& projector,
                                const Eigen::Matrix4d& T_projector_target) const {
  const Target& t = targets_.at(target);
  return t.model ? choose_gain(surface_samples(*t.model, projector, T_projector_target, t.surface.get()), t.albedo, ambient_lux_,
                               0.02, projector.photometry.mixing)
                 : 1.0;
}

// The gain in use moved towards the pose's own, at most kRatePerS, from when the two differ by more than
// kDeadband until it is there.
void CompensationPlan::follow(Chosen& c, std::size_t target, const config::ProjectorConfig& projector,
                              const Eigen::Matrix4d& T_projector_target, double display_s) const {
  if (std::isnan(c.chosen_s) || display_s < c.used_s) {  // chosen without a time, or the clock went back
    c.chosen_s = c.used_s = display_s;
    return;
  }
  if (display_s - c.chosen_s >= kRechooseS) {
    c.wanted = choose(target, projector, T_projector_target);
    c.chosen_s = display_s;
  }
  const double off = std::log(std::max(c.wanted, 1e-6) / std::max(c.gain, 1e-6));
  const double step = kRatePerS * (display_s - c.used_s);
  c.used_s = display_s;
  c.adjusting = c.adjusting || std::abs(off) > std::log1p(kDeadband);
  if (!c.adjusting) return;
  c.gain *= std::exp(std::clamp(off, -step, step));
  c.adjusting = std::abs(off) > step;  // until it gets there
}

Compensation CompensationPlan::at(std::size_t target, long visit, const config::ProjectorConfig& projector,
                                  const Eigen::Matrix4d& T_projector_target, double display_s) {
  if (!on_) return {};
  Chosen& c = chosen_.at(target);
  if (!c.made || c.visit != visit) {
    c.gain = c.wanted = choose(target, projector, T_projector_target);
    c.visit = visit;
    c.made = true;
    c.chosen_s = c.used_s = display_s;
    c.adjusting = false;
  } else if (!std::isnan(display_s)) {
    follow(c, target, projector, T_projector_target, display_s);
  }
  return compensation(targets_.at(target).albedo, ambient_lux_, c.gain);
}

}  // namespace projbot::engine
