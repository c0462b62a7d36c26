// Materials over time (issue 44): a texture's transform as a matrix, and the animated materials' states at a
// time, sampled from their glTF channels as glTF says.

#include <algorithm>
#include <cmath>

#include "projbot/assets/model.hpp"

namespace projbot::assets {

std::array<double, 6> TextureTransform::matrix() const {
  const double c = std::cos(rotation_rad), s = std::sin(rotation_rad);
  return {c * scale[0], s * scale[1], offset[0], -s * scale[0], c * scale[1], offset[1]};
}

MaterialState Material::state() const {
  return {base_color_factor, emissive_factor, emissive_strength, base_color_transform, emissive_transform};
}

int MaterialChannel::width(Property p) {
  switch (p) {
    case Property::kBaseColorFactor:
      return 4;
    case Property::kEmissiveFactor:
      return 3;
    case Property::kEmissiveStrength:
    case Property::kBaseColorRotation:
    case Property::kEmissiveRotation:
      return 1;
    default:
      return 2;
  }
}

namespace {

// The channel's value at t (within its keys' span or held outside it) into `out` (width numbers).
void sample(const MaterialChannel& ch, double t, float* out) {
  const int n = MaterialChannel::width(ch.property);
  const bool cubic = ch.interpolation == MaterialChannel::Interpolation::kCubicSpline;
  const std::size_t per_key = static_cast<std::size_t>(n) * (cubic ? 3 : 1);
  const auto value = [&](std::size_t k) { return ch.values.data() + per_key * k + (cubic ? n : 0); };
  const std::size_t last = ch.times.size() - 1;
  const auto next = std::upper_bound(ch.times.begin(), ch.times.end(), static_cast<float>(t));
  if (next == ch.times.begin() || next == ch.times.end()) {  // before the first key or from the last on: held
    std::copy_n(value(next == ch.times.begin() ? 0 : last), n, out);
    return;
  }
  const auto k1 = static_cast<std::size_t>(next - ch.times.begin()), k0 = k1 - 1;
  const double td = ch.times[k1] - ch.times[k0];
  const double s = td > 0.0 ? (t - ch.times[k0]) / td : 0.0;
  for (int c = 0; c < n; ++c) {
    const double v0 = value(k0)[c], v1 = value(k1)[c];
    double v = v0;
    if (ch.interpolation == MaterialChannel::Interpolation::kLinear) {
      v = v0 + s * (v1 - v0);
    } else if (cubic) {  // glTF's Hermite spline: b0 the first key's out-tangent, a1 the second's in-tangent
      const double b0 = ch.values[per_key * k0 + 2 * n + c], a1 = ch.values[per_key * k1 + c];
      const double s2 = s * s, s3 = s2 * s;
      v = (2 * s3 - 3 * s2 + 1) * v0 + td * (s3 - 2 * s2 + s) * b0 + (-2 * s3 + 3 * s2) * v1 + td * (s3 - s2) * a1;
    }
    out[c] = static_cast<float>(v);
  }
}

void set(MaterialState& st, MaterialChannel::Property p, const float* v) {
  using P = MaterialChannel::Property;
  switch (p) {
    case P::kBaseColorFactor:
      std::copy_n(v, 4, st.base_color_factor.begin());
      break;
    case P::kEmissiveFactor:
      std::copy_n(v, 3, st.emissive_factor.begin());
      break;
    case P::kEmissiveStrength:
      st.emissive_strength = v[0];
      break;
    case P::kBaseColorOffset:
      st.base_color_transform.offset = {v[0], v[1]};
      break;
    case P::kBaseColorScale:
      st.base_color_transform.scale = {v[0], v[1]};
      break;
    case P::kBaseColorRotation:
      st.base_color_transform.rotation_rad = v[0];
      break;
    case P::kEmissiveOffset:
      st.emissive_transform.offset = {v[0], v[1]};
      break;
    case P::kEmissiveScale:
      st.emissive_transform.scale = {v[0], v[1]};
      break;
    case P::kEmissiveRotation:
      st.emissive_transform.rotation_rad = v[0];
      break;
  }
}

}  // namespace

std::vector<std::pair<int, MaterialState>> animate_materials(const Model& model, double t_s) {
  std::vector<std::pair<int, MaterialState>> out;
  for (const MaterialAnimation& a : model.material_animations) {
    const double t = a.duration_s > 0.0 && t_s > 0.0 ? std::fmod(t_s, a.duration_s) : std::max(t_s, 0.0);
    for (const MaterialChannel& ch : a.channels) {
      if (ch.times.empty() || ch.material < 0 || static_cast<std::size_t>(ch.material) >= model.materials.size()) continue;
      auto it = std::find_if(out.begin(), out.end(), [&](const auto& p) { return p.first == ch.material; });
      if (it == out.end())
        it = out.insert(out.end(), {ch.material, model.materials[static_cast<std::size_t>(ch.material)].state()});
      float v[4] = {};
      sample(ch, t, v);
      set(it->second, ch.property, v);
    }
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  return out;
}

}  // namespace projbot::assets
