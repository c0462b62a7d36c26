#include "projbot/assets/model.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>

#include "projbot/config/stop_request.hpp"

namespace projbot::assets {
namespace {

Eigen::Vector3d pos(const Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

// A texture coordinate wrapped into [0, 1] as the sampler says.
double wrapped(double x, Wrap w) {
  if (w == Wrap::kClampToEdge) return std::clamp(x, 0.0, 1.0);
  const double f = x - std::floor(x);
  if (w == Wrap::kRepeat) return f;
  return std::fmod(std::floor(x), 2.0) == 0.0 ? f : 1.0 - f;  // mirrored (fmod: no overflow for a huge coordinate)
}

}  // namespace

int texel_index(double t, int n, Wrap wrap) { return std::min(n - 1, static_cast<int>(wrapped(t, wrap) * n)); }

Eigen::Vector3f texel_colour(const Image& image, double u, double v, Wrap wrap_s, Wrap wrap_t) {
  if (image.width <= 0 || image.height <= 0) return Eigen::Vector3f::Ones();
  const std::uint8_t* px = image.pixel(texel_index(u, image.width, wrap_s), texel_index(v, image.height, wrap_t));
  return Eigen::Vector3f(px[0], px[1], px[2]) / 255.0F;
}

Eigen::Vector3f surface_colour(const Model& model, int material, double u, double v, const Eigen::Vector3f& vc) {
  if (model.materials.empty()) return vc;
  const Material& m = model.materials[static_cast<std::size_t>(std::max(material, 0)) % model.materials.size()];
  Eigen::Vector3f c(m.base_color_factor[0], m.base_color_factor[1], m.base_color_factor[2]);
  c = c.cwiseProduct(vc);
  if (m.base_color_image < 0 || static_cast<std::size_t>(m.base_color_image) >= model.images.size()) return c;
  const Image& img = model.images[static_cast<std::size_t>(m.base_color_image)];
  if (img.width <= 0 || img.height <= 0) return c;
  return c.cwiseProduct(texel_colour(img, u, v, m.sampler.wrap_s, m.sampler.wrap_t));
}

std::size_t Model::triangle_count() const {
  std::size_t n = 0;
  for (const auto& p : primitives) n += p.indices.size() / 3;
  return n;
}

Eigen::AlignedBox3d Model::bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& p : primitives)
    for (const auto& v : p.vertices) box.extend(pos(v));
  return box;
}

Eigen::Vector3d Model::surface_centroid() const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (const auto& p : primitives)
    for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      const Eigen::Vector3d a = pos(p.vertices[p.indices[t]]);
      const Eigen::Vector3d b = pos(p.vertices[p.indices[t + 1]]);
      const Eigen::Vector3d c = pos(p.vertices[p.indices[t + 2]]);
      const double w = 0.5 * (b - a).cross(c - a).norm();
      sum += w * (a + b + c) / 3.0;
      area += w;
    }
  return area > 0.0 ? Eigen::Vector3d(sum / area) : bounds().center();
}

bool has_texture_coordinates(const Model& model) {
  return std::any_of(model.primitives.begin(), model.primitives.end(), [](const Primitive& p) {
    return std::any_of(p.vertices.begin(), p.vertices.end(), [](const Vertex& v) { return v.uv[0] != 0.0F || v.uv[1] != 0.0F; });
  });
}

void scale_and_recenter(Model& model, double scale, bool recenter) {
  if (!(scale > 0.0) || !std::isfinite(scale)) throw AssetError(model.source + ": scale must be finite and > 0");
  for (auto& p : model.primitives)
    for (auto& v : p.vertices)
      for (auto& x : v.position) x = static_cast<float>(x * scale);
  if (!recenter) return;
  const Eigen::Vector3d c = model.surface_centroid();
  for (auto& p : model.primitives)
    for (auto& v : p.vertices)
      for (int k = 0; k < 3; ++k)
        v.position[static_cast<std::size_t>(k)] = static_cast<float>(v.position[static_cast<std::size_t>(k)] - c[k]);
}

SurfaceSamples sample_surface(const Model& model, std::size_t count, std::uint32_t seed) {
  struct Tri {
    Eigen::Vector3d a, b, c;
    const Vertex *va, *vb, *vc;
    int material;
  };
  std::vector<Tri> tris;
  std::vector<double> cumulative;
  double total = 0.0;
  for (const auto& p : model.primitives)
    for (std::size_t t = 0; t + 2 < p.indices.size(); t += 3) {
      if (t % (3 * config::kStopCheckEvery) == 0)
        config::stop_if_requested("sampling the surface of a model of " + std::to_string(p.indices.size() / 3) + " triangles");
      const Vertex& va = p.vertices[p.indices[t]];
      const Vertex& vb = p.vertices[p.indices[t + 1]];
      const Vertex& vc = p.vertices[p.indices[t + 2]];
      Tri tri{pos(va), pos(vb), pos(vc), &va, &vb, &vc, p.material};
      const double area = 0.5 * (tri.b - tri.a).cross(tri.c - tri.a).norm();
      if (!(area > 0.0)) continue;  // degenerate triangles carry no surface
      total += area;
      tris.push_back(tri);
      cumulative.push_back(total);
    }
  SurfaceSamples out;
  if (tris.empty() || count == 0) return out;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  out.points.reserve(count);
  out.normals.reserve(count);
  out.colours.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double pick = uni(rng) * total;
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), pick);
    const Tri& t = tris[static_cast<std::size_t>(
        std::min<std::ptrdiff_t>(it - cumulative.begin(), static_cast<std::ptrdiff_t>(tris.size()) - 1))];
    // Uniform point in a triangle: reflect (u, v) back into the lower half of the unit square.
    double u = uni(rng), v = uni(rng);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    out.points.push_back((t.a + u * (t.b - t.a) + v * (t.c - t.a)).cast<float>());
    out.normals.push_back((t.b - t.a).cross(t.c - t.a).normalized().cast<float>());
    // The colour at the same barycentric point (no draw from rng: the points stay as they were).
    const auto mix = [&](const auto& fa, const auto& fb, const auto& fc, std::size_t k) {
      return fa[k] + u * (fb[k] - fa[k]) + v * (fc[k] - fa[k]);
    };
    const Eigen::Vector3f vertex_colour(static_cast<float>(mix(t.va->color, t.vb->color, t.vc->color, 0)),
                                        static_cast<float>(mix(t.va->color, t.vb->color, t.vc->color, 1)),
                                        static_cast<float>(mix(t.va->color, t.vb->color, t.vc->color, 2)));
    out.colours.push_back(surface_colour(model, t.material, mix(t.va->uv, t.vb->uv, t.vc->uv, 0),
                                         mix(t.va->uv, t.vb->uv, t.vc->uv, 1), vertex_colour));
  }
  return out;
}

Model make_uv_sphere(double radius_m, int rings, int segments) {
  if (rings < 2 || segments < 3 || !(radius_m > 0.0)) throw AssetError("uv sphere: need rings >= 2, segments >= 3, radius > 0");
  Model m;
  m.source = "uv-sphere(" + std::to_string(rings) + "x" + std::to_string(segments) + ")";
  Primitive p;
  for (int r = 0; r <= rings; ++r) {
    const double theta = M_PI * r / rings;  // from +y (north pole) down
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2.0 * M_PI * s / segments;
      const Eigen::Vector3d n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
      Vertex v;
      v.position = {static_cast<float>(radius_m * n.x()), static_cast<float>(radius_m * n.y()),
                    static_cast<float>(radius_m * n.z())};
      v.normal = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
      v.uv = {static_cast<float>(s) / static_cast<float>(segments), static_cast<float>(r) / static_cast<float>(rings)};
      p.vertices.push_back(v);
    }
  }
  const auto idx = [&](int r, int s) { return static_cast<std::uint32_t>(r * (segments + 1) + s); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // Counter-clockwise seen from outside.
      p.indices.insert(p.indices.end(), {idx(r, s), idx(r + 1, s), idx(r, s + 1)});
      p.indices.insert(p.indices.end(), {idx(r, s + 1), idx(r + 1, s), idx(r + 1, s + 1)});
    }
  m.primitives.push_back(std::move(p));
  // An 8x8 checker texture so the benchmark samples a real texture.
  Image checker;
  checker.width = checker.height = 256;
  checker.rgba.resize(256 * 256 * 4);
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const bool on = ((x / 32) + (y / 32)) % 2 == 0;
      std::uint8_t* px = checker.pixel(x, y);
      px[0] = on ? 240 : 30;
      px[1] = on ? 200 : 60;
      px[2] = on ? 40 : 160;
      px[3] = 255;
    }
  m.images.push_back(std::move(checker));
  Material mat;
  mat.base_color_image = 0;
  m.materials.push_back(mat);
  return m;
}

Model make_box(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, const std::array<float, 4>& rgba) {
  if (!min_m.allFinite() || !max_m.allFinite() || !(min_m.array() < max_m.array()).all())
    throw AssetError("box: need finite min < max on every axis");
  Model m;
  m.source = "box";
  Primitive p;
  for (int axis = 0; axis < 3; ++axis)
    for (const int side : {-1, 1}) {
      // The face on `side` of `axis`, its corners walked counter-clockwise seen from outside.
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      n[axis] = side;
      const auto base = static_cast<std::uint32_t>(p.vertices.size());
      for (const auto& [a, b] : {std::pair{0, 0}, std::pair{1, 0}, std::pair{1, 1}, std::pair{0, 1}}) {
        Eigen::Vector3d c;
        c[axis] = side > 0 ? max_m[axis] : min_m[axis];
        c[u] = a ? max_m[u] : min_m[u];
        c[v] = b ? max_m[v] : min_m[v];
        Vertex vert;
        vert.position = {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
        vert.normal = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
        vert.uv = {static_cast<float>(a), static_cast<float>(b)};
        p.vertices.push_back(vert);
      }
      // (u, v, n) is right-handed, so 0-1-2 is counter-clockwise seen from +n; flip for the -n face.
      if (side > 0)
        p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
      else
        p.indices.insert(p.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    }
  m.primitives.push_back(std::move(p));
  Material mat;
  mat.base_color_factor = rgba;
  m.materials.push_back(mat);
  return m;
}

}  // namespace projbot::assets
