// calib.yaml: what a scene's `calibration:` reads (config/src/scene.cpp apply_calibration), plus the
// camera's lens and what the solve measured.

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <sstream>

#include "projbot/calibrate/calibrate.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/yaml_keys.hpp"
#include "yaml_file.hpp"

namespace projbot::calibrate {
namespace {

std::string pinhole_fields(const Camera& l) {
  std::ostringstream y;
  y.precision(17);
  const config::Pinhole& p = l;
  y << "width: " << p.width_px << ", height: " << p.height_px << ", fx: " << p.fx_px << ", fy: " << p.fy_px << ", cx: " << p.cx_px
    << ", cy: " << p.cy_px << ", distortion: [";
  for (std::size_t i = 0; i < l.distortion.size(); ++i) y << (i ? ", " : "") << l.distortion[i];
  y << "]";
  return y.str();
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) out += (ch == '"' || ch == '\\') ? std::string("\\") + ch : std::string(1, ch);
  return out + "\"";
}

Camera read_lens(const YAML::Node& n) {
  Camera l;
  static_cast<config::Pinhole&>(l) = config::Pinhole{n["width"].as<int>(), n["height"].as<int>(), n["fx"].as<double>(),
                                                     n["fy"].as<double>(), n["cx"].as<double>(),  n["cy"].as<double>()};
  if (n["distortion"])
    for (std::size_t i = 0; i < n["distortion"].size() && i < 5; ++i) l.distortion[i] = n["distortion"][i].as<double>();
  return l;
}

}  // namespace

void write_calibration(const Calibration& c, const std::filesystem::path& path, const std::string& comment) {
  std::ostringstream y;
  y.precision(17);
  y << "# Projector-camera calibration (projbot calibrate): " << comment << "\n"
    << "# Pinholes in OpenCV's convention (pixel centres at integers), distortion k1 k2 p1 p2 k3.\n"
    << "# projector_from_camera: X_p = R_cp X_c + T_cp (Eq. 2), metres.\n"
    << "projector: {" << pinhole_fields(c.projector) << "}\n"
    << "projector_from_camera:\n  matrix: [";
  for (int i = 0; i < 16; ++i) y << (i ? ", " : "") << c.T_projector_camera(i / 4, i % 4);
  y << "]\ncamera: {" << pinhole_fields(c.camera) << "}\n"
    << "reprojection_rms_px: {camera: " << c.camera_rms_px << ", projector: " << c.projector_rms_px << "}\n"
    << "projector_coverage: " << c.projector_coverage << "\n";
  if (!c.views.empty()) {
    y << "views:\n";
    for (const ViewResult& v : c.views) {
      y << "  - {folder: " << quoted(v.folder) << ", corners: " << v.corners << ", projector_corners: " << v.projector_corners;
      if (v.refused.empty())
        y << ", camera_rms_px: " << v.camera_rms_px << ", projector_rms_px: " << v.projector_rms_px << "}\n";
      else
        y << ", refused: " << quoted(v.refused) << "}\n";
    }
  }
  if (!c.T_camera_board.empty()) {
    y << "board_poses:  # T_camera_board of each pose, the truth of a simulated capture\n";
    for (const Eigen::Matrix4d& T : c.T_camera_board) {
      y << "  - [";
      for (int i = 0; i < 16; ++i) y << (i ? ", " : "") << T(i / 4, i % 4);
      y << "]\n";
    }
  }
  y << "warnings: [";
  for (std::size_t i = 0; i < c.warnings.size(); ++i) y << (i ? ", " : "") << quoted(c.warnings[i]);
  y << "]\n";
  config::write_file_atomically(path, y.str());  // a device or FIFO is written in place, never replaced
}

Calibration read_calibration(const std::filesystem::path& path) {
  try {
    const YAML::Node y = detail::load_yaml(path, "a calibration file");
    Calibration c;
    c.projector = read_lens(y["projector"]);
    c.camera = read_lens(y["camera"]);
    const YAML::Node m = y["projector_from_camera"]["matrix"];
    if (!m.IsSequence() || m.size() != 16)
      throw CalibrationError(path.string() + ": projector_from_camera.matrix needs 16 numbers");
    for (int i = 0; i < 16; ++i) c.T_projector_camera(i / 4, i % 4) = m[static_cast<std::size_t>(i)].as<double>();
    c.camera_rms_px = y["reprojection_rms_px"]["camera"].as<double>(0.0);
    c.projector_rms_px = y["reprojection_rms_px"]["projector"].as<double>(0.0);
    c.projector_coverage = y["projector_coverage"].as<double>(0.0);
    for (const auto& pose : y["board_poses"]) {
      Eigen::Matrix4d T;
      for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = pose[static_cast<std::size_t>(i)].as<double>();
      c.T_camera_board.push_back(T);
    }
    return c;
  } catch (const YAML::ParserException& e) {
    throw CalibrationError(config::yaml_error_message(e, path.string()));
  } catch (const YAML::Exception& e) {
    throw CalibrationError(path.string() + ": not a calibration file: " + e.what());
  }
}

}  // namespace projbot::calibrate
