#pragma once
// The fuzzers' shared step: the input as a file with the extension the reader dispatches on (every
// reader under test takes a path, as the executable does).
//
// libFuzzer's per-input timer is a SIGALRM whose handler has no SA_RESTART, so any system call of the
// harness's own may fail with EINTR: every write here retries it. A failure of the harness itself (the
// disk full, the temporary folder gone) is not a finding in the reader: it says so and exits with
// kHarnessFailure before libFuzzer can save the input as a crash (tools/fuzz.sh reports it apart).
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <system_error>

#include "projbot/config/write_all.hpp"

namespace projbot::fuzz {

inline constexpr int kHarnessFailure = 86;  // tools/fuzz.sh: "harness failure, not a finding"

[[noreturn]] inline void harness_failure(const std::string& what);

// The paths a fuzzer wrote under the temporary folder, removed (with what they hold) when it exits:
// libFuzzer ends a timed run through exit(), which runs the destructor of the static below.
class Scratch {
 public:
  Scratch() = default;
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  ~Scratch() { remove(); }
  // The temporary folder's `stem` + this process's id + `suffix`, removed at exit.
  std::filesystem::path path(const std::string& stem, const std::string& suffix = "") {
    std::error_code ec;
    const auto temp = std::filesystem::temp_directory_path(ec);
    if (ec) harness_failure("no temporary folder: " + ec.message());
    auto path = temp / (stem + std::to_string(::getpid()) + suffix);
    paths_.insert(path);
    return path;
  }
  void remove() {
    for (const auto& path : paths_) {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  }

 private:
  std::set<std::filesystem::path> paths_;
};

inline Scratch& scratch() {
  static Scratch s;
  return s;
}

[[noreturn]] inline void harness_failure(const std::string& what) {
  std::fprintf(stderr, "projbot-fuzz: HARNESS FAILURE (not a finding in the reader): %s\n", what.c_str());
  scratch().remove();
  std::_Exit(kHarnessFailure);  // not exit(): libFuzzer's exit hook would save the input as a crash
}

// `bytes` as the whole of `file`, through short writes and EINTR.
inline void write_file(const std::filesystem::path& file, std::string_view bytes) {
  const int fd = config::open_retrying(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) harness_failure("cannot create " + file.string() + ": " + std::strerror(errno));
  if (const int err = config::write_all(fd, bytes.data(), bytes.size()); err != 0)
    harness_failure("cannot write " + file.string() + ": " + std::strerror(err));
  if (::close(fd) != 0 && errno != EINTR) harness_failure("cannot close " + file.string() + ": " + std::strerror(errno));
}

inline void make_folders(const std::filesystem::path& folder) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) harness_failure("cannot make " + folder.string() + ": " + ec.message());
}

inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const std::filesystem::path file = scratch().path("projbot_fuzz_", extension);
  write_file(file, std::string_view(reinterpret_cast<const char*>(data), size));
  return file;
}

}  // namespace projbot::fuzz
