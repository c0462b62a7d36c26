#pragma once
// Running the projbot executable from a test, as a user's shell would: its exit code and its output
// (stdout and stderr together).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

struct CliRun {
  int code;  ///< the exit status, or 128 + N for a death by signal N (as a shell reports it)
  std::string output;
};

/// What keeps the Markdown tables in `text` from rendering (empty: nothing): a table is a run of lines
/// beginning with '|'; each must end with '|' and hold as many cells as its header, and its second line
/// must be the rule ("|---|---|").
inline std::string markdown_table_problem(const std::string& text) {
  std::istringstream lines(text);
  std::size_t header_cells = 0, row = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line.front() != '|') {
      row = 0;
      continue;
    }
    const auto cells = static_cast<std::size_t>(std::count(line.begin(), line.end(), '|')) - 1;
    if (line.back() != '|') return "a table row does not end with '|': " + line;
    if (row == 0) header_cells = cells;
    if (row == 1 && line.find_first_not_of("|-: ") != std::string::npos) return "a table's second line is no rule: " + line;
    if (cells != header_cells)
      return "a table row has " + std::to_string(cells) + " cells under a header of " + std::to_string(header_cells) + ": " +
             line;
    ++row;
  }
  return {};
}

/// Runs `projbot ARGS` through the shell, killed after `limit_s` seconds (then code 137).
inline CliRun run_projbot(const std::string& args, int limit_s = 300) {
#ifdef __SANITIZE_ADDRESS__
  // Mesa's lavapipe makes a one-time allocation (128 bytes, in a pthread_once during
  // vkEnumeratePhysicalDevices) that its globals hold; the Vulkan loader unloads the driver at
  // vkDestroyInstance, and LeakSanitizer then reports the block at exit with a stack too short to
  // suppress (the driver's frames are gone). It appeared when projbot began linking libfreenect (libusb,
  // libudev). Preloading the driver keeps it mapped, so leak checking stays on for everything else; the
  // ASan runtime is then not the first library, which is harmless here.
  // The leaks of the packaged OpenNI2 drivers are suppressed by name (tests/lsan.supp).
  const std::string env =
      "env LD_PRELOAD=libvulkan_lvp.so ASAN_OPTIONS=\"verify_asan_link_order=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}\" "
      "LSAN_OPTIONS=suppressions=" PROJBOT_SOURCE_DIR "/tests/lsan.supp:print_suppressions=0 ";
#else
  const std::string env;
#endif
  const std::string cmd =
      env + "timeout -s KILL " + std::to_string(limit_s) + " " + std::string(PROJBOT_EXE) + " " + args + " 2>&1 </dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 512> buf{};
  while (pipe != nullptr && fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
  const int status = pipe != nullptr ? pclose(pipe) : -1;
  if (status == -1) return {-1, out};
  // Every table any command prints renders (issue 88: a header of 13 cells once stood over a rule of 12).
  if (const std::string problem = markdown_table_problem(out); !problem.empty())
    ADD_FAILURE() << "projbot " << args << ": " << problem;
  // sh reports a child's death by signal N as exit 128 + N.
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}

// The number printed right after `key` (searched from `from`) in a command's output; NaN when the key
// is missing, so a comparison with it fails.
inline double number_after(const std::string& text, const std::string& key, std::size_t from = 0) {
  const auto at = text.find(key, from);
  return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + key.size()));
}
