#include "projbot/live/reflectance_probe.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::live {
namespace {
constexpr int kGrey = 128;  // the projector's input under which the surface is measured (and black)
// A stop's median reflectance (clamped to 0..1) whose brightest channel is under kLeastAlbedo saw no light
// (a real surface reflects some of one); one at 1 is whiter than white: the camera changed between the
// images, or saturated.
constexpr double kLeastAlbedo = 0.02, kMostAlbedo = 0.995;
// Moved further than this between the black and the grey image, the two do not show the same points.
constexpr double kStillM = 0.003, kStillDeg = 1.0;
}  // namespace

ReflectanceProbe::ReflectanceProbe(const config::Scene& scene, std::vector<const assets::Model*> models, double settle_s)
    : scene_(scene), models_(std::move(models)), settle_s_(settle_s) {
  if (models_.size() != scene.targets.size()) throw std::invalid_argument("ReflectanceProbe: one model per scene target");
}

void ReflectanceProbe::lit(const live::Stop& stop, double since_s) {
  target_ = stop.target;
  since_s_ = since_s;
  phase_ = Phase::idle;
  show(-1);
}

void ReflectanceProbe::left() {
  phase_ = Phase::done;
  show(-1);
}

std::string ReflectanceProbe::frame(const alignment::RgbdFrame& f, double now_s, const live::PoseSource& poses) {
  if (phase_ == Phase::done || target_ < 0) return "";
  const std::string& name = scene_.targets[static_cast<std::size_t>(target_)].name;
  alignment::PoseSample pose;
  const bool found = poses(target_, pose) && pose.drawable() && pose.capture_time_s >= since_s_;
  if (phase_ == Phase::idle) {
    if (!found) return "";  // not yet accepted at this stop
    phase_ = Phase::black, phase_s_ = now_s;
    show(0);
    return "";
  }
  if (f.depth.capture_time_s < phase_s_ + settle_s_) return "";  // taken before the colour was surely shown
  if (phase_ == Phase::black && !f.colour.rgba.empty()) {        // (the twin's camera gives colour under one colour only)
    black_ = f.colour;
    black_pose_ = pose.T_camera_target;
    phase_ = Phase::grey, phase_s_ = now_s;
    show(kGrey);
    return "";
  }
  phase_ = Phase::done;
  show(-1);
  if (f.colour.rgba.empty()) return "reflectance of " + name + " not measured: the camera's frames carry no colour";
  if (!found) return "reflectance of " + name + " not measured: its pose was lost while measuring";
  const Eigen::Matrix4d moved = black_pose_.inverse() * pose.T_camera_target;
  const double moved_deg = config::degrees(Eigen::AngleAxisd(Eigen::Matrix3d(moved.topLeftCorner<3, 3>())).angle());
  if (moved.topRightCorner<3, 1>().norm() > kStillM || moved_deg > kStillDeg)
    return "reflectance of " + name + " not measured: it moved between the black and the grey image";
  return measure(f, pose);
}

// The points under black and grey at the tracked pose (the target held still meanwhile) into its map.
std::string ReflectanceProbe::measure(const alignment::RgbdFrame& grey, const alignment::PoseSample& pose) {
  const std::string& name = scene_.targets[static_cast<std::size_t>(target_)].name;
  const Eigen::Matrix4d T_projector_target =
      alignment::projector_from_target(scene_.pan_tilt.T_projector_camera, pose.T_camera_target);
  const config::Camera& camera = scene_.depth_camera;
  if (black_.width != camera.width_px || black_.height != camera.height_px || grey.colour.width != camera.width_px ||
      grey.colour.height != camera.height_px)
    return "reflectance of " + name + " not measured: its colour images are " + std::to_string(grey.colour.width) + "x" +
           std::to_string(grey.colour.height) + ", not the depth camera's " + std::to_string(camera.width_px) + "x" +
           std::to_string(camera.height_px) + " (colour registered to depth is needed)";
  std::vector<engine::ReflectancePoint> points;
  try {
    points = engine::reflectance_points(*models_[static_cast<std::size_t>(target_)], scene_.depth_camera, pose.T_camera_target,
                                        scene_.projector, T_projector_target, black_, grey.colour, kGrey / 255.0);
  } catch (const std::exception& e) {  // a model it cannot read (an index past its vertices)
    return "reflectance of " + name + " not measured: " + e.what();
  }
  if (points.empty())
    return "reflectance of " + name + " not measured: no point of it both in the camera's view and lit by the projector";
  // A camera that does not see the projector's light (or changed its exposure between the two) would
  // make a surface black, or whiter than white, and its compensation wrong everywhere: refused.
  const std::optional<Eigen::Vector3d> seen = engine::median_albedo(points);
  if (!seen || seen->maxCoeff() < kLeastAlbedo || seen->maxCoeff() > kMostAlbedo) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "reflectance of %s not measured: read as %.3f %.3f %.3f, %s (is the projector's light on it, and the "
                  "colour camera's exposure and white balance fixed?)",
                  name.c_str(), seen ? seen->x() : 0.0, seen ? seen->y() : 0.0, seen ? seen->z() : 0.0,
                  seen && seen->maxCoeff() > kMostAlbedo ? "whiter than white" : "no brighter under grey than black");
    return why;
  }
  engine::ReflectanceMap& map = maps_[target_];
  map.add(points);
  Learnt l;
  l.target = target_;
  l.points = points.size();
  if (const auto albedo = map.median()) l.albedo = *albedo;
  if (assets::has_texture_coordinates(*models_[static_cast<std::size_t>(target_)]))
    if (auto image = map.image()) l.map = std::make_shared<const assets::Image>(std::move(*image));
  char said[160];
  std::snprintf(said, sizeof said, "reflectance of %s measured: %zu points, median %.3f %.3f %.3f%s", name.c_str(), l.points,
                l.albedo.x(), l.albedo.y(), l.albedo.z(), l.map ? " (a map over its texture coordinates)" : "");
  const std::string saved = save(l);
  const std::lock_guard lock(mutex_);
  learnt_.push_back(std::move(l));
  return said + saved;
}

// save_to's files after a measurement; what to add to its log line.
std::string ReflectanceProbe::save(const Learnt& l) {
  if (save_dir_.empty()) return "";
  const std::string& name = scene_.targets[static_cast<std::size_t>(l.target)].name;
  try {
    std::filesystem::create_directories(save_dir_);
    char line[160];
    if (l.map) {
      const std::filesystem::path png =
          std::filesystem::absolute(save_dir_ / (config::file_stem(name) + "_" + std::to_string(l.target) + ".png"));
      assets::write_png(png, *l.map);
      surfaces_[l.target] = "  surface: {texture: " + png.string() + "}";
    } else {
      std::snprintf(line, sizeof line, "  surface: {albedo: [%.3f, %.3f, %.3f]}", l.albedo.x(), l.albedo.y(), l.albedo.z());
      surfaces_[l.target] = line;
    }
    std::string yaml =
        "# projbot run --learn-reflectance: each target's surface as measured at its stops so far. Put a\n"
        "# target's surface: line into its entry in the scene (targets:) to compensate with it from the start.\n";
    for (const auto& [target, surface] : surfaces_)
      yaml += "- name: " + scene_.targets[static_cast<std::size_t>(target)].name + "\n" + surface + "\n";
    config::write_file_atomically(save_dir_ / "surfaces.yaml", yaml);
    return "; saved in " + save_dir_.string();
  } catch (const std::exception& e) {
    return std::string("; not saved: ") + e.what();
  }
}

std::optional<std::array<std::uint8_t, 3>> ReflectanceProbe::showing() const {
  const int level = showing_.load();
  if (level < 0) return std::nullopt;
  const auto v = static_cast<std::uint8_t>(level);
  return std::array<std::uint8_t, 3>{v, v, v};
}

std::vector<ReflectanceProbe::Learnt> ReflectanceProbe::take_learnt() {
  const std::lock_guard lock(mutex_);
  return std::exchange(learnt_, {});
}

}  // namespace projbot::live
