#pragma once
// A Hokuyo URG laser scanner on a pseudo-terminal, for testing the configured-laser path (MrptLaser
// with MRPT's CHokuyoURG driver) without the hardware.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

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

}  // namespace projbot::robot
