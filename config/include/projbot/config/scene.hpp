#pragma once
// Scene files: the projector and the targets it lights, validated once into plain structs.

#include <Eigen/Core>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "projbot/config/robot.hpp"

namespace projbot::config {

/// A bad scene or value: the message names the file, line and key path ("scene.yaml:7: projector.fx: ...").
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Projector pinhole model, OpenCV convention: x right, y down, z forward; a point (X, Y, Z) in the
/// projector frame lands at u = fx X/Z + cx, v = fy Y/Z + cy, and pixel (i, j) has its centre at
/// u = i, v = j (Eq. 3 of the paper, x = A_p X).
struct ProjectorConfig {
  int width_px = 1280;    ///< image width, pixels (> 0)
  int height_px = 800;    ///< image height, pixels (> 0)
  double fx_px = 1400.0;  ///< focal length along x, pixels (> 0)
  double fy_px = 1400.0;  ///< focal length along y, pixels (> 0)
  double cx_px = 639.5;   ///< principal point x, pixels
  double cy_px = 399.5;   ///< principal point y, pixels
  double near_m = 0.1;    ///< near clipping distance along z, metres (> 0)
  double far_m = 20.0;    ///< far clipping distance along z, metres (> near_m)
};

/// One target object: its textured model and its pose in the projector frame.
struct TargetConfig {
  std::string name;             ///< unique within the scene
  std::filesystem::path model;  ///< glTF (.gltf/.glb); relative paths resolved against the scene's folder
  double scale = 1.0;           ///< uniform scale applied to the model frame (> 0)
  bool recenter = false;        ///< move the model frame's origin to the surface centroid
  /// T_projector_target: maps model-frame points (metres) into the projector frame. Rigid.
  Eigen::Matrix4d T_projector_target = Eigen::Matrix4d::Identity();
};

/// A whole scene file.
struct Scene {
  std::filesystem::path source;  ///< the file it came from (empty when parsed from a string)
  ProjectorConfig projector;
  std::vector<TargetConfig> targets;
  /// The robot's pan-tilt rig (optional `robot.pan_tilt` section; defaults: default_pan_tilt()).
  PanTiltConfig pan_tilt = default_pan_tilt();
};

/// Reads and validates a scene file. Throws ConfigError naming file:line and the key path.
Scene load_scene(const std::filesystem::path& path);

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
