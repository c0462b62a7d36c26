#pragma once
// Command-line parsing for the projbot subcommands: declared options, so unknown flags and missing
// values are reported with the subcommand's help.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "projbot/config/paths.hpp"

namespace projbot::cli {

/// A wrong command line: printed with a pointer to --help, exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What an option's value names on disk, so every command checks its paths the same way before work.
enum class PathRole { none, input_file, input_folder, output_file, output_folder };

/// An input that cannot be read as named (a FIFO or a device for a file): exit code 1, as a bad file.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string name;   ///< without the leading dashes
  std::string value;  ///< placeholder shown in help ("FILE"); empty for a flag
  std::string help;
  PathRole role = PathRole::none;
};

class Args {
 public:
  /// Parses argv[first..] against `specs`. Throws UsageError on unknown options or missing values.
  Args(const std::vector<OptionSpec>& specs, int argc, char** argv, int first);

  bool flag(const std::string& name) const { return values_.contains(name); }
  std::optional<std::string> get(const std::string& name) const;
  /// Every value of a repeatable option, in the order given (get() returns the last).
  std::vector<std::string> get_all(const std::string& name) const;
  /// A comma-separated option ("--scenes A,B") as its non-empty items; empty when not given.
  std::vector<std::string> get_list(const std::string& name) const;
  std::string get_or(const std::string& name, const std::string& fallback) const;
  int get_int(const std::string& name, int fallback, int min_value, int max_value) const;
  double get_double(const std::string& name, double fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  /// Before any work, the paths of the options with a PathRole: no input is a FIFO, device or socket
  /// (InputError; a missing file is the reader's to name); each output file can be written (its folder
  /// exists and is writable, it is no folder) and each output folder exists or can be created; and no
  /// output clashes with an input (those options' and `more_inputs`: defaults, arguments) or another
  /// output (config::find_path_clash). Throws UsageError naming the option(s) and the problem.
  void check_paths(const std::vector<config::NamedPath>& more_inputs = {}) const;
  /// Only the clash part of check_paths, for inputs a command learns after the dispatcher's check (a
  /// default scene): the options' paths against `more_inputs` and each other. Throws UsageError.
  void check_clashes(const std::vector<config::NamedPath>& more_inputs) const;

 private:
  void check_outputs() const;
  void named_paths(std::vector<config::NamedPath>& inputs, std::vector<config::NamedPath>& outputs) const;
  std::map<std::string, PathRole> roles_;
  std::map<std::string, std::string> values_;
  std::map<std::string, std::vector<std::string>> all_;
  std::vector<std::string> positional_;
};

/// A distance and an angle given as "D,DEG" (a guess's or a start's error), the distance in `unit` ("mm",
/// "cm") within 0..max_distance and the angle within 0..180 degrees. Throws UsageError naming `option`.
std::pair<double, double> parse_distance_angle(const std::string& text, const std::string& option, const std::string& unit,
                                               int max_distance);

/// `count` numbers separated by commas or spaces ("x y phi", "0.1, 0.2, 0.3"): config::parse_number_list's
/// checks and errors naming `what`.
std::vector<double> spaced_numbers(const std::string& text, std::size_t count, const std::string& what);

/// An output folder that must be new or empty (a recording, learnt surfaces): one holding anything is a
/// UsageError "FOLDER: not empty; `needs`".
void check_new_folder(const std::string& folder, const std::string& needs);

/// "  --scene FILE     help" lines for a subcommand's help text.
std::string format_options(const std::vector<OptionSpec>& specs);

}  // namespace projbot::cli
