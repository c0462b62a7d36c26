#pragma once
// The fuzzers' shared step: the input as a file with the extension the reader dispatches on (every
// reader under test takes a path, as the executable does).
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <system_error>

namespace projbot::fuzz {

// The paths a fuzzer wrote under the temporary folder, removed (with what they hold) when it exits:
// libFuzzer ends a timed run through exit(), which runs the destructor of the static below.
class Scratch {
 public:
  Scratch() = default;
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  ~Scratch() {
    for (const auto& path : paths_) {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  }
  // The temporary folder's `stem` + this process's id + `suffix`, removed at exit.
  std::filesystem::path path(const std::string& stem, const std::string& suffix = "") {
    auto path = std::filesystem::temp_directory_path() / (stem + std::to_string(::getpid()) + suffix);
    paths_.insert(path);
    return path;
  }

 private:
  std::set<std::filesystem::path> paths_;
};

inline Scratch& scratch() {
  static Scratch s;
  return s;
}

inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const std::filesystem::path file = scratch().path("projbot_fuzz_", extension);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

}  // namespace projbot::fuzz
