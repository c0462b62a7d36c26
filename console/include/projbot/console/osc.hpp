#pragma once
// Show control over OSC (issue 70, item 2; liblo), as lighting desks, QLab and TouchDesigner send it:
//
//   /projbot/blackout i   1: every projector frame black until 0
//   /projbot/pause i      1: the tour holds at its stop until 0
//   /projbot/goto s       the robot leaves for that target now
//   /projbot/content s s  that target plays that video (a file name in the site's content folder)
//
// the same actions as the console's page, through the same live::ShowControl. UDP; an action is taken
// only from a loopback sender or a host the operator listed (by IP address): anything else is counted
// and dropped, as is a message of another path or type. With a desk to tell, the show's state goes to it
// whenever it changes:
//
//   /projbot/state s i s i i   phase, visit, visiting (empty while driving), blackout, paused

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "projbot/live/show_control.hpp"

namespace projbot::console {

struct OscConfig {
  int port = 0;                      ///< UDP; 0: any free port (OscControl::port() says which)
  std::vector<std::string> allowed;  ///< senders besides loopback whose actions are taken (IP addresses)
  std::string send_host;             ///< where /projbot/state goes on each change; empty: nowhere
  int send_port = 0;
};

/// Whether an OSC message from `host` (an IP address) may act: loopback, or one of `allowed`.
bool osc_sender_allowed(const std::string& host, const std::vector<std::string>& allowed);

class OscControl {
 public:
  /// Listens on its own thread. Throws ConsoleError naming the port when it cannot be bound.
  OscControl(live::ShowControl& show, OscConfig config);
  ~OscControl();
  OscControl(const OscControl&) = delete;
  OscControl& operator=(const OscControl&) = delete;
  int port() const;
  std::size_t taken() const;    ///< actions taken
  std::size_t refused() const;  ///< messages dropped: a sender not allowed, a target the robot cannot go to
  std::size_t sent() const;     ///< states sent to the desk

  struct Impl;  // what liblo's handlers are given

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::console
