#include "projbot/config/stop_request.hpp"

#include <atomic>

namespace projbot::config {
namespace {

std::atomic<bool (*)()> g_asked{nullptr};

}  // namespace

void set_stop_request(bool (*asked)()) { g_asked.store(asked); }

bool stop_requested() {
  bool (*asked)() = g_asked.load();
  return asked != nullptr && asked();
}

void stop_if_requested(const std::string& doing) {
  if (stop_requested()) throw StopRequested("stopped while " + doing);
}

}  // namespace projbot::config
