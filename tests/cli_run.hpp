#pragma once
// Running the projbot executable from a test, as a user's shell would: its exit code and its output
// (stdout and stderr together).
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

struct CliRun {
  int code;  ///< the exit status, or 128 + N for a death by signal N (as a shell reports it)
  std::string output;
};

/// Runs `projbot ARGS` through the shell, killed after `limit_s` seconds (then code 137).
inline CliRun run_projbot(const std::string& args, int limit_s = 300) {
  const std::string cmd =
      "timeout -s KILL " + std::to_string(limit_s) + " " + std::string(PROJBOT_EXE) + " " + args + " 2>&1 </dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 512> buf{};
  while (pipe != nullptr && fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
  const int status = pipe != nullptr ? pclose(pipe) : -1;
  if (status == -1) return {-1, out};
  // sh reports a child's death by signal N as exit 128 + N.
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), out};
}
