#include "projbot/twin/spectator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "projbot/alignment/equations.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/projection.hpp"

namespace projbot::twin {

Eigen::Matrix4d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& at) {
  const Eigen::Vector3d z = (at - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) x = Eigen::Vector3d::UnitX();  // looking straight up or down
  x.normalize();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.block<3, 1>(0, 0) = x;
  T.block<3, 1>(0, 1) = z.cross(x);
  T.block<3, 1>(0, 2) = z;
  T.topRightCorner<3, 1>() = eye;
  return T;
}

Eigen::Matrix4d spectator_pose(const Eigen::Vector3d& head, const Eigen::Vector3d& target_middle) {
  Eigen::Vector3d forward = target_middle - head;
  forward.z() = 0.0;
  forward = forward.norm() > 1e-9 ? forward.normalized() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ());
  Eigen::Vector3d eye = head + 1.0 * right - 0.6 * forward;
  eye.z() = 1.6;
  return look_at(eye, target_middle);
}

namespace {

config::ProjectorConfig spectator_eye() {
  config::ProjectorConfig eye;
  eye.width_px = SpectatorView::kWidth;
  eye.height_px = SpectatorView::kHeight;
  eye.fx_px = eye.fy_px = 660.0;
  eye.cx_px = (SpectatorView::kWidth - 1) / 2.0;
  eye.cy_px = (SpectatorView::kHeight - 1) / 2.0;
  eye.near_m = 0.1;
  eye.far_m = 20.0;
  return eye;
}

}  // namespace

SpectatorView::SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector)
    : SpectatorView(renderer, projector, spectator_eye()) {}

SpectatorView::SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector, const config::Camera& eye)
    : renderer_(renderer), projector_(projector), pinhole_(eye) {
  colour_ = renderer_.make_offscreen(pinhole_.width_px, pinhole_.height_px);
  depth_ = renderer_.make_depth_camera(pinhole_.width_px, pinhole_.height_px);
  projector_depth_ = renderer_.make_depth_camera(projector_.width_px, projector_.height_px);
}

namespace {

// The surface normal at a depth pixel (camera frame), from its nearer neighbour on each axis so that a
// silhouette's far side does not bend it; zero where a neighbour is missing.
Eigen::Vector3d normal_at(const engine::DepthMap& depth, const config::ProjectorConfig& k, int u, int v) {
  const auto point = [&](int x, int y) -> std::optional<Eigen::Vector3d> {
    if (x < 0 || y < 0 || x >= depth.width || y >= depth.height) return std::nullopt;
    const float z = depth.z_m[static_cast<std::size_t>(y) * depth.width + x];
    if (!(z > 0.0F)) return std::nullopt;
    return k.back_project(x, y, z);
  };
  const auto p = point(u, v);
  if (!p) return Eigen::Vector3d::Zero();
  const auto step = [&](int dx, int dy) -> Eigen::Vector3d {
    const auto a = point(u + dx, v + dy), b = point(u - dx, v - dy);
    if (a && (!b || std::abs(a->z() - p->z()) <= std::abs(b->z() - p->z()))) return *a - *p;
    if (b) return *p - *b;
    return Eigen::Vector3d::Zero();
  };
  const Eigen::Vector3d n = step(1, 0).cross(step(0, 1));
  return n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::Zero();
}

}  // namespace

// Each pixel's true normal where a target is the nearest surface (its facet, from facet_model_ids), in the
// spectator's frame; zero elsewhere.
std::vector<Eigen::Vector3f> SpectatorView::facet_normals(Twin& twin, const Eigen::Matrix4d& T_world_spectator,
                                                          const engine::DepthMap& depth) {
  std::vector<Eigen::Vector3f> out(depth.z_m.size(), Eigen::Vector3f::Zero());
  const Eigen::Matrix4d T_spectator_world = alignment::rigid_inverse(T_world_spectator);
  for (std::size_t t = 0; t < twin.targets().size(); ++t) {
    if (!twin.targets()[t].in_world) continue;
    const Eigen::Matrix4d T = T_spectator_world * twin.targets()[t].T_world_target_true;
    const std::vector<engine::DrawItem> item{{twin.facet_model_ids()[t], T}};
    renderer_.draw_frame(*depth_, pinhole_, item);
    const engine::DepthMap alone = depth_->read_back_depth();
    renderer_.draw_frame(*colour_, pinhole_, item);
    const assets::Image colours = colour_->read_back();
    const Eigen::Matrix3f R = T.topLeftCorner<3, 3>().cast<float>();
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (!(alone.z_m[i] > 0.0F) || std::abs(alone.z_m[i] - depth.z_m[i]) > 0.002F) continue;
      const std::uint8_t* c = colours.rgba.data() + 4 * i;
      const Eigen::Vector3f n(c[0] / 127.5F - 1.0F, c[1] / 127.5F - 1.0F, c[2] / 127.5F - 1.0F);
      if (n.norm() > 0.5F) out[i] = R * n.normalized();
    }
  }
  return out;
}

SpectatorScene SpectatorView::look(Twin& twin, const Eigen::Matrix4d& T_world_spectator,
                                   const Eigen::Matrix4d& T_world_projector) {
  const std::vector<engine::DrawItem> room = twin.surface_items(T_world_spectator);
  renderer_.draw_frame(*colour_, pinhole_, room);
  SpectatorScene out;
  out.albedo = colour_->read_back();
  out.ambient_lux = twin.scene().room.ambient_lux;
  const int width = pinhole_.width_px, height = pinhole_.height_px;
  out.white_lux.assign(static_cast<std::size_t>(width) * height, 0.0F);
  out.panel.assign(out.white_lux.size(), -1);
  renderer_.draw_frame(*depth_, pinhole_, room);
  const engine::DepthMap depth = depth_->read_back_depth();
  out.z_m = depth.z_m;
  const std::vector<Eigen::Vector3f> facets = facet_normals(twin, T_world_spectator, depth);
  renderer_.draw_frame(*projector_depth_, projector_, twin.surface_items(T_world_projector));
  const engine::DepthMap lit_depth = projector_depth_->read_back_depth();
  const Eigen::Matrix4d T_projector_spectator = alignment::rigid_inverse(T_world_projector) * T_world_spectator;
  const Eigen::Matrix3d R = T_projector_spectator.topLeftCorner<3, 3>();
  const config::ProjectorConfig& k = projector_;
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      const float z = depth.z_m[i];
      if (!(z > 0.0F)) continue;
      const Eigen::Vector3d q = (T_projector_spectator * pinhole_.back_project(u, v, z).homogeneous()).head<3>();
      // Eq. 3: the projector pixel that reaches this point through its lens, if nothing nearer the
      // projector blocks it (the projector's depth image is a pinhole's: looked up along the ray).
      const bool ahead = q.z() > k.near_m;
      const Eigen::Vector2d x = ahead ? k.project_lit(q) : Eigen::Vector2d(-1.0, -1.0);
      const Eigen::Vector2d ray = ahead ? k.project(q) : Eigen::Vector2d(-1.0, -1.0);
      const long pu = std::lround(x.x()), pv = std::lround(x.y()), ru = std::lround(ray.x()), rv = std::lround(ray.y());
      if (pu < 0 || pv < 0 || pu >= k.width_px || pv >= k.height_px || ru < 0 || rv < 0 || ru >= k.width_px || rv >= k.height_px)
        continue;
      const float seen = lit_depth.z_m[static_cast<std::size_t>(rv) * k.width_px + ru];
      if (!(seen > 0.0F) || !(std::abs(seen - q.z()) < 0.01 + 0.01 * q.z())) continue;
      // The targets' true facets; the room's flat faces from the depth.
      const Eigen::Vector3d n = facets[i].isZero() ? normal_at(depth, pinhole_, u, v) : facets[i].cast<double>();
      out.white_lux[i] = static_cast<float>(engine::white_lux(k, q, R * n));
      out.panel[i] = static_cast<std::int32_t>(pv * k.width_px + pu);
    }
  return out;
}

assets::Image uniform_frame(const config::ProjectorConfig& projector, const std::array<std::uint8_t, 3>& rgb) {
  assets::Image frame;
  frame.width = projector.width_px, frame.height = projector.height_px;
  frame.rgba.resize(static_cast<std::size_t>(frame.width) * frame.height * 4, 255);
  for (std::size_t i = 0; i < frame.rgba.size(); i += 4)
    std::copy(rgb.begin(), rgb.end(), frame.rgba.begin() + static_cast<std::ptrdiff_t>(i));
  return frame;
}

SpectatorPicture SpectatorView::light(const SpectatorScene& scene, const assets::Image& projector_frame) const {
  if (projector_frame.width != projector_.width_px || projector_frame.height != projector_.height_px ||
      projector_frame.rgba.size() != static_cast<std::size_t>(projector_frame.width) * projector_frame.height * 4)
    throw TwinError("spectator view: the projector frame is " + std::to_string(projector_frame.width) + "x" +
                    std::to_string(projector_frame.height) + ", the projector " + std::to_string(projector_.width_px) + "x" +
                    std::to_string(projector_.height_px));
  SpectatorPicture out{scene.albedo, scene.albedo, scene.white_lux, scene.z_m};
  for (std::size_t i = 0; i < scene.panel.size(); ++i) {
    Eigen::Vector3d lux = Eigen::Vector3d::Constant(scene.ambient_lux);
    if (scene.panel[i] >= 0) {
      const std::uint8_t* c = projector_frame.rgba.data() + 4 * static_cast<std::size_t>(scene.panel[i]);
      lux += scene.white_lux[i] * engine::light(projector_.photometry, Eigen::Vector3d(c[0], c[1], c[2]) / 255.0);
    }
    std::uint8_t* px = out.image.rgba.data() + 4 * i;
    for (int ch = 0; ch < 3; ++ch) {
      const double seen = engine::srgb_to_linear(px[ch] / 255.0) * lux[ch] / engine::kReferenceLux;
      px[ch] = static_cast<std::uint8_t>(std::lround(255.0 * engine::linear_to_srgb(seen)));
    }
    px[3] = 255;
  }
  return out;
}

ContentView SpectatorView::content(Twin& twin, std::size_t target, const Eigen::Matrix4d& T_world_spectator,
                                   const SpectatorScene& picture) {
  const TwinTarget& t = twin.targets().at(target);
  const Eigen::Matrix4d T_spectator_target = alignment::rigid_inverse(T_world_spectator) * t.T_world_target_true;
  ContentView view;
  renderer_.draw_frame(*colour_, pinhole_,
                       std::vector<engine::DrawItem>{{twin.target_model_ids().at(target), T_spectator_target}});
  view.content = colour_->read_back();
  renderer_.draw_frame(*depth_, pinhole_,
                       std::vector<engine::DrawItem>{{twin.target_model_ids().at(target), T_spectator_target}});
  const engine::DepthMap alone = depth_->read_back_depth();
  view.mask.assign(alone.z_m.size(), 0);
  for (std::size_t i = 0; i < alone.z_m.size() && i < picture.z_m.size(); ++i)
    view.mask[i] = t.in_world && alone.z_m[i] > 0.0F && std::abs(alone.z_m[i] - picture.z_m[i]) < 0.002F ? 1 : 0;
  return view;
}

}  // namespace projbot::twin
