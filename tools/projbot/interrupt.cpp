#include "interrupt.hpp"

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "projbot/config/stop_request.hpp"

namespace projbot::tools {
namespace {

std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "used from a signal handler");

extern "C" void on_signal(int sig) {
  if (g_signal.exchange(sig) != 0) _exit(128 + sig);  // the second one: at once
  constexpr char kMsg[] =
      "\nprojbot: stopping after the current frame, visit or scan, and writing what was measured (Ctrl-C again quits now)\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, kMsg, sizeof kMsg - 1);
}

}  // namespace

void catch_interrupts() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  config::set_stop_request(&interrupted);  // heard inside the loaders too (a model of millions of triangles)
}

bool interrupted() { return g_signal.load() != 0; }

int interrupt_exit_code() {
  const int sig = g_signal.load();
  return sig == 0 ? 0 : 128 + sig;
}

int benchmark_interrupted(const std::string& where) {
  std::cout << "interrupted " << where << "; the rows above are complete" << std::endl;
  return interrupt_exit_code();
}

void quit_now() {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(interrupt_exit_code());
}

int nothing_written(const std::string& when) {
  std::cout << "interrupted " << when << "; nothing written (the outputs, if they existed, are unchanged)" << std::endl;
  return interrupt_exit_code();
}

}  // namespace projbot::tools
