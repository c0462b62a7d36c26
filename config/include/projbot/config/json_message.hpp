#pragma once
// The JSON library's message for a person: nlohmann's exceptions begin with their own tag
// ("[json.exception.parse_error.101] "), which says nothing to someone mending the file.

#include <string>

namespace projbot::config {

/// `what` without its "[json.exception.KIND.N] " tags (unchanged where it has none; a library that passes
/// the JSON library's message on, as tinygltf does, may put it after its own words).
inline std::string without_json_tag(std::string what) {
  for (auto at = what.find("[json.exception."); at != std::string::npos; at = what.find("[json.exception.", at)) {
    const auto end = what.find("] ", at);
    if (end == std::string::npos) break;
    what.erase(at, end + 2 - at);
  }
  return what;
}

}  // namespace projbot::config
