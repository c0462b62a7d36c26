#pragma once
// The JSON library's message for a person: nlohmann's exceptions begin with their own tag
// ("[json.exception.parse_error.101] "), which says nothing to someone mending the file.

#include <string>

namespace projbot::config {

/// `what` without a leading "[json.exception.KIND.N] " tag (unchanged where it has none).
inline std::string without_json_tag(const std::string& what) {
  const auto tag = what.rfind("[json.exception.", 0) == 0 ? what.find("] ") : std::string::npos;
  return tag == std::string::npos ? what : what.substr(tag + 2);
}

}  // namespace projbot::config
