#pragma once
// Scene files: the projector and the targets it lights, validated once into plain structs.

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "projbot/config/devices.hpp"
#include "projbot/config/error.hpp"
#include "projbot/config/lens.hpp"
#include "projbot/config/odometry_drift.hpp"
#include "projbot/config/pinhole.hpp"
#include "projbot/config/robot.hpp"
#include "projbot/config/room.hpp"

namespace projbot::config {

/// How much light the projector gives and how its input becomes light (issue 43): per channel, an input
/// c in 0..1 gives black + (1 - black) c^gamma of full white, and full white is `brightness_lm` lumens
/// spread evenly over the panel's pixels. Defaults: a typical 3000-lumen DLP.
struct Photometry {
  double brightness_lm = 3000.0;  ///< `projector.brightness_lm`: full white's flux (1..100000 lm)
  double gamma = 2.2;             ///< `projector.gamma`: the response's exponent (1..4)
  double black_level = 0.0005;    ///< `projector.black_level`: black's light, of full white's (0..0.2)
  /// `projector.gamma_rgb`: each channel's exponent (1..4); `gamma` for each when not given.
  std::array<double, 3> gamma_rgb{2.2, 2.2, 2.2};
  /// `projector.mixing` (9 numbers, row-major): column j is channel j's light in R, G, B (a colour wheel's
  /// crosstalk; rows sum to 1 so white stays white). Identity when not given.
  Eigen::Matrix3d mixing = Eigen::Matrix3d::Identity();
};

/// The projector as a scene gives it (`projector:`): its camera model (A_p, Eq. 3, the lens, the clip
/// range) plus when its frames reach the object and how bright they are.
struct ProjectorConfig : Camera {
  ProjectorConfig() : Camera{Pinhole{1280, 800, 1400.0, 1400.0, 639.5, 399.5}, 0.1, 20.0} {}
  ProjectorConfig(const Pinhole& pinhole, double near, double far) : Camera(pinhole, near, far) {}
  explicit ProjectorConfig(const Camera& camera) : Camera(camera) {}
  // For the time a frame reaches the object (issue 14):
  double refresh_hz = 60.0;   ///< frames per second it shows (1..1000)
  double input_lag_ms = 0.0;  ///< its own delay from a frame's arrival to light (0..1000 ms)
  Photometry photometry;      ///< its brightness and response
};

/// How a scripted move runs through its duration: `smooth` eases in and out (no jump in speed);
/// `constant` starts and stops at full speed (a sudden start and a sudden stop); `accelerate` starts from
/// rest at constant acceleration and stops suddenly at twice the mean speed.
enum class MotionProfile { smooth, constant, accelerate };

/// A scripted move of a target while the robot projects onto it (the twin): during visit `visit`
/// (1-based, counted per target), from `start_s` after projection starts, the target turns and slides
/// by `delta` (applied in the world frame about the target's origin) over `duration_s`, along `profile`.
struct TargetMotion {
  int visit = 1;
  double start_s = 0.5;
  double duration_s = 2.0;
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  ///< world-frame shift, metres
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();        ///< world-frame turn, degrees
  MotionProfile profile = MotionProfile::smooth;
  bool stays = false;  ///< the target is left where it was moved: later visits find it away from its map pose
  /// Someone carries it away: at start_s + duration_s (after moving as above) it leaves the world for
  /// the rest of the tour.
  bool removed = false;
  double end_s() const { return start_s + duration_s; }
  /// Whether the target is moving `t_s` into the visit: after start_s, up to and including end_s().
  bool moving_at(double t_s) const { return t_s > start_s && t_s <= end_s(); }
};

/// What a target stands on in the twin (`support:`): the floor itself (`support: floor`: its lowest
/// point must be at z = 0), or a box from the floor up to its lowest point, centred under it
/// (`support: {width: W, depth: D}`, metres along the world's x and y; may be wider than the target, a
/// table). Default: a 24 x 24 cm pedestal.
struct TargetSupport {
  bool floor = false;
  double width_m = 0.24;
  double depth_m = 0.24;
};

/// What a target's physical surface reflects (`surface:`, issue 43): the twin's visitor sees it lit, and
/// the renderer divides it out when it compensates. Linear reflectance per channel, 0..1: one colour, or
/// a picture of the surface in the model's texture coordinates.
struct TargetSurface {
  Eigen::Vector3d albedo{0.75, 0.75, 0.75};  ///< `surface: {albedo: [r, g, b]}`; default a light grey
  /// `surface: {texture: file.png}` (beside the scene file): its colour under white light, sRGB, over the
  /// model's UVs (those of its base colour texture); empty: `albedo` everywhere.
  std::filesystem::path texture;
};

/// Content that moves on a target (`content:`, issue 44): a video in place of one material's base colour
/// texture, on the display clock of each frame drawn.
struct TargetContent {
  enum class Start { kArrival, kTour, kAt };
  /// One key of `timeline:`: the material's properties at at_s seconds of content time; between keys they are
  /// interpolated linearly, before the first and after the last they hold. Every key gives the same ones
  /// (at least one); what none gives stays as the model has it.
  struct Key {
    double at_s = 0.0;
    std::optional<std::array<double, 4>> base_color_factor;  ///< linear RGBA, each 0..1
    std::optional<std::array<double, 3>> emissive_factor;    ///< each 0..1, added as stored
    /// The base colour texture's (or the video's) placement: KHR_texture_transform's offset, scale, rotation.
    std::optional<std::array<double, 2>> uv_offset;
    std::optional<std::array<double, 2>> uv_scale;
    std::optional<double> uv_rotation_deg;
  };
  std::filesystem::path video;  ///< `video:`; relative paths resolved against the scene's folder; empty: none
  /// `material:` as written: a material's name or its index; empty: the model's first textured material
  /// (material 0 where none is textured).
  std::string material;
  bool loop = true;  ///< `loop:`; false holds the last frame
  /// `start:` arrival (content time 0 when the robot reaches the target's stop, again at every visit), tour
  /// (when the tour began), or a number: that many seconds after the tour began (kAt, at_s).
  Start start = Start::kArrival;
  double at_s = 0.0;
  /// `timeline: [{at_s: 0, base_color_factor: [r, g, b, a], emissive_factor: [r, g, b], uv_offset: [u, v],
  /// uv_scale: [u, v], uv_rotation_deg: D}, ...]`: the material over content time (times increasing; with
  /// loop, it repeats every last at_s), over the model's own material animations where it has any.
  std::vector<Key> timeline;
};

/// A static thing in the twin's room that is not a target (`props:`): a neighbour, a distractor, a
/// pillar that hides part of a target. A glTF model placed like a target, or a plain coloured box.
struct PropConfig {
  std::string name;
  std::filesystem::path model;  ///< glTF; empty for a box
  double scale = 1.0;
  bool recenter = false;
  Eigen::Matrix4d T_world_prop = Eigen::Matrix4d::Identity();  ///< the model's pose (`world_pose`)
  Eigen::Vector3d box_min_m = Eigen::Vector3d::Zero();         ///< a box's corners, world frame
  Eigen::Vector3d box_max_m = Eigen::Vector3d::Zero();
  std::array<float, 3> colour{0.6F, 0.6F, 0.6F};  ///< a box's colour, 0..1
  bool is_box() const { return model.empty(); }
  /// A box's footprint on the floor (what a laser at its height sees of it).
  Box2D box_footprint() const { return {box_min_m.x(), box_min_m.y(), box_max_m.x(), box_max_m.y()}; }
};

/// One target object: its textured model and its pose in the projector frame.
struct TargetConfig {
  std::string name;             ///< unique within the scene
  std::filesystem::path model;  ///< glTF (.gltf/.glb); relative paths resolved against the scene's folder
  double scale = 1.0;           ///< uniform scale applied to the model frame (> 0)
  bool recenter = false;        ///< move the model frame's origin to the surface centroid
  /// The twin only: false leaves the target out of the world (its survey pose and stop stay), so a tour
  /// checks that a missing target is searched for within its budget and never lit.
  bool present = true;
  /// T_projector_target: maps model-frame points (metres) into the projector frame. Rigid.
  Eigen::Matrix4d T_projector_target = Eigen::Matrix4d::Identity();

  // The tour (optional; `projbot tour` needs world_pose and stop):
  /// T_world_target: where the target truly stands in the map frame (the twin's ground truth).
  std::optional<Eigen::Matrix4d> T_world_target;
  /// The target's rough pose as surveyed into the map in preparation (Eq. 1's T_world_target);
  /// defaults to world_pose.
  std::optional<Eigen::Matrix4d> T_map_target;
  /// The designated robot stop near it: x, y (metres, map frame) and heading (radians).
  std::optional<Eigen::Vector3d> stop;
  /// Marker points on the model (model frame after scale and recenter, metres): where the
  /// projection error is measured.
  std::vector<Eigen::Vector3d> markers_m;
  TargetSupport support;                 ///< the twin only
  TargetSurface surface;                 ///< its own colour under white light
  std::optional<TargetContent> content;  ///< moving content, where there is any
  /// Scripted moves in the twin (`motion:`, one or a list), at most one per visit of this target.
  std::vector<TargetMotion> motions;
  /// The move scripted for this target's `visit`-th visit, or nullptr.
  const TargetMotion* motion_on(int visit) const {
    for (const auto& m : motions)
      if (m.visit == visit) return &m;
    return nullptr;
  }
};

/// `console:` the operator's console, as the site file starts it (run's --console and --console-token
/// given on the command line replace it).
struct ConsoleSite {
  std::string listen;                ///< [ADDR:]PORT, as --console takes it (checked where the console starts)
  std::filesystem::path token_file;  ///< `token_file:`, beside the scene file; empty: none
};

/// `osc:` show control over OSC, as the site file starts it (--osc, --osc-allow and --osc-send replace it).
struct OscSite {
  int port = 0;                    ///< UDP port 1..65535
  std::vector<std::string> allow;  ///< hosts whose actions are taken besides loopback
  std::string send;                ///< HOST:PORT the show's state goes to on each change; empty: none
};

/// `fleet:` this robot on the fleet's DDS bus (issue 69), as the site file names it (--fleet replaces it).
struct FleetSite {
  std::string name;  ///< its name in the fleet (a ROS 2 namespace; checked where the fleet starts)
  int domain = 0;    ///< the DDS domain, 0..232
};

/// A whole scene file.
struct Scene {
  std::filesystem::path source;       ///< the file it came from (empty when parsed from a string)
  std::filesystem::path calibration;  ///< its `calibration:` file (an input like the scene itself); empty: none
  ProjectorConfig projector;
  std::vector<TargetConfig> targets;
  /// The robot's pan-tilt rig (optional `robot.pan_tilt` section; defaults: default_pan_tilt()).
  PanTiltConfig pan_tilt = default_pan_tilt();

  // The tour (optional sections):
  Room room;                                          ///< `room:`
  Eigen::Vector3d robot_start{1.0, 1.0, 0.0};         ///< `robot.start: [x, y, heading_deg]`
  OdometryDrift drift = OdometryDrift::good_floor();  ///< `robot.drift:` (its seed is the run's)
  Camera depth_camera = kinect_v1_depth_camera();     ///< `camera:`, the RGB-D camera's depth intrinsics
  std::vector<std::string> visits;                    ///< `tour.visits:` target names in order
  std::vector<PropConfig> props;                      ///< `props:` the twin's static non-targets
  DevicesConfig devices;                              ///< `devices:` real devices (none: the twin)
  std::optional<ConsoleSite> console;                 ///< `console:` the operator's page (none: not served)
  std::optional<OscSite> osc;                         ///< `osc:` show control from a desk (none: not listened for)
  std::optional<FleetSite> fleet;                     ///< `fleet:` this robot on the fleet's bus (none: alone)
  /// `content_folder:` (beside the scene file) the videos an operator may switch a target's content to,
  /// by name (the console, OSC); empty: none.
  std::filesystem::path content_folder;

  /// Kinect v1 depth: 640x480, fx = fy = 525 px, 0.5-4.5 m.
  static Camera kinect_v1_depth_camera() { return {Pinhole::kinect_v1(), 0.5, 4.5}; }
  /// Index of the target named `name`, or -1.
  int target_index(std::string_view name) const;
};

/// Reads and validates a scene file. Throws ConfigError naming file:line and the key path.
Scene load_scene(const std::filesystem::path& path);

/// What a calibration file (`projbot calibrate solve`'s calib.yaml) gives: the projector's pinhole A_p
/// and the camera-to-projector pose R_cp, T_cp (X_p = R_cp X_c + T_cp, Eq. 2).
struct ProjectorCalibration {
  Camera projector;  ///< A_p and its distortion, k1 k2 p1 p2 k3 (its clip range unused)
  Eigen::Matrix4d T_projector_camera = Eigen::Matrix4d::Identity();
  /// `photometry:` (projbot calibrate photometric): its gammas, mixing and black level (brightness_lm when
  /// given) replace the scene's.
  std::optional<Photometry> photometry;
  bool photometry_brightness = false;  ///< its `photometry:` gave brightness_lm (else the scene's stays)
};
/// Reads and validates one (a scene's `calibration:` reads it so). Throws ConfigError naming file:line.
ProjectorCalibration load_calibration(const std::filesystem::path& path);

/// Parses scene YAML text; `source` names it in errors and resolves relative model paths.
Scene parse_scene(std::string_view yaml_text, const std::filesystem::path& source);

/// Checks a projector model (also after command-line overrides). Throws ConfigError with `where`.
void validate_projector(const ProjectorConfig& projector, std::string_view where);

/// Checks that T is finite and rigid (orthonormal rotation, det +1, last row 0 0 0 1), within 1e-6.
/// Throws ConfigError with `where`.
void validate_rigid(const Eigen::Matrix4d& T, std::string_view where);

/// Pose from translation (metres) and roll/pitch/yaw (degrees): R = Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix4d pose_from_xyz_rpy(const Eigen::Vector3d& translation_m, const Eigen::Vector3d& rpy_deg);

/// Parses "a,b,c" into exactly `count` finite numbers. Throws ConfigError naming `what`.
std::vector<double> parse_number_list(std::string_view text, std::size_t count, std::string_view what);

}  // namespace projbot::config
