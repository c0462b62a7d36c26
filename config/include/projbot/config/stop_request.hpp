#pragma once
// A stop asked of the whole process (Ctrl-C, SIGTERM), heard by the work no caller hands a predicate to:
// reading, checking and preparing a model of millions of triangles takes seconds in loops deep inside
// the loaders. The executable says how a stop is asked (set_stop_request); those loops ask every few
// milliseconds of work (stop_requested) and end with StopRequested, which the executable answers as a
// command stopped before it made anything. Without a hook nothing is ever stopped (the libraries' tests).

#include <cstddef>
#include <stdexcept>
#include <string>

namespace projbot::config {

/// The work was stopped on request; the message says what it was doing ("loading model.ply").
class StopRequested : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// `asked` answers whether a stop was asked (null: never). Set once, before the work starts; asked from
/// any thread.
void set_stop_request(bool (*asked)());

/// Whether a stop was asked.
bool stop_requested();

/// Throws StopRequested("stopped while " + `doing`) when a stop was asked.
void stop_if_requested(const std::string& doing);

/// How many items (triangles, faces, vertices) a loop does between two questions: about a millisecond.
constexpr std::size_t kStopCheckEvery = 1U << 16;

}  // namespace projbot::config
