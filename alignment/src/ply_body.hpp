#pragma once
// A PLY file's body against its header, checked by us before PCL's reader sees the file: that reader
// reads the counts the header declares and silently ignores what follows, so a file holding more
// vertices than it declares was half read and its pose accepted.

#include <cstdint>
#include <filesystem>

namespace projbot::alignment::detail {

/// What the header declares.
struct PlyCounts {
  std::uint64_t vertices = 0;
  std::uint64_t faces = 0;
};

/// Walks the body element by element (list properties included) and throws AlignmentError naming the
/// file unless it ends exactly where the header's counts say (ASCII: one line per element, blank lines
/// aside). Returns the declared vertex and face counts.
PlyCounts check_ply_body(const std::filesystem::path& path);

}  // namespace projbot::alignment::detail
