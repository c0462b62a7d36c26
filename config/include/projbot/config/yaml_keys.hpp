#pragma once
// yaml-cpp keeps a key given twice in one mapping and answers the first, silently: every YAML reader of the
// project asks here and refuses the file instead. Include only where yaml-cpp is a dependency already.

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
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

/// The text of the YAML file at `path`, read as every YAML reader of the project reads one: a regular file (a
/// FIFO, device or folder is refused by kind before anything opens it), at most `max_bytes` (the limit said),
/// with no NUL byte. `kind` names what the file should be in the size message ("a calibration file").
/// Throws ConfigError naming the file.
std::string read_yaml_text(const std::filesystem::path& path, std::uintmax_t max_bytes, const std::string& kind);

/// read_yaml_text, parsed: a syntax error as yaml_error_message, a key given twice refused (ConfigError).
YAML::Node load_yaml_file(const std::filesystem::path& path, std::uintmax_t max_bytes, const std::string& kind);

}  // namespace projbot::config
