#pragma once
// Directed Perception / FLIR PTU-D46 over a serial line, through MRPT's CPtuDPerception, and a
// simulated unit that speaks the same ASCII protocol on a pseudo-terminal.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "projbot/robot/error.hpp"
#include "projbot/robot/pan_tilt.hpp"

namespace projbot::robot {

/// The real unit. Commands go through mrpt::hwdrivers::CPtuDPerception (9600 baud, verbose
/// replies, echo on, immediate execution); limits and errors the unit reports become
/// PanTiltStatus values naming the reply.
class PtuD46 final : public PanTilt {
 public:
  /// Opens the serial device (e.g. /dev/ttyUSB0) and reads the axis resolutions. Throws
  /// RobotError when the port cannot be opened or the unit does not answer.
  explicit PtuD46(const std::string& port);
  ~PtuD46() override;
  PtuD46(const PtuD46&) = delete;
  PtuD46& operator=(const PtuD46&) = delete;

  PanTiltStatus move_to(const PanTiltAngles& angles) override;
  PanTiltStatus position(PanTiltAngles& out) override;
  /// Radians per position step, as the unit reported them.
  double pan_step_rad() const;
  double tilt_step_rad() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A PTU-D46-17 on a pseudo-terminal (posix_openpt): answers the commands CPtuDPerception sends
/// (FV FT PR TR EE ED I S PP TP PO TO PX PN TX TN A H HP HT PS TS L LE LD V R DR) with the unit's
/// replies, including limit errors ("! Maximum allowable ...") and "! Illegal Command". Runs on
/// its own thread until destroyed.
class PtuD46Emulator {
 public:
  PtuD46Emulator();
  ~PtuD46Emulator();
  PtuD46Emulator(const PtuD46Emulator&) = delete;
  PtuD46Emulator& operator=(const PtuD46Emulator&) = delete;

  /// The slave side's path (/dev/pts/N): what a driver opens.
  std::string port() const;
  /// Current positions, in steps.
  long pan_steps() const;
  long tilt_steps() const;
  /// Stops answering (the driver then sees its 1 s timeouts), or answers again.
  void set_silent(bool silent);
  /// Commands received so far, in order, without their terminators.
  std::vector<std::string> received() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::robot
