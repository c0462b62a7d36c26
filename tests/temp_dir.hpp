#pragma once
// The tests' temporary folder, one way for every test that needs one.

#include <unistd.h>

#include <filesystem>
#include <string>

namespace test_support {

/// An empty folder `projbot_NAME_PID` under the system's temporary folder: one per test process and name,
/// emptied first where an earlier run left it.
inline std::filesystem::path temp_dir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("projbot_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace test_support
