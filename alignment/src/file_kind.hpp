#pragma once
// A file's extension in lower case, for choosing a reader ("Scan.PCD" -> ".pcd").

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace projbot::alignment::detail {

inline std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace projbot::alignment::detail
