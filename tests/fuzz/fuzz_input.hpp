#pragma once
// The fuzzers' shared step: the input as a file with the extension the reader dispatches on (every
// reader under test takes a path, as the executable does).
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace projbot::fuzz {

inline std::filesystem::path input_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("projbot_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

}  // namespace projbot::fuzz
