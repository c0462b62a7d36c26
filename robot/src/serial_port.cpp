#include "serial_port.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace projbot::robot::detail {

// Why `port` is no serial port, or "": a regular file, a folder or /dev/null once read as "the unit did
// not answer". A serial port is a character device that is a terminal (a USB adapter, a pty).
std::string serial_port_problem(const std::string& port) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_type type = fs::status(port, ec).type();
  if (type == fs::file_type::not_found) return "cannot open the serial port (no such device)";
  if (type != fs::file_type::character)
    return std::string("is ") +
           (type == fs::file_type::directory ? "a folder"
            : type == fs::file_type::regular ? "a regular file"
                                             : "no device") +
           ", not a serial port (a character device such as /dev/ttyUSB0)";
  const int fd = ::open(port.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::string("cannot open the serial port (") + std::strerror(errno) + ")";
  const bool terminal = ::isatty(fd) == 1;
  ::close(fd);
  return terminal ? "" : "is a character device but not a serial port (not a terminal; /dev/null?)";
}

}  // namespace projbot::robot::detail
