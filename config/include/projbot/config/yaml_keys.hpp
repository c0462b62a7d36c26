#pragma once
// yaml-cpp keeps a key given twice in one mapping and answers the first, silently: every YAML reader of the
// project asks here and refuses the file instead. Include only where yaml-cpp is a dependency already.

#include <yaml-cpp/yaml.h>

#include <optional>
#include <string>
#include <string_view>

namespace projbot::config {

/// A key given twice in one mapping: its text and the 1-based line of its second appearance.
struct DuplicateKey {
  std::string key;
  int line = 0;
};

/// The first duplicate key anywhere under `node` (walked without recursion: nesting depth costs no stack).
std::optional<DuplicateKey> find_duplicate_key(const YAML::Node& node);

/// "FILE:LINE: 'key' is given twice in one mapping (the second would be ignored)", or empty.
std::string duplicate_key_message(const YAML::Node& node, const std::string& file);

/// "FILE:LINE: a NUL byte (byte N): ..." for YAML text holding one (yaml-cpp reads up to it and reports a
/// key missing further on), or empty. YAML is text; a NUL says the file is not what was meant.
std::string yaml_text_problem(std::string_view text, const std::string& file);

/// yaml-cpp's error as the user reads it: "FILE:LINE: YAML syntax error: ...", and for nesting past the
/// parser's depth (which yaml-cpp calls "bad file") the depth it stops at.
std::string yaml_error_message(const YAML::Exception& e, const std::string& file);

}  // namespace projbot::config
