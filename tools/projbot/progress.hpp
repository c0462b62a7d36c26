#pragma once
// Progress of a long command on a terminal (issue 12): a line per step with the time elapsed and the time
// expected to remain, on standard error, only when it is a terminal (pipes, logs and reports stay as
// they are).

#include <chrono>
#include <string>

namespace projbot::tools {

class Progress {
 public:
  /// `what` names a step ("visit", "scan"); `total` steps are expected; at most `lines` lines are
  /// printed (evenly spread: a slam of 4000 scans prints 20, a tour of 9 visits prints 9).
  Progress(std::string what, int total, int lines = 20);
  /// Step `done` (1-based) has finished: prints "  visit 3/9 done, 12 s elapsed, about 24 s left" when due.
  void step(int done);
  /// Whether lines are printed at all (standard error is a terminal).
  bool shown() const { return shown_; }

 private:
  std::string what_;
  int total_;
  int every_;
  bool shown_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace projbot::tools
