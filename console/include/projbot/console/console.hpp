#pragma once
// The operator's console (issue 70): one web page and the HTTP interface under it, served from the
// engine's own process (cpp-httplib) on threads of its own. It reads the show's state and acts through a
// live::ShowControl, never touching the render loop. On loopback by default; any other address needs a
// token (from a file only its owner can read), which every action must carry as `Authorization: Bearer`.
//
//   GET  /              the page                       POST /api/blackout {"on": true|false}
//   GET  /api/state     the show's state (JSON)        POST /api/pause    {"on": true|false}
//   GET  /api/events    the same, pushed as it changes POST /api/goto     {"target": NAME}
//                       (server-sent events)
//   GET  /api/frame.png the projector's frame, small    GET /api/camera.png  the camera's view, small
//   GET  /api/content   the videos a target may switch to  POST /api/content {"target": NAME, "file": NAME}

#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "projbot/live/show_control.hpp"

namespace projbot::console {

/// A console that cannot start as configured (a bad address, a token file missing or readable by others,
/// a port taken). The message names the option or file.
class ConsoleError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ConsoleConfig {
  std::string host = "127.0.0.1";
  int port = 0;  ///< 0: any free port (Console::port() says which)
  /// The token every action must carry; empty: none, allowed only on a loopback address.
  std::string token;
  std::size_t max_body_bytes = 4096;  ///< a request's body beyond this is refused (413)
  int max_viewers = 32;               ///< pages pushed to at once (server-sent events); more are refused (503)
};

/// "[ADDR:]PORT" (as `--console` takes it): the address (127.0.0.1 when left out) and port (0-65535).
/// Throws ConsoleError naming `what` (the option) for anything else.
ConsoleConfig parse_listen(const std::string& listen, const std::string& what);

/// The token in `file`: its first line, trimmed. Throws ConsoleError naming the file when it is missing,
/// not a regular file, readable or writable by anyone but its owner (mode must be 0600 or 0400), or empty.
std::string read_token(const std::filesystem::path& file);

/// Whether `host` is a loopback address (127.0.0.0/8, ::1, localhost).
bool is_loopback(const std::string& host);

/// The show's state as the API gives it (GET /api/state, each event of /api/events).
std::string state_json(const live::ShowState& state);

class Console {
 public:
  /// Binds and starts serving on a thread of its own. Throws ConsoleError when a non-loopback address has
  /// no token or the address cannot be bound.
  Console(live::ShowControl& show, ConsoleConfig config);
  ~Console();  ///< stops serving: open pages are closed
  Console(const Console&) = delete;
  Console& operator=(const Console&) = delete;
  int port() const;
  /// The page's address, e.g. http://127.0.0.1:8080/
  std::string url() const;
  /// Requests refused so far (4xx, 5xx), for the run's closing lines.
  std::size_t refused() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::console
