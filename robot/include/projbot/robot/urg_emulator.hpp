#pragma once
// A Hokuyo URG laser scanner on a pseudo-terminal, for testing the configured-laser path (MrptLaser
// with MRPT's CHokuyoURG driver) without the hardware.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"
#include "projbot/robot/laser.hpp"
#include "projbot/robot/pose2d.hpp"

namespace projbot::robot {

/// A Hokuyo UTM-30LX on a pseudo-terminal (posix_openpt), speaking SCIP 2.0: it answers SCIP2.0, QT,
/// BM, SS, HS, CR, RS, PP (the UTM-30LX's parameters: steps 0..1080 over 270 degrees, 1440 per turn,
/// 23 mm to 60 m, 2400 rpm), VV and II, and after MD or ME streams a scan every 25 ms (40 Hz, as the
/// unit does) with the ranges it is given, checksummed as the protocol says. A scan that the line
/// cannot take (the reader is behind) is dropped, as a serial line's would be. Runs on its own thread
/// until destroyed.
class UrgEmulator {
 public:
  /// `ranges_mm`: one per step, 1081 (0: no echo). Throws RobotError for another count.
  explicit UrgEmulator(std::vector<std::uint32_t> ranges_mm);
  ~UrgEmulator();
  UrgEmulator(const UrgEmulator&) = delete;
  UrgEmulator& operator=(const UrgEmulator&) = delete;

  /// The slave side's path (/dev/pts/N): what a driver opens.
  std::string port() const;
  /// The ranges of the scans from now on.
  void set_ranges(std::vector<std::uint32_t> ranges_mm);
  /// Scans written to the line so far.
  int scans_sent() const;
  /// Commands received so far, in order, without their line ends.
  std::vector<std::string> received() const;

  static constexpr int kSteps = 1081;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The twin's laser for a base served on DDS (`projbot sim-base --laser`): a UTM-30LX (UrgEmulator) whose
/// pseudo-terminal is linked at `link`, its scans ray-traced in `room` from where the base truly stands
/// (`T_room_odometry` composed with the pose it is told). The link is removed when it is destroyed.
class RoomUrg {
 public:
  /// Throws RobotError naming `link` when it cannot be made.
  RoomUrg(const config::Room& room, std::filesystem::path link, const Pose2D& T_room_odometry);
  ~RoomUrg();
  RoomUrg(const RoomUrg&) = delete;
  RoomUrg& operator=(const RoomUrg&) = delete;
  /// The scans from now on: from the base at `pose` (its odometry's frame).
  void stand_at(const Pose2D& pose);
  int scans_sent() const { return unit_.scans_sent(); }

 private:
  OccupancyMap map_;
  UrgEmulator unit_;
  std::filesystem::path link_;
  Pose2D T_room_odometry_;
  LaserConfig laser_;
  std::mt19937_64 rng_{7};
};

}  // namespace projbot::robot
