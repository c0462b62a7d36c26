#include <Eigen/Geometry>
#include <charconv>
#include <cmath>
#include <string>

#include "projbot/config/scene.hpp"

namespace projbot::config {

Eigen::Matrix4d pose_from_xyz_rpy(const Eigen::Vector3d& translation_m, const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d rad = rpy_deg * (M_PI / 180.0);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(rad.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rad.y(), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(rad.x(), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = translation_m;
  return T;
}

void validate_rigid(const Eigen::Matrix4d& T, std::string_view where) {
  const auto fail = [&](const std::string& why) { throw ConfigError(std::string(where) + ": " + why); };
  if (!T.allFinite()) fail("pose has a non-finite entry");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) fail("pose's last row must be 0 0 0 1");
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double orth = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth > 1e-6 || R.determinant() < 0.0)
    fail("pose's rotation is not a proper rotation (orthonormality error " + std::to_string(orth) + ", det " +
         std::to_string(R.determinant()) + "); scale the model with 'scale' instead");
}

std::vector<double> parse_number_list(std::string_view text, std::size_t count, std::string_view what) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    std::string item(text.substr(pos, comma - pos));
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    double value = 0.0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
    if (item.empty() || ec != std::errc() || end != item.data() + item.size() || !std::isfinite(value))
      throw ConfigError(std::string(what) + ": '" + item + "' is not a finite number");
    out.push_back(value);
    pos = comma + 1;
  }
  if (out.size() != count)
    throw ConfigError(std::string(what) + ": expected " + std::to_string(count) + " comma-separated numbers, got " +
                      std::to_string(out.size()));
  return out;
}

}  // namespace projbot::config
