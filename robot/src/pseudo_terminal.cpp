#include "pseudo_terminal.hpp"

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "projbot/robot/error.hpp"

namespace projbot::robot::detail {

PseudoTerminal::PseudoTerminal(const std::string& who) {
  master = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) {
    const std::string reason = std::strerror(errno);
    if (master >= 0) ::close(master);
    throw RobotError(who + ": cannot create a pseudo-terminal: " + reason);
  }
  char name[128];
  if (::ptsname_r(master, name, sizeof name) != 0) {
    ::close(master);
    throw RobotError(who + ": ptsname failed");
  }
  slave_path = name;
  slave = ::open(name, O_RDWR | O_NOCTTY);
  if (slave < 0) {
    ::close(master);
    throw RobotError(who + ": cannot open " + slave_path);
  }
  termios t{};
  ::tcgetattr(slave, &t);
  ::cfmakeraw(&t);  // a serial line: no echo, no line editing on the pty itself
  ::tcsetattr(slave, TCSANOW, &t);
}

PseudoTerminal::~PseudoTerminal() {
  ::close(slave);
  ::close(master);
}

}  // namespace projbot::robot::detail
