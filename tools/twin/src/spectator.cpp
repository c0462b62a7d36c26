#include "projbot/twin/spectator.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "projbot/alignment/equations.hpp"
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

SpectatorView::SpectatorView(engine::Renderer& renderer, const config::ProjectorConfig& projector)
    : renderer_(renderer), projector_(projector) {
  pinhole_.width_px = kWidth;
  pinhole_.height_px = kHeight;
  pinhole_.fx_px = pinhole_.fy_px = 660.0;
  pinhole_.cx_px = (kWidth - 1) / 2.0;
  pinhole_.cy_px = (kHeight - 1) / 2.0;
  pinhole_.near_m = 0.1;
  pinhole_.far_m = 20.0;
  colour_ = renderer_.make_offscreen(kWidth, kHeight);
  depth_ = renderer_.make_depth_camera(kWidth, kHeight);
  projector_depth_ = renderer_.make_depth_camera(projector_.width_px, projector_.height_px);
}

assets::Image SpectatorView::draw(Twin& twin, const Eigen::Matrix4d& T_world_spectator, const Eigen::Matrix4d& T_world_projector,
                                  const assets::Image& projector_frame) {
  if (projector_frame.width != projector_.width_px || projector_frame.height != projector_.height_px ||
      projector_frame.rgba.size() != static_cast<std::size_t>(projector_frame.width) * projector_frame.height * 4)
    throw TwinError("spectator view: the projector frame is " + std::to_string(projector_frame.width) + "x" +
                    std::to_string(projector_frame.height) + ", the projector " + std::to_string(projector_.width_px) + "x" +
                    std::to_string(projector_.height_px));
  const std::vector<engine::DrawItem> room = twin.draw_items(T_world_spectator);
  renderer_.draw_frame(*colour_, pinhole_, room);
  assets::Image out = colour_->read_back();  // the albedo: the twin's colours as they are
  renderer_.draw_frame(*depth_, pinhole_, room);
  const engine::DepthMap depth = depth_->read_back_depth();
  renderer_.draw_frame(*projector_depth_, projector_, twin.draw_items(T_world_projector));
  const engine::DepthMap lit_depth = projector_depth_->read_back_depth();
  const Eigen::Matrix4d T_projector_spectator = alignment::rigid_inverse(T_world_projector) * T_world_spectator;
  const config::ProjectorConfig& k = projector_;
  for (int v = 0; v < kHeight; ++v)
    for (int u = 0; u < kWidth; ++u) {
      std::uint8_t* px = out.pixel(u, v);
      const float z = depth.z_m[static_cast<std::size_t>(v) * kWidth + u];
      double light[3] = {kRoomLight, kRoomLight, kRoomLight};
      if (z > 0.0F) {
        const Eigen::Vector4d p(z * (u - pinhole_.cx_px) / pinhole_.fx_px, z * (v - pinhole_.cy_px) / pinhole_.fy_px, z, 1.0);
        const Eigen::Vector3d q = (T_projector_spectator * p).head<3>();
        // Eq. 3: the projector pixel that reaches this point through its lens, if nothing nearer the
        // projector blocks it (the projector's depth image is a pinhole's: looked up along the ray).
        const bool ahead = q.z() > k.near_m;
        const Eigen::Vector2d x = ahead ? k.project_lit(q) : Eigen::Vector2d(-1.0, -1.0);
        const Eigen::Vector2d ray = ahead ? k.project(q) : Eigen::Vector2d(-1.0, -1.0);
        const long pu = std::lround(x.x()), pv = std::lround(x.y()), ru = std::lround(ray.x()), rv = std::lround(ray.y());
        if (pu >= 0 && pv >= 0 && pu < k.width_px && pv < k.height_px && ru >= 0 && rv >= 0 && ru < k.width_px &&
            rv < k.height_px) {
          const float seen = lit_depth.z_m[static_cast<std::size_t>(rv) * k.width_px + ru];
          if (seen > 0.0F && std::abs(seen - q.z()) < 0.01 + 0.01 * q.z()) {
            const std::uint8_t* c = projector_frame.pixel(static_cast<int>(pu), static_cast<int>(pv));
            for (int ch = 0; ch < 3; ++ch) light[ch] += c[ch] / 255.0;
          }
        }
      }
      for (int ch = 0; ch < 3; ++ch) px[ch] = static_cast<std::uint8_t>(std::clamp(std::lround(px[ch] * light[ch]), 0L, 255L));
      px[3] = 255;
    }
  return out;
}

}  // namespace projbot::twin
