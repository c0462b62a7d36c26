#pragma once
// The twin's world: the room and the targets at their true poses, the simulated robot (drifting base,
// MRPT localisation, pan-tilt with backlash), an RGB-D camera that renders the true scene's depth with
// the Kinect v1 error model, and the true surfaces the projector's light falls on. Same interfaces as
// the hardware; nothing here is visible to the estimator except through them.
// Not thread-safe: one owner thread (the tour, or the sensor thread of `projbot run`).

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/robot/pan_tilt.hpp"
#include "projbot/robot/sim_tour.hpp"
#include "projbot/twin/raycast.hpp"

namespace projbot::twin {

/// Thrown for a scene the twin cannot simulate (missing tour sections, markers off the surface).
class TwinError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct TwinOptions {
  /// Laser localisation where the build has MRPT; odometry alone in the portable build (tools/bundle.sh).
  robot::PoseSource pose_source = robot::built_with_mrpt() ? robot::PoseSource::localized : robot::PoseSource::odometry;
  std::uint64_t seed = 1;
  bool depth_noise = true;                   ///< Kinect v1 noise on captured depth...
  alignment::KinectNoiseConfig depth_model;  ///< ...this model of it (KinectNoiseConfig::fitted(): the real frames')
  double marker_tolerance_m = 0.005;         ///< markers farther than this from the model's surface are an error
  /// Asked while the robot's map is surveyed: true ends the construction (robot::SetupInterrupted).
  std::function<bool()> stop_requested;
};

/// One target as the twin and the estimator know it.
struct TwinTarget {
  config::TargetConfig config;
  assets::Model model;  ///< scaled and recentred, model frame
  /// Its surface as a picture over the model's UVs (`surface.texture`); null: config.surface.albedo.
  std::shared_ptr<const assets::Image> surface_texture;
  std::shared_ptr<MeshRaycaster> raycaster;
  alignment::ModelCloud cloud;          ///< 50k surface samples for ICP and tracking
  Eigen::Matrix4d T_world_target_true;  ///< where it stands now (moves with its motion script)
  /// In the world now: false for a target that is not there (`present: false`) or was carried away
  /// (`motion.removed`). An absent target is neither seen by the camera nor catches the projector's
  /// light; its pedestal stays.
  bool in_world = true;
  /// What it stands on (config.support): a box from the floor (a translation), none for the floor.
  Eigen::Matrix4d T_world_pedestal = Eigen::Matrix4d::Identity();
  std::shared_ptr<MeshRaycaster> pedestal_raycaster;  ///< null when it stands on the floor
  std::size_t pedestal_id = 0;                        ///< renderer model id
};

/// Where the robot stands after driving to a target's stop and aiming at it.
struct Arrival {
  robot::StopReport drive;
  robot::HeadPoses truth;                                      ///< the head's true frames
  robot::HeadPoses believed;                                   ///< where the robot believes its head is
  Eigen::Matrix4d T_map_target = Eigen::Matrix4d::Identity();  ///< the target as surveyed
  /// Eq. 1: the target's initial pose in the camera frame, from the map and the believed head.
  Eigen::Matrix4d T_camera_target_guess = Eigen::Matrix4d::Identity();
};

class Twin {
 public:
  /// Loads every target's model, checks the tour sections and markers, builds the room map and the
  /// simulated robot, and uploads the scene's meshes to `renderer` (used for depth capture; it must
  /// outlive the twin and belong to the calling thread). Throws TwinError, config::ConfigError or
  /// assets::AssetError naming what is wrong.
  Twin(const config::Scene& scene, const TwinOptions& options, engine::Renderer& renderer);

  const config::Scene& scene() const { return scene_; }
  std::vector<TwinTarget>& targets() { return targets_; }
  const std::vector<TwinTarget>& targets() const { return targets_; }
  robot::SimRobot& robot() { return *robot_; }
  robot::SimulatedPanTilt& pan_tilt() { return pan_tilt_; }
  const alignment::CameraIntrinsics& camera() const { return camera_; }

  /// Index into targets() of the target named `name`. Throws TwinError if the twin has none.
  std::size_t target_index(const std::string& name) const;
  /// Drives to the target's stop (`index` goes into the report), aims the pan-tilt at the target's
  /// surveyed position from where the robot believes it is (live::drive_and_aim, the session's own
  /// step), and takes Eq. 1's initial guess; with the head's true frames. For tests and benches that
  /// need one target at its stop; a tour runs through live::StopSequence.
  Arrival arrive(std::size_t target, int index);
  /// The head's true frames now (the robot's true pose and the pan-tilt's true angles).
  robot::HeadPoses true_head() const;
  /// The targets as a session knows them (scene index, surface samples, model middle); they point into
  /// the twin, which must outlive the session.
  std::vector<live::Target> session_targets() const;

  /// The target's pose `t_s` into a projection during its `target_visit`-th visit (motion script);
  /// visit 0 is where it stands between visits.
  Eigen::Matrix4d scripted_pose(std::size_t target, int target_visit, double t_s) const;
  /// Where the target stands between visits (its world pose, or where a `stays` motion left it).
  const Eigen::Matrix4d& home(std::size_t target) const { return home_.at(target); }
  /// Whether the target is in the world `t_s` into its `target_visit`-th visit (a `removed` motion
  /// takes it away at its end).
  bool scripted_presence(std::size_t target, int target_visit, double t_s) const;
  /// After a visit: a target whose motion `stays` is left where the motion took it; one `removed` is gone.
  void end_visit(std::size_t target, int target_visit);

  /// Renders the true scene's depth from T_world_camera (Kinect v1 noise when enabled, seeded).
  alignment::DepthImage capture(const Eigen::Matrix4d& T_world_camera, std::uint32_t noise_seed);
  /// Renders the true scene's colour from T_world_camera, registered to capture()'s depth (the same
  /// pinhole and viewpoint, as a Kinect v1 registers its RGB to depth): textured models under plain,
  /// even room light, with the colour sensor's noise (Gaussian, kColourNoiseSigma levels per channel,
  /// seeded) when depth noise is on. RGBA8, alpha 255.
  assets::Image capture_colour(const Eigen::Matrix4d& T_world_camera, std::uint32_t noise_seed);
  static constexpr double kColourNoiseSigma = 2.5;
  /// The camera's pinhole as capture() and capture_colour() render it (clipped at 0.3 and 8 m).
  config::Camera camera_pinhole() const;
  /// The true surfaces placed in a frame (T_frame_world): for the projector's rays.
  std::vector<PlacedMesh> true_scene(const Eigen::Matrix4d& T_frame_world) const;
  /// Every surface's ray caster (room, props, targets, pedestals): a holder keeps them beyond the twin.
  std::vector<std::shared_ptr<const MeshRaycaster>> meshes() const;

  /// What a camera at T_world_camera sees: the room, props, supports and the targets in the world, each
  /// placed in the camera frame (for the renderer's draw_frame).
  std::vector<engine::DrawItem> draw_items(const Eigen::Matrix4d& T_world_camera) const;
  /// draw_items with each target's physical surface (`surface:`, its albedo as sRGB colour) instead of
  /// its content: what the projector's light and the room's fall on (issue 43).
  std::vector<engine::DrawItem> surface_items(const Eigen::Matrix4d& T_world_camera) const;
  /// The middle of a target's model (its bounding box's centre) where the map says it stands.
  Eigen::Vector3d surveyed_middle(std::size_t target) const;

  /// Renderer model ids of the targets (same order as targets()).
  const std::vector<std::size_t>& target_model_ids() const { return target_ids_; }
  /// Renderer model ids of the targets' facets, each coloured (n + 1) / 2 by its model-frame normal.
  const std::vector<std::size_t>& facet_model_ids() const { return facet_ids_; }

 private:
  config::Scene scene_;
  TwinOptions options_;
  engine::Renderer& renderer_;
  std::vector<TwinTarget> targets_;
  std::vector<Eigen::Matrix4d> home_;        // where each target stands between visits
  std::set<std::size_t> gone_;               // targets carried away (motion.removed) on an earlier visit
  std::shared_ptr<MeshRaycaster> room_ray_;  // floor, walls, obstacle blocks and box props
  std::size_t room_id_ = 0;
  struct PlacedProp {
    std::shared_ptr<MeshRaycaster> raycaster;
    std::size_t id = 0;  // renderer model id
    Eigen::Matrix4d T_world = Eigen::Matrix4d::Identity();
  };
  std::vector<PlacedProp> props_;  // the glTF props
  std::vector<std::size_t> target_ids_;
  std::vector<std::size_t> surface_ids_;  // each target's model coloured by its surface's albedo
  std::vector<std::size_t> facet_ids_;    // facet_model_ids()
  std::vector<engine::DrawItem> placed_items(const Eigen::Matrix4d& T_world_camera, const std::vector<std::size_t>& ids) const;
  // Checks and builds a target's support; adds what stands on the floor to `footprints` (the laser's).
  void place_support(TwinTarget& t, const std::string& where, std::vector<config::Box2D>& footprints);
  std::unique_ptr<robot::SimRobot> robot_;
  robot::SimulatedPanTilt pan_tilt_;
  alignment::CameraIntrinsics camera_;
  std::unique_ptr<engine::RenderTarget> depth_target_;
  std::unique_ptr<engine::RenderTarget> colour_target_;
};

/// The colour camera's sensor noise over an RGBA8 image: Gaussian, Twin::kColourNoiseSigma levels per
/// colour channel (alpha kept), reproducible for a seed.
void add_colour_noise(assets::Image& image, std::uint32_t seed);

/// The middle of a target's model (its bounding box's centre) placed by T_world_target.
Eigen::Vector3d model_middle(const TwinTarget& t, const Eigen::Matrix4d& T_world_target);

/// The pose of `target` standing at `home`, `t_s` into its `target_visit`-th visit (its motion script).
Eigen::Matrix4d scripted_pose(const config::TargetConfig& target, const Eigen::Matrix4d& home, int target_visit, double t_s);

/// How far through a scripted motion (0..1) its profile is at the fraction x (0..1) of its duration.
double motion_fraction(config::MotionProfile profile, double x);

/// The twin's robot set-up for a scene: its room (with the `footprints` of what stands on the
/// floor: supports, floor-standing targets, props), start pose and drift, closing the loop on `source`.
robot::SimTourConfig robot_config(const config::Scene& scene, robot::PoseSource source, std::uint64_t seed,
                                  const std::vector<config::Box2D>& footprints);

}  // namespace projbot::twin
