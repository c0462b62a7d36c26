#include "projbot/live/stop_sequence.hpp"

#include <algorithm>
#include <chrono>

#include "projbot/alignment/equations.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/robot/error.hpp"

namespace projbot::live {

Eigen::Matrix4d surveyed_pose(const config::TargetConfig& target) {
  if (target.T_map_target) return *target.T_map_target;
  if (target.T_world_target) return *target.T_world_target;
  throw SessionError("target '" + target.name + "' has neither a map_pose nor a world_pose: the session cannot find it");
}

void drive_and_aim(const config::Scene& scene, const config::TargetConfig& target, const Eigen::Vector3d& middle_world,
                   robot::Navigator& base, robot::PanTilt& pan_tilt, int index, Stop& stop) {
  const Eigen::Vector3d& goal = *target.stop;
  stop.drive = base.drive_to({goal.x(), goal.y(), goal.z()}, index);
  // Aim at the middle of the model, not its origin: a standing figure's origin is at its feet, and
  // aiming there left its chest above the projector's image.
  const auto aim = robot::aim_at(base.believed_pose(), middle_world, scene.pan_tilt);
  if (const auto s = pan_tilt.move_to(aim.angles); !s.ok) throw robot::RobotError("pan-tilt: " + s.error);
  if (const auto s = pan_tilt.position(stop.angles); !s.ok) throw robot::RobotError("pan-tilt: " + s.error);
  stop.believed = robot::head_poses(base.believed_pose(), stop.angles, scene.pan_tilt);
}

StopSequence::StopSequence(const config::Scene& scene, std::vector<Target> targets, robot::Navigator& base,
                           robot::PanTilt& pan_tilt, config::Clock clock)
    : scene_(scene),
      targets_(std::move(targets)),
      base_(base),
      pan_tilt_(pan_tilt),
      clock_(std::move(clock)),
      visits_per_target_(scene.targets.size(), 0) {
  const std::string where = scene.source.empty() ? std::string("<scene>") : scene.source.string();
  if (scene.visits.empty()) throw SessionError(where + ": a session needs a 'tour: {visits: [...]}' section");
  for (const Target& t : targets_)
    if (t.scene_index < 0 || t.scene_index >= static_cast<int>(scene.targets.size()) || t.cloud == nullptr)
      throw SessionError("session target " + std::to_string(t.scene_index) + " is not one of the scene's, or has no model");
  for (int v = 0; v < static_cast<int>(scene.visits.size()); ++v) {
    const int s = target_of(v);
    const config::TargetConfig& t = scene.targets[static_cast<std::size_t>(s)];
    if (!t.stop) throw SessionError(where + ": target '" + t.name + "' is visited but has no stop");
    surveyed_pose(t);  // throws for a target the map does not place
    find(s);
  }
}

int StopSequence::target_of(int visit) const {
  const std::string& name = scene_.visits[static_cast<std::size_t>(visit) % scene_.visits.size()];
  const int s = scene_.target_index(name);
  if (s < 0) throw SessionError("the tour visits '" + name + "', which is not one of the scene's targets");
  return s;
}

const Target& StopSequence::find(int target) const {
  for (const Target& t : targets_)
    if (t.scene_index == target) return t;
  throw SessionError("target '" + scene_.targets.at(static_cast<std::size_t>(target)).name +
                     "' is visited but the session was given no model of it");
}

MapPose StopSequence::map_pose(int target) const {
  if (map_poses_)
    if (std::optional<MapPose> shared = map_poses_(target)) return *shared;
  return {surveyed_pose(scene_.targets.at(static_cast<std::size_t>(target))), {}};
}

Eigen::Vector3d StopSequence::surveyed_middle(int target) const {
  return (map_pose(target).T_map_target * find(target).middle_model.homogeneous()).head<3>();
}

LitTarget StopSequence::plan(int target, const robot::HeadPoses& believed) const {
  LitTarget l;
  l.target = target;
  MapPose placed = map_pose(target);
  l.T_map_target = placed.T_map_target;
  l.map_pose_from = std::move(placed.from);
  const Eigen::Matrix4d T_world_camera = believed.T_world_camera.matrix();
  l.T_camera_target_guess = alignment::camera_from_target_initial(T_world_camera, l.T_map_target);  // Eq. 1
  l.footing = alignment::footing_in_camera(*find(target).cloud, l.T_map_target, T_world_camera);
  return l;
}

std::vector<LitTarget> StopSequence::neighbours(int visited, const robot::HeadPoses& believed) const {
  const Eigen::Matrix4d T_camera_world = alignment::rigid_inverse(believed.T_world_camera.matrix());
  const Eigen::Matrix4d T_projector_world = alignment::rigid_inverse(believed.T_world_projector.matrix());
  const auto inside = [](const config::Pinhole& k, const Eigen::Vector3d& p) {
    return p.z() >= 0.3 && p.z() <= 5.0 && k.contains(k.project(p));
  };
  std::vector<std::pair<double, int>> in_view;  // range, scene index
  for (const Target& t : targets_) {
    if (t.scene_index == visited) continue;
    const config::TargetConfig& c = scene_.targets[static_cast<std::size_t>(t.scene_index)];
    if (!c.T_map_target && !c.T_world_target) continue;  // not on the map: nothing to expect
    const Eigen::Vector4d middle = surveyed_middle(t.scene_index).homogeneous();
    const Eigen::Vector3d in_camera = (T_camera_world * middle).head<3>();
    if (inside(scene_.depth_camera, in_camera) && inside(scene_.projector, (T_projector_world * middle).head<3>()))
      in_view.emplace_back(in_camera.z(), t.scene_index);
  }
  std::stable_sort(in_view.begin(), in_view.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<LitTarget> out;
  for (const auto& [range, s] : in_view) out.push_back(plan(s, believed));
  return out;
}

void StopSequence::visit_next(int target) {
  if (target < 0 || target >= static_cast<int>(scene_.targets.size()))
    throw SessionError("visit_next: " + std::to_string(target) + " is not one of the scene's targets");
  const config::TargetConfig& t = scene_.targets[static_cast<std::size_t>(target)];
  if (!t.stop) throw SessionError("target '" + t.name + "' has no stop to go to");
  surveyed_pose(t);  // throws for a target the map does not place
  find(target);      // and for one the session does not track
  next_target_ = target;
}

Stop StopSequence::arrive(int visit) {
  Stop stop;
  stop.visit = visit;
  stop.target = next_target_ >= 0 ? next_target_ : target_of(visit);
  next_target_ = -1;
  stop.target_visit = ++visits_per_target_[static_cast<std::size_t>(stop.target)];
  drive_and_aim(scene_, scene_.targets[static_cast<std::size_t>(stop.target)], surveyed_middle(stop.target), base_, pan_tilt_,
                visit, stop);
  stop.lit.push_back(plan(stop.target, stop.believed));
  for (LitTarget& n : neighbours(stop.target, stop.believed)) stop.lit.push_back(std::move(n));
  return stop;
}

Stop StopSequence::visit(int visit, const std::vector<alignment::PoseTracker*>& workers, const Dwell& dwell,
                         StopObserver& observer, const std::stop_token& cancel) {
  observer.driving(visit);
  Stop at = arrive(visit);
  std::vector<alignment::PoseTracker*> lit;
  for (const LitTarget& l : at.lit) {
    const auto t = static_cast<std::size_t>(l.target);
    if (t >= workers.size() || workers[t] == nullptr)
      throw SessionError("target '" + scene_.targets[t].name + "' is lit at visit " + std::to_string(visit + 1) +
                         " but has no tracker worker");
    lit.push_back(workers[t]);
  }
  const double since = clock_.now_s();
  alignment::RgbdCamera& camera = dwell.camera(at, since);
  const auto read = [&] {
    auto f = std::make_shared<alignment::RgbdFrame>(camera.next());
    f->delivered_s = clock_.now_s();
    return f;
  };
  // The first frame's colour, taken before anything is lit, guides each lit target's acquisition.
  auto frame = read();
  std::shared_ptr<const assets::Image> colour;
  if (!frame->colour.rgba.empty()) colour = std::shared_ptr<const assets::Image>(frame, &frame->colour);
  for (std::size_t k = 0; k < at.lit.size(); ++k)
    lit[k]->set_initial_guess(at.lit[k].T_camera_target_guess, at.lit[k].footing, colour);
  observer.lit(at, since);
  std::vector<std::optional<alignment::PoseSample>> samples;
  for (int k = 0;; ++k) {
    const std::shared_ptr<const alignment::DepthImage> depth(frame, &frame->depth);  // shared, never copied
    samples.clear();
    for (alignment::PoseTracker* w : lit)
      if (dwell.lockstep)
        samples.push_back(w->track(depth));
      else
        w->submit(depth);
    observer.frame(at, k, *frame, samples);
    if (cancel.stop_requested() || dwell.over(at, k + 1, clock_.now_s() - since)) break;
    frame = read();
  }
  observer.left(at);
  return at;
}

}  // namespace projbot::live
