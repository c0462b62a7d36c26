#pragma once
// The JSON library's message for a person: nlohmann's exceptions begin with their own tag
// ("[json.exception.parse_error.101] "), which says nothing to someone mending the file.

#include <string>

namespace projbot::config {

inline constexpr const char* kJsonTag = "[json.exception.";

/// Whether `what` carries the JSON library's tag: its message was passed on by another library.
inline bool has_json_tag(const std::string& what) { return what.find(kJsonTag) != std::string::npos; }

/// `what` without its "[json.exception.KIND.N] " tags (unchanged where it has none; a library that passes
/// the JSON library's message on, as tinygltf does, may put it after its own words).
inline std::string without_json_tag(std::string what) {
  for (auto at = what.find(kJsonTag); at != std::string::npos; at = what.find(kJsonTag, at)) {
    const auto end = what.find("] ", at);
    if (end == std::string::npos) break;
    what.erase(at, end + 2 - at);
  }
  return what;
}

}  // namespace projbot::config
