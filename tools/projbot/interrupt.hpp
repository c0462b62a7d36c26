#pragma once
// Ctrl-C and SIGTERM for the long commands (run, show, tour, slam, localize, the benchmarks): the first
// signal asks the work to stop at its next frame, visit or scan, so what was measured is still written; a
// second one ends the process at once.

#include <chrono>
#include <exception>
#include <functional>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>

namespace projbot::tools {

/// Installs the SIGINT / SIGTERM handlers (idempotent).
void catch_interrupts();
/// A signal arrived since catch_interrupts().
bool interrupted();
/// The exit status for the signal that arrived: 130 (SIGINT), 143 (SIGTERM); 0 when none did.
int interrupt_exit_code();
/// A benchmark stopped by a signal: prints "interrupted WHERE; the rows above are complete" (the rows
/// printed are whole measurements, the one under way is dropped) and returns interrupt_exit_code().
int benchmark_interrupted(const std::string& where);
/// Says that a command stopped before it had produced anything, so it wrote nothing; the exit code.
int nothing_written(const std::string& when);

/// Ends the process now with interrupt_exit_code(), stdout and stderr flushed and no destructor run: a
/// thread left by unless_interrupted may still be using what they would destroy.
[[noreturn]] void quit_now();

/// Runs `work` on a thread of its own and waits for its result, unless a signal arrives first: then it
/// returns nothing at once and the work runs on (a PCL trial or an ICP run cannot be stopped inside), so
/// the caller prints what was measured before and ends with quit_now(), never returning past anything the
/// work uses. An exception from the work is thrown here.
template <typename T>
std::optional<T> unless_interrupted(std::function<T()> work) {
  auto promise = std::make_shared<std::promise<T>>();
  std::future<T> result = promise->get_future();
  std::thread([promise, work = std::move(work)] {
    try {
      promise->set_value(work());
    } catch (...) {
      promise->set_exception(std::current_exception());
    }
  }).detach();
  while (result.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready)
    if (interrupted()) return std::nullopt;
  return result.get();
}

}  // namespace projbot::tools
