#include "cli.hpp"

#include <unistd.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>
#include <sstream>

#include "projbot/config/output_file.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::cli {

Args::Args(const std::vector<OptionSpec>& specs, int argc, char** argv, int first) {
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0 || arg == "--") {
      positional_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::optional<std::string> inline_value;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    const OptionSpec* spec = nullptr;
    for (const auto& s : specs)
      if (s.name == name) spec = &s;
    if (spec == nullptr) throw UsageError("unknown option --" + name);
    if (spec->role != PathRole::none) roles_[name] = spec->role;
    if (spec->value.empty()) {
      if (inline_value) throw UsageError("--" + name + " takes no value");
      values_[name] = "1";
    } else if (inline_value) {
      values_[name] = *inline_value;
    } else {
      if (i + 1 >= argc) throw UsageError("--" + name + " needs a value (" + spec->value + ")");
      values_[name] = argv[++i];
    }
    if (!spec->value.empty()) all_[name].push_back(values_[name]);
  }
}

std::optional<std::string> Args::get(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  return std::nullopt;
}

std::pair<double, double> parse_distance_angle(const std::string& text, const std::string& option, const std::string& unit,
                                               int max_distance) {
  double distance = 0.0, deg = 0.0;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf%c", &distance, &deg, &extra) != 2 || !(distance >= 0.0 && distance <= max_distance) ||
      !(deg >= 0.0 && deg <= 180.0)) {
    std::string upper = unit;
    for (auto& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    throw UsageError("--" + option + " must be " + upper + ",DEG with 0.." + std::to_string(max_distance) + " " + unit +
                     " and 0..180 degrees, not '" + text + "'");
  }
  return {distance, deg};
}

std::vector<std::string> Args::get_all(const std::string& name) const {
  if (auto it = all_.find(name); it != all_.end()) return it->second;
  return {};
}

std::vector<std::string> Args::get_list(const std::string& name) const {
  std::vector<std::string> out;
  std::stringstream in(get_or(name, ""));
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string Args::get_or(const std::string& name, const std::string& fallback) const { return get(name).value_or(fallback); }

int Args::get_int(const std::string& name, int fallback, int min_value, int max_value) const {
  const auto v = get(name);
  if (!v) return fallback;
  int out = 0;
  const auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), out);
  if (ec != std::errc() || end != v->data() + v->size() || out < min_value || out > max_value)
    throw UsageError("--" + name + " must be an integer in " + std::to_string(min_value) + ".." + std::to_string(max_value) +
                     ", got '" + *v + "'");
  return out;
}

void Args::check_outputs() const {
  namespace fs = std::filesystem;
  for (const auto& entry : roles_) {
    const std::string& name = entry.first;  // not a structured binding: clang 14 cannot capture one
    const PathRole role = entry.second;
    const auto value = get(name);
    if (!value) continue;
    const auto check = [&](const auto& how, const fs::path& p) {
      try {
        how(p);
      } catch (const config::OutputError& e) {
        throw UsageError("--" + name + " " + e.what());
      }
    };
    if (role == PathRole::output_file) check(config::check_writable, *value);
    if (role != PathRole::output_folder) continue;
    std::error_code ec;
    const fs::path dir = fs::path(*value).lexically_normal();
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
      throw UsageError("--" + name + " " + *value + ": exists and is not a folder");
    fs::path parent = dir;
    if (!fs::is_directory(dir, ec)) {
      parent = dir.has_filename() ? dir.parent_path() : dir.parent_path().parent_path();
      if (parent.empty()) parent = ".";
      if (!fs::is_directory(parent, ec))
        throw UsageError("--" + name + " " + *value + ": its parent folder " + parent.string() + " does not exist");
    }
    check(config::check_folder_writable, parent);
  }
}

void Args::named_paths(std::vector<config::NamedPath>& inputs, std::vector<config::NamedPath>& outputs) const {
  for (const auto& [name, role] : roles_) {
    const auto value = get(name);
    if (!value || role == PathRole::none) continue;
    const bool folder = role == PathRole::input_folder || role == PathRole::output_folder;
    const bool input = role == PathRole::input_file || role == PathRole::input_folder;
    (input ? inputs : outputs).push_back({"--" + name, *value, folder});
  }
}

void Args::check_paths(const std::vector<config::NamedPath>& more_inputs) const {
  std::vector<config::NamedPath> inputs = more_inputs, outputs;
  named_paths(inputs, outputs);
  // A FIFO, device or socket is refused here, before anything opens it (open() on a FIFO blocks,
  // /dev/zero never ends); a missing file or a folder is left to the reader, which names it.
  for (std::size_t i = more_inputs.size(); i < inputs.size(); ++i)
    if (const std::string problem = config::input_file_problem(inputs[i].path);
        problem.find("not a regular file") != std::string::npos)
      throw InputError(inputs[i].name + " " + inputs[i].path.string() + ": " + problem);
  // Outputs among themselves first: one inside another's folder is that clash, not a missing folder (the
  // folder is made by the run). Then each output's own checks, then outputs against inputs.
  if (const auto clash = config::find_path_clash({}, outputs)) throw UsageError(*clash);
  check_outputs();
  if (const auto clash = config::find_path_clash(inputs, outputs)) throw UsageError(*clash);
}

void Args::check_clashes(const std::vector<config::NamedPath>& more_inputs) const {
  std::vector<config::NamedPath> inputs = more_inputs, outputs;
  named_paths(inputs, outputs);
  if (const auto clash = config::find_path_clash(inputs, outputs)) throw UsageError(*clash);
}

double Args::get_double(const std::string& name, double fallback) const {
  const auto v = get(name);
  if (!v) return fallback;
  double out = 0;
  const auto [end, ec] = std::from_chars(v->data(), v->data() + v->size(), out);
  if (ec != std::errc() || end != v->data() + v->size() || !std::isfinite(out))
    throw UsageError("--" + name + " must be a finite number, got '" + *v + "'");
  return out;
}

void check_new_folder(const std::string& folder, const std::string& needs) {
  std::error_code ec;
  if (std::filesystem::exists(folder, ec) && !std::filesystem::is_empty(folder, ec))
    throw UsageError(folder + ": not empty; " + needs);
}

std::vector<double> spaced_numbers(const std::string& text, std::size_t count, const std::string& what) {
  static const std::regex separator(R"(\s*,\s*|\s+)");
  const std::size_t first = text.find_first_not_of(" \t"), last = text.find_last_not_of(" \t");
  const std::string trimmed = first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
  return config::parse_number_list(std::regex_replace(trimmed, separator, ","), count, what);
}

std::string format_options(const std::vector<OptionSpec>& specs) {
  std::ostringstream out;
  for (const auto& s : specs) {
    std::string head = "  --" + s.name + (s.value.empty() ? "" : " " + s.value);
    if (head.size() < 28)
      head.resize(28, ' ');
    else
      head += "\n" + std::string(28, ' ');
    out << head << s.help << '\n';
  }
  return out.str();
}

}  // namespace projbot::cli
