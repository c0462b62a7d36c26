#pragma once
// Ctrl-C and SIGTERM for the long commands (run, show, tour, slam, localize, the benchmarks): the first
// signal asks the work to stop at its next frame, visit or scan, so what was measured is still written; a
// second one ends the process at once.

#include <string>

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

}  // namespace projbot::tools
