#pragma once
// A PCD file's header, checked by us before PCL's reader sees the file: that reader crashes on empty,
// header-only and random files and allocates whatever POINTS claims (a 4.9 KB file claiming 2e9 points
// took 21 GB). What passes here is a file whose data section can hold the points it claims.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace projbot::alignment::detail {

struct PcdHeader {
  std::vector<std::string> fields;
  std::vector<int> sizes;   ///< bytes per value
  std::vector<char> types;  ///< I, U or F
  std::vector<int> counts;  ///< values per field
  std::uint64_t width = 0, height = 0, points = 0;
  std::string data;               ///< ascii, binary or binary_compressed
  std::uint64_t data_offset = 0;  ///< first byte after the DATA line
  std::uint64_t point_bytes() const;
};

/// Reads and checks the header and the data section's length against the points claimed. Throws
/// AlignmentError naming the file and what is wrong (with the header line where there is one).
PcdHeader check_pcd(const std::filesystem::path& path);

}  // namespace projbot::alignment::detail
