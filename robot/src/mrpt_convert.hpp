#pragma once
// Conversions between Projbot's plain types and MRPT's; for the MRPT translation units only.

#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPose3D.h>
#include <mrpt/system/datetime.h>

#include "projbot/robot/laser.hpp"

namespace projbot::robot::detail {

inline mrpt::poses::CPose2D to_mrpt(const Pose2D& p) { return {p.x_m, p.y_m, p.theta_rad}; }
inline Pose2D from_mrpt(const mrpt::poses::CPose2D& p) { return {p.x(), p.y(), wrap_angle(p.phi())}; }
inline Pose2D from_mrpt(const mrpt::poses::CPose3D& p) { return {p.x(), p.y(), wrap_angle(p.yaw())}; }

inline mrpt::obs::CObservation2DRangeScan::Ptr to_mrpt(const LaserScan& s) {
  auto obs = mrpt::obs::CObservation2DRangeScan::Create();
  obs->sensorLabel = "LASER";
  obs->timestamp = mrpt::Clock::fromDouble(s.timestamp_s);
  obs->aperture = static_cast<float>(s.aperture_rad);
  obs->maxRange = static_cast<float>(s.max_range_m);
  obs->rightToLeft = true;
  obs->sensorPose = mrpt::poses::CPose3D(s.sensor_on_base.x_m, s.sensor_on_base.y_m, 0.0, s.sensor_on_base.theta_rad, 0, 0);
  obs->resizeScan(s.ranges_m.size());
  for (std::size_t i = 0; i < s.ranges_m.size(); ++i) {
    obs->setScanRange(i, s.ranges_m[i]);
    obs->setScanRangeValidity(i, s.valid[i] != 0);
  }
  return obs;
}

inline LaserScan from_mrpt(const mrpt::obs::CObservation2DRangeScan& obs) {
  LaserScan s;
  s.timestamp_s = mrpt::Clock::toDouble(obs.timestamp);
  s.aperture_rad = obs.aperture;
  s.max_range_m = obs.maxRange;
  s.sensor_on_base = from_mrpt(obs.sensorPose);
  const std::size_t n = obs.getScanSize();
  s.ranges_m.resize(n);
  s.valid.resize(n);
  // MRPT scans may run left to right; ours always run right to left (counter-clockwise).
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = obs.rightToLeft ? i : n - 1 - i;
    s.ranges_m[i] = obs.getScanRange(j);
    s.valid[i] = obs.getScanRangeValidity(j) ? 1 : 0;
  }
  return s;
}

}  // namespace projbot::robot::detail
