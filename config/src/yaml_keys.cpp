#include "projbot/config/yaml_keys.hpp"

#include <yaml-cpp/depthguard.h>

#include <algorithm>
#include <fstream>
#include <set>
#include <vector>

#include "projbot/config/error.hpp"
#include "projbot/config/paths.hpp"

namespace projbot::config {

std::optional<DuplicateKey> find_duplicate_key(const YAML::Node& node) {
  std::vector<YAML::Node> todo{node};
  while (!todo.empty()) {
    const YAML::Node n = todo.back();
    todo.pop_back();
    if (n.IsMap()) {
      std::set<std::string> seen;
      for (auto it = n.begin(); it != n.end(); ++it) {
        if (it->first.IsScalar() && !seen.insert(it->first.Scalar()).second)
          return DuplicateKey{it->first.Scalar(), it->first.Mark().line + 1};
        todo.push_back(it->second);
      }
    } else if (n.IsSequence()) {
      for (auto it = n.begin(); it != n.end(); ++it) todo.push_back(*it);
    }
  }
  return std::nullopt;
}

std::string duplicate_key_message(const YAML::Node& node, const std::string& file) {
  const auto d = find_duplicate_key(node);
  if (!d) return "";
  return file + ":" + std::to_string(d->line) + ": '" + d->key + "' is given twice in one mapping (the second would be ignored)";
}

std::string yaml_text_problem(std::string_view text, const std::string& file) {
  const auto nul = text.find('\0');
  if (nul == std::string_view::npos) return {};
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(nul), '\n');
  return file + ":" + std::to_string(line) + ": a NUL byte (byte " + std::to_string(nul) +
         "): YAML is text, and this file is not (the wrong file, or a damaged one?)";
}

std::string yaml_error_message(const YAML::Exception& e, const std::string& file) {
  const std::string where = file + (e.mark.is_null() ? std::string() : ":" + std::to_string(e.mark.line + 1));
  if (const auto* deep = dynamic_cast<const YAML::DeepRecursion*>(&e))
    return where + ": YAML nested deeper than the parser reads (it stops at " + std::to_string(deep->depth()) + " levels)";
  return where + ": YAML syntax error: " + e.msg;
}

std::string read_yaml_text(const std::filesystem::path& path, std::uintmax_t max_bytes, const std::string& kind) {
  const std::string file = path.string();
  if (const std::string problem = input_file_problem(path); !problem.empty()) throw ConfigError(file + ": " + problem);
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (!ec && bytes > max_bytes)
    throw ConfigError(file + ": " + std::to_string(bytes) + " bytes, more than the " + std::to_string(max_bytes >> 20) + " MB " +
                      kind + " may be");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(file + ": cannot open");
  std::string text;  // read in blocks up to the limit: a file that grew since its size was taken is seen
  char block[1 << 16];
  while (in.read(block, sizeof block) || in.gcount() > 0) {
    text.append(block, static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes)
      throw ConfigError(file + ": more than the " + std::to_string(max_bytes >> 20) + " MB " + kind + " may be");
  }
  if (const std::string problem = yaml_text_problem(text, file); !problem.empty()) throw ConfigError(problem);
  return text;
}

YAML::Node load_yaml_file(const std::filesystem::path& path, std::uintmax_t max_bytes, const std::string& kind) {
  const std::string text = read_yaml_text(path, max_bytes, kind);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(yaml_error_message(e, path.string()));
  }
  if (const std::string twice = duplicate_key_message(root, path.string()); !twice.empty()) throw ConfigError(twice);
  return root;
}

}  // namespace projbot::config
