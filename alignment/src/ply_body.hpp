#pragma once
// config::check_ply_body (one PLY check for clouds and meshes), its error as alignment's.

#include "projbot/alignment/depth.hpp"
#include "projbot/config/ply_body.hpp"

namespace projbot::alignment::detail {

using config::PlyCounts;

/// config::check_ply_body, throwing AlignmentError.
inline PlyCounts check_ply_body(const std::filesystem::path& path) {
  try {
    return config::check_ply_body(path);
  } catch (const config::PlyError& e) {
    throw AlignmentError(e.what());
  }
}

}  // namespace projbot::alignment::detail
