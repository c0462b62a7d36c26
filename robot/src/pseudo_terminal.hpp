#pragma once
// A pseudo-terminal standing in for a serial device in the protocol emulators (PTU-D46, Hokuyo URG):
// the emulator reads and writes the master side; the slave side is what a driver opens, held open here
// (raw, like a serial line) so the master never sees EOF between driver sessions.

#include <string>

namespace projbot::robot::detail {

struct PseudoTerminal {
  /// Throws RobotError naming `who` when the system has no pseudo-terminal to give.
  explicit PseudoTerminal(const std::string& who);
  ~PseudoTerminal();
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;
  int master = -1;
  int slave = -1;
  std::string slave_path;  ///< /dev/pts/N
};

}  // namespace projbot::robot::detail
