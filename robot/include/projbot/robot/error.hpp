#pragma once
// The robot module's one exception type, for start-up failures (STYLE.md: expected run-time
// failures are values).

#include <stdexcept>

namespace projbot::robot {

/// A robot device, map, rawlog or config that could not be opened or read; the message names it.
class RobotError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Set-up work (surveying the simulated room's map) stopped on request (Ctrl-C, SIGTERM) before it was
/// done: nothing was built.
class SetupInterrupted : public RobotError {
 public:
  using RobotError::RobotError;
};

}  // namespace projbot::robot
