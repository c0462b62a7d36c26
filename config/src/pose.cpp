#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include "projbot/config/angles.hpp"
#include "projbot/config/rigid.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::config {

Eigen::Matrix4d pose_from_xyz_rpy(const Eigen::Vector3d& translation_m, const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d rad = rpy_deg * radians(1.0);
  const Eigen::Matrix3d R =
      (Eigen::AngleAxisd(rad.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rad.y(), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(rad.x(), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = translation_m;
  return T;
}

namespace {

void check_rigid(const Eigen::Matrix4d& T, std::string_view where, double tolerance) {
  const auto fail = [&](const std::string& why) { throw ConfigError(std::string(where) + ": " + why); };
  if (!T.allFinite()) fail("pose has a non-finite entry");
  if ((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) fail("pose's last row must be 0 0 0 1");
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double orth = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orth > tolerance || R.determinant() < 0.0) {
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, "orthonormality error %.3g, allowed %.1g, det %.6g", orth, tolerance, R.determinant());
    fail("pose's rotation is not a proper rotation (" + std::string(numbers) + "); scale the model with 'scale' instead");
  }
}

}  // namespace

void validate_rigid(const Eigen::Matrix4d& T, std::string_view where) { check_rigid(T, where, 1e-6); }

Eigen::Matrix4d orthonormalised_rigid(const Eigen::Matrix4d& T, std::string_view where, double tolerance) {
  check_rigid(T, where, tolerance);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.topLeftCorner<3, 3>(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix4d out = T;
  out.topLeftCorner<3, 3>() = svd.matrixU() * svd.matrixV().transpose();  // det +1: checked above, near I
  return out;
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
