#include "progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <iostream>

namespace projbot::tools {
namespace {

std::string duration(double s) {
  if (s < 90.0) return std::to_string(static_cast<int>(std::lround(s))) + " s";
  if (s < 5400.0) return std::to_string(static_cast<int>(std::lround(s / 60.0))) + " min";
  return std::to_string(static_cast<int>(std::lround(s / 360.0)) / 10.0).substr(0, 4) + " h";
}

}  // namespace

Progress::Progress(std::string what, int total, int lines)
    : what_(std::move(what)),
      total_(std::max(total, 1)),
      every_(std::max(1, (std::max(total, 1) + std::max(lines, 1) - 1) / std::max(lines, 1))),
      shown_(::isatty(STDERR_FILENO) == 1) {}

void Progress::step(int done) {
  if (!shown_ || (done % every_ != 0 && done != total_)) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::cerr << "  " << what_ << ' ' << done << '/' << total_ << " done, " << duration(elapsed) << " elapsed";
  if (done < total_ && done > 0) std::cerr << ", about " << duration(elapsed / done * (total_ - done)) << " left";
  std::cerr << std::endl;
}

}  // namespace projbot::tools
