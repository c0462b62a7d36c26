#include "projbot/twin/world.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/config/stop_request.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/photometry.hpp"
#include "projbot/engine/projection.hpp"

namespace projbot::twin {
namespace {

// The model's bounds in the world frame (its vertices placed by T_world_model).
Eigen::AlignedBox3d world_bounds(const assets::Model& model, const Eigen::Matrix4d& T_world_model) {
  Eigen::AlignedBox3d box;
  for (const auto& p : model.primitives)
    for (const auto& v : p.vertices)
      box.extend((T_world_model * Eigen::Vector4d(v.position[0], v.position[1], v.position[2], 1.0)).head<3>());
  return box;
}

config::Box2D footprint(const Eigen::AlignedBox3d& b) { return {b.min().x(), b.min().y(), b.max().x(), b.max().y()}; }

// Appends `part`'s primitives and materials to `into` (one mesh for the room's static surfaces).
void append(assets::Model& into, const assets::Model& part) {
  const int offset = static_cast<int>(into.materials.size());
  for (auto p : part.primitives) {
    p.material += offset;
    into.primitives.push_back(std::move(p));
  }
  into.materials.insert(into.materials.end(), part.materials.begin(), part.materials.end());
}

// The room's static surfaces: the floor, the outline's walls, the obstacles as blocks (all
// room.wall_height high) and the box props.
assets::Model room_model(const config::Scene& scene) {
  const double w = scene.room.width_m, d = scene.room.depth_m, h = scene.room.wall_height_m, t = 0.05;
  assets::Model room = assets::make_box({-2.0, -2.0, -0.05}, {w + 2.0, d + 2.0, 0.0}, {0.45F, 0.45F, 0.45F, 1.0F});
  const std::array<float, 4> wall{0.8F, 0.8F, 0.78F, 1.0F};
  append(room, assets::make_box({-t, -t, 0.0}, {w + t, 0.0, h}, wall));
  append(room, assets::make_box({-t, d, 0.0}, {w + t, d + t, h}, wall));
  append(room, assets::make_box({-t, 0.0, 0.0}, {0.0, d, h}, wall));
  append(room, assets::make_box({w, 0.0, 0.0}, {w + t, d, h}, wall));
  for (const auto& o : scene.room.obstacles)
    append(room, assets::make_box({o.min_x_m, o.min_y_m, 0.0}, {o.max_x_m, o.max_y_m, h}, wall));
  for (const auto& p : scene.props)
    if (p.is_box()) append(room, assets::make_box(p.box_min_m, p.box_max_m, {p.colour[0], p.colour[1], p.colour[2], 1.0F}));
  room.source = "room";
  return room;
}

// The target's physical surface: its mesh, every material a flat colour, its albedo as sRGB, or its
// surface texture over the model's UVs (the twin's colours are sRGB, as the room's are; SpectatorView
// decodes them to reflectance).
assets::Model surface_model(const assets::Model& model, const Eigen::Vector3d& albedo, const assets::Image* texture) {
  assets::Model surface = model;
  surface.images.clear();
  if (texture) surface.images.push_back(*texture);
  for (assets::Material& m : surface.materials) {
    m.base_color_image = texture ? 0 : -1;
    m.sampler = assets::Sampler{};  // repeating, linear
    for (int i = 0; i < 3; ++i)
      m.base_color_factor[static_cast<std::size_t>(i)] = static_cast<float>(engine::linear_to_srgb(albedo[i]));
  }
  for (assets::Primitive& p : surface.primitives)
    for (assets::Vertex& v : p.vertices) v.color = {1.0F, 1.0F, 1.0F, v.color[3]};
  return surface;
}

// The target's facets as colours: each triangle on its own, its three corners coloured (n + 1) / 2 by its
// model-frame normal, so that a rendering of it tells each pixel's true facet (SpectatorView's light).
assets::Model facet_normal_model(const assets::Model& model) {
  assets::Model out;
  out.source = model.source;
  assets::Material m;
  m.double_sided = true;
  out.materials.push_back(m);
  assets::Primitive all;
  for (const assets::Primitive& p : model.primitives)
    for (std::size_t f = 0; f + 2 < p.indices.size(); f += 3) {
      std::array<Eigen::Vector3f, 3> x;
      for (int k = 0; k < 3; ++k)
        x[static_cast<std::size_t>(k)] =
            Eigen::Vector3f(p.vertices.at(p.indices[f + static_cast<std::size_t>(k)]).position.data());
      const Eigen::Vector3f n = (x[1] - x[0]).cross(x[2] - x[0]).normalized();
      if (!n.allFinite()) continue;  // a degenerate triangle covers no pixel
      for (int k = 0; k < 3; ++k) {
        assets::Vertex v;
        v.position = {x[static_cast<std::size_t>(k)].x(), x[static_cast<std::size_t>(k)].y(), x[static_cast<std::size_t>(k)].z()};
        v.normal = {n.x(), n.y(), n.z()};
        v.color = {0.5F * (n.x() + 1.0F), 0.5F * (n.y() + 1.0F), 0.5F * (n.z() + 1.0F), 1.0F};
        all.indices.push_back(static_cast<std::uint32_t>(all.vertices.size()));
        all.vertices.push_back(v);
      }
    }
  out.primitives.push_back(std::move(all));
  return out;
}

}  // namespace

robot::SimTourConfig robot_config(const config::Scene& scene, robot::PoseSource source, std::uint64_t seed,
                                  const std::vector<config::Box2D>& footprints) {
  robot::SimTourConfig c;
  c.room = scene.room;
  c.room.obstacles.insert(c.room.obstacles.end(), footprints.begin(), footprints.end());
  c.start = {scene.robot_start.x(), scene.robot_start.y(), scene.robot_start.z()};
  c.errors = scene.drift;
  c.errors.seed = seed;
  c.source = source;
  return c;
}

Twin::Twin(const config::Scene& scene, const TwinOptions& options, engine::Renderer& renderer)
    : scene_(scene), options_(options), renderer_(renderer), pan_tilt_(scene.pan_tilt), camera_(scene.depth_camera) {
  const std::string where = scene.source.empty() ? std::string("<scene>") : scene.source.string();
  if (scene.visits.empty()) throw TwinError(where + ": the twin needs a 'tour: {visits: [...]}' section");
  const assets::Model room = room_model(scene);
  room_ray_ = std::make_shared<MeshRaycaster>(room);
  room_id_ = renderer_.add_model(room);
  std::vector<config::Box2D> footprints;  // for the laser: what stands on the floor
  for (const auto& p : scene.props) {
    if (p.is_box()) {
      footprints.push_back(p.box_footprint());
      continue;
    }
    assets::Model model = assets::load_model(p.model);
    assets::scale_and_recenter(model, p.scale, p.recenter);
    footprints.push_back(footprint(world_bounds(model, p.T_world_prop)));
    props_.push_back({std::make_shared<MeshRaycaster>(model), renderer_.add_model(model), p.T_world_prop});
  }
  for (const auto& t : scene.targets) {
    if (!t.T_world_target) continue;
    if (!t.stop) throw TwinError(where + ": target '" + t.name + "' has a world_pose but no stop");
    if (t.markers_m.empty())
      throw TwinError(where + ": target '" + t.name + "' has no markers to measure the projection error at");
    TwinTarget tt;
    tt.config = t;
    tt.model = assets::load_model(t.model);
    const std::string preparing = "preparing target '" + t.name + "' for the twin";
    config::stop_if_requested(preparing);  // between the steps that each take a second on millions of triangles
    assets::scale_and_recenter(tt.model, t.scale, t.recenter);
    tt.raycaster = std::make_shared<MeshRaycaster>(tt.model);
    config::stop_if_requested(preparing);
    for (std::size_t k = 0; k < t.markers_m.size(); ++k) {
      const Eigen::Vector3d q = tt.raycaster->closest_point(t.markers_m[k]);
      const double d = (q - t.markers_m[k]).norm();
      if (d > options.marker_tolerance_m) {
        char msg[256];
        std::snprintf(msg, sizeof msg,
                      "lies %.1f mm off the model's surface (tolerance %.1f mm); the nearest surface point is [%.4f, %.4f, %.4f]",
                      d * 1000, options.marker_tolerance_m * 1000, q.x(), q.y(), q.z());
        throw TwinError(where + ": target '" + t.name + "' marker " + std::to_string(k) + " " + msg);
      }
    }
    tt.cloud = alignment::model_cloud_from(tt.model, 50000);
    config::stop_if_requested(preparing);
    tt.T_world_target_true = *t.T_world_target;
    place_support(tt, where, footprints);
    tt.surface_texture = engine::load_surface_texture(t, tt.model);
    target_ids_.push_back(renderer_.add_model(tt.model));
    if (tt.surface_texture) renderer_.set_surface(target_ids_.back(), *tt.surface_texture);  // what compensation divides by
    surface_ids_.push_back(renderer_.add_model(surface_model(tt.model, t.surface.albedo, tt.surface_texture.get())));
    config::stop_if_requested(preparing);
    facet_ids_.push_back(renderer_.add_model(facet_normal_model(tt.model)));
    tt.in_world = t.present;
    home_.push_back(tt.T_world_target_true);
    targets_.push_back(std::move(tt));
  }
  robot::SimTourConfig rc = robot_config(scene, options.pose_source, options.seed, footprints);
  rc.stop_requested = options.stop_requested;
  robot_ = std::make_unique<robot::SimRobot>(rc);
  depth_target_ = renderer_.make_depth_camera(camera_.width_px, camera_.height_px);
}

void Twin::place_support(TwinTarget& t, const std::string& where, std::vector<config::Box2D>& footprints) {
  const Eigen::AlignedBox3d bounds = world_bounds(t.model, t.T_world_target_true);
  const config::TargetSupport& support = t.config.support;
  if (support.floor) {
    if (std::abs(bounds.min().z()) > 0.01) {
      char msg[160];
      std::snprintf(msg, sizeof msg, "stands on the floor (support: floor) but its lowest point is at z = %.3f m",
                    bounds.min().z());
      throw TwinError(where + ": target '" + t.config.name + "' " + msg +
                      ": move its world_pose so that it is at 0 (within 1 cm), or give it a support");
    }
    footprints.push_back(footprint(bounds));
    return;
  }
  // A box from the floor up to the target's lowest point, centred under it: the target stands on it.
  const double hx = support.width_m / 2.0, hy = support.depth_m / 2.0;
  const auto box = assets::make_box({-hx, -hy, 0.0}, {hx, hy, std::max(bounds.min().z(), 0.01)}, {0.7F, 0.7F, 0.7F, 1.0F});
  t.T_world_pedestal = Eigen::Matrix4d::Identity();
  t.T_world_pedestal.topRightCorner<2, 1>() = t.T_world_target_true.topRightCorner<2, 1>();
  t.pedestal_raycaster = std::make_shared<MeshRaycaster>(box);
  t.pedestal_id = renderer_.add_model(box);
  const double x = t.T_world_pedestal(0, 3), y = t.T_world_pedestal(1, 3);
  footprints.push_back({x - hx, y - hy, x + hx, y + hy});
}

std::size_t Twin::target_index(const std::string& name) const {
  for (std::size_t i = 0; i < targets_.size(); ++i)
    if (targets_[i].config.name == name) return i;
  throw TwinError("the twin has no target named '" + name + "'");
}

Eigen::Vector3d model_middle(const TwinTarget& t, const Eigen::Matrix4d& T_world_target) {
  return (T_world_target * t.model.bounds().center().homogeneous()).head<3>();
}

Eigen::Vector3d Twin::surveyed_middle(std::size_t target) const {
  const TwinTarget& t = targets_.at(target);
  return model_middle(t, live::surveyed_pose(t.config));
}

Arrival Twin::arrive(std::size_t target, int index) {
  const TwinTarget& t = targets_.at(target);
  live::Stop stop;
  live::drive_and_aim(scene_, t.config, surveyed_middle(target), *robot_, pan_tilt_, index, stop);
  Arrival a;
  a.drive = stop.drive;
  a.truth = true_head();
  a.believed = stop.believed;
  a.T_map_target = live::surveyed_pose(t.config);
  a.T_camera_target_guess = alignment::camera_from_target_initial(a.believed.T_world_camera.matrix(), a.T_map_target);
  return a;
}

robot::HeadPoses Twin::true_head() const {
  return robot::head_poses(robot_->true_pose(), pan_tilt_.true_angles(), scene_.pan_tilt);
}

std::vector<live::Target> Twin::session_targets() const {
  std::vector<live::Target> out;
  for (const TwinTarget& t : targets_) out.push_back({scene_.target_index(t.config.name), &t.cloud, t.model.bounds().center()});
  return out;
}

double motion_fraction(config::MotionProfile profile, double x) {
  switch (profile) {
    case config::MotionProfile::smooth:
      return x * x * (3.0 - 2.0 * x);  // smoothstep: no jump in speed at either end
    case config::MotionProfile::constant:
      return x;
    case config::MotionProfile::accelerate:
      return x * x;
  }
  return x;
}

Eigen::Matrix4d scripted_pose(const config::TargetConfig& target, const Eigen::Matrix4d& home, int target_visit, double t_s) {
  const config::TargetMotion* motion = target.motion_on(target_visit);
  if (!motion) return home;
  const config::TargetMotion& m = *motion;
  const double x = std::clamp((t_s - m.start_s) / m.duration_s, 0.0, 1.0);
  const double s = motion_fraction(m.profile, x);
  const Eigen::Matrix4d delta = config::pose_from_xyz_rpy(Eigen::Vector3d::Zero(), s * m.rpy_deg);
  Eigen::Matrix4d T = home;
  // Turn about the target's own origin, then shift, both in the world frame.
  T.topLeftCorner<3, 3>() = delta.topLeftCorner<3, 3>() * home.topLeftCorner<3, 3>();
  T.topRightCorner<3, 1>() += s * m.translation_m;
  return T;
}

Eigen::Matrix4d Twin::scripted_pose(std::size_t target, int target_visit, double t_s) const {
  return twin::scripted_pose(targets_.at(target).config, home_.at(target), target_visit, t_s);
}

bool Twin::scripted_presence(std::size_t target, int target_visit, double t_s) const {
  const TwinTarget& t = targets_.at(target);
  if (!t.config.present || gone_.contains(target)) return false;
  const config::TargetMotion* m = t.config.motion_on(target_visit);
  return !(m && m->removed && t_s >= m->end_s());
}

void Twin::end_visit(std::size_t target, int target_visit) {
  const config::TargetMotion* motion = targets_.at(target).config.motion_on(target_visit);
  if (motion && motion->stays) home_[target] = scripted_pose(target, target_visit, motion->end_s());
  if (motion && motion->removed) gone_.insert(target);
  targets_[target].T_world_target_true = home_[target];
  targets_[target].in_world = scripted_presence(target, 0, 0.0);
}

std::vector<engine::DrawItem> Twin::draw_items(const Eigen::Matrix4d& T_world_camera) const {
  return placed_items(T_world_camera, target_ids_);
}

std::vector<engine::DrawItem> Twin::surface_items(const Eigen::Matrix4d& T_world_camera) const {
  return placed_items(T_world_camera, surface_ids_);
}

std::vector<engine::DrawItem> Twin::placed_items(const Eigen::Matrix4d& T_world_camera,
                                                 const std::vector<std::size_t>& ids) const {
  const Eigen::Matrix4d T_camera_world = alignment::rigid_inverse(T_world_camera);
  std::vector<engine::DrawItem> items{{room_id_, T_camera_world}};
  for (const auto& p : props_) items.push_back({p.id, T_camera_world * p.T_world});
  for (std::size_t i = 0; i < targets_.size(); ++i) {
    if (targets_[i].in_world) items.push_back({ids[i], T_camera_world * targets_[i].T_world_target_true});
    if (targets_[i].pedestal_raycaster) items.push_back({targets_[i].pedestal_id, T_camera_world * targets_[i].T_world_pedestal});
  }
  return items;
}

config::Camera Twin::camera_pinhole() const {
  // Rendered from 0.3 to 8 m: the noise model, not the clip planes, drops what the Kinect cannot see.
  config::Camera pinhole = scene_.depth_camera;
  pinhole.near_m = 0.3;
  pinhole.far_m = 8.0;
  return pinhole;
}

assets::Image Twin::capture_colour(const Eigen::Matrix4d& T_world_camera, std::uint32_t noise_seed) {
  if (!colour_target_) colour_target_ = renderer_.make_offscreen(camera_.width_px, camera_.height_px);
  renderer_.draw_frame(*colour_target_, camera_pinhole(), draw_items(T_world_camera));
  assets::Image image = colour_target_->read_back();
  if (options_.depth_noise) add_colour_noise(image, noise_seed);
  return image;
}

void add_colour_noise(assets::Image& image, std::uint32_t seed) {
  std::mt19937 rng(seed ^ 0x9e3779b9U);
  std::normal_distribution<double> noise(0.0, Twin::kColourNoiseSigma);
  for (std::size_t i = 0; i < image.rgba.size(); ++i) {
    if (i % 4 == 3) continue;  // alpha
    image.rgba[i] = static_cast<std::uint8_t>(std::clamp(std::lround(image.rgba[i] + noise(rng)), 0L, 255L));
  }
}

alignment::DepthImage Twin::capture(const Eigen::Matrix4d& T_world_camera, std::uint32_t noise_seed) {
  renderer_.draw_frame(*depth_target_, camera_pinhole(), draw_items(T_world_camera));
  const engine::DepthMap map = depth_target_->read_back_depth();
  alignment::DepthImage clean{map.width, map.height, map.z_m, 0.0};
  if (!options_.depth_noise) return clean;
  return alignment::apply_kinect_v1_noise(clean, camera_, options_.depth_model, noise_seed);
}

std::vector<std::shared_ptr<const MeshRaycaster>> Twin::meshes() const {
  std::vector<std::shared_ptr<const MeshRaycaster>> out{room_ray_};
  for (const auto& p : props_) out.push_back(p.raycaster);
  for (const auto& t : targets_) {
    out.push_back(t.raycaster);
    if (t.pedestal_raycaster) out.push_back(t.pedestal_raycaster);
  }
  return out;
}

std::vector<PlacedMesh> Twin::true_scene(const Eigen::Matrix4d& T_frame_world) const {
  std::vector<PlacedMesh> out{{room_ray_.get(), T_frame_world}};
  for (const auto& p : props_) out.push_back({p.raycaster.get(), T_frame_world * p.T_world});
  for (const auto& t : targets_) {
    if (t.in_world) out.push_back({t.raycaster.get(), T_frame_world * t.T_world_target_true});
    if (t.pedestal_raycaster) out.push_back({t.pedestal_raycaster.get(), T_frame_world * t.T_world_pedestal});
  }
  return out;
}

}  // namespace projbot::twin
