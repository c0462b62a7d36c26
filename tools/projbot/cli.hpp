#pragma once
// Command-line parsing for the projbot subcommands: declared options, so unknown flags and missing
// values are reported with the subcommand's help.

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace projbot::cli {

/// A wrong command line: printed with a pointer to --help, exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OptionSpec {
  std::string name;   ///< without the leading dashes
  std::string value;  ///< placeholder shown in help ("FILE"); empty for a flag
  std::string help;
};

class Args {
 public:
  /// Parses argv[first..] against `specs`. Throws UsageError on unknown options or missing values.
  Args(const std::vector<OptionSpec>& specs, int argc, char** argv, int first);

  bool flag(const std::string& name) const { return values_.contains(name); }
  std::optional<std::string> get(const std::string& name) const;
  /// Every value of a repeatable option, in the order given (get() returns the last).
  std::vector<std::string> get_all(const std::string& name) const;
  std::string get_or(const std::string& name, const std::string& fallback) const;
  int get_int(const std::string& name, int fallback, int min_value, int max_value) const;
  double get_double(const std::string& name, double fallback) const;
  const std::vector<std::string>& positional() const { return positional_; }
  /// Before long work: each given file option (`out`, `report`, ...) can be written (its folder exists
  /// and is writable, it is no folder). Throws UsageError naming the option and the problem.
  void check_output_files(const std::vector<std::string>& names) const;
  /// Each given folder option exists as a folder, or can be created (its parent exists and is writable).
  void check_output_folders(const std::vector<std::string>& names) const;

 private:
  std::map<std::string, std::string> values_;
  std::map<std::string, std::vector<std::string>> all_;
  std::vector<std::string> positional_;
};

/// A distance and an angle given as "D,DEG" (a guess's or a start's error), the distance in `unit` ("mm",
/// "cm") within 0..max_distance and the angle within 0..180 degrees. Throws UsageError naming `option`.
std::pair<double, double> parse_distance_angle(const std::string& text, const std::string& option, const std::string& unit,
                                               int max_distance);

/// "  --scene FILE     help" lines for a subcommand's help text.
std::string format_options(const std::vector<OptionSpec>& specs);

}  // namespace projbot::cli
