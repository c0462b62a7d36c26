#pragma once
// What a serial port's path names, before a driver opens it: drivers that open a regular file, a folder
// or /dev/null report only that "the unit did not answer".

#include <string>

namespace projbot::robot::detail {

/// Why `port` is no serial port ("is a regular file, not a serial port ..."), or "" for a terminal device.
std::string serial_port_problem(const std::string& port);

}  // namespace projbot::robot::detail
