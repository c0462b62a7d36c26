// The icp-slam .ini, checked strictly before MRPT reads it: MRPT's own reader takes "abc" as 0, "0.5" as
// 0 for a whole number, and ignores a misspelt key. What each key holds is taken from MRPT itself
// (CICP's saveToConfigFile) and from the default settings below.
#include "icp_slam_ini.hpp"

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/slam/CICP.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "projbot/config/paths.hpp"
#include "projbot/robot/localization.hpp"

namespace projbot::robot {
namespace detail {

// MRPT's icp-slam_demo_classic.ini, the settings its demo uses for a 2-D laser in a building.
const char* const kDefaultIcpSlamIni = R"ini(
[MappingApplication]
localizationLinDistance = 0.2
localizationAngDistance = 5
insertionLinDistance = 1.2
insertionAngDistance = 45.0
minICPgoodnessToAccept = 0.40
matchAgainstTheGrid = 0
occupancyGrid_count = 0
gasGrid_count = 0
beaconMap_count = 0
pointsMap_count = 1
likelihoodMapSelection = -1
[MappingApplication_pointsMap_00_insertOpts]
minDistBetweenLaserPoints = 0.05
fuseWithExisting = false
isPlanarMap = 1
[ICP]
maxIterations = 80
minAbsStep_trans = 1e-6
minAbsStep_rot = 1e-6
thresholdDist = 0.3
thresholdAng_DEG = 5
ALFA = 0.8
smallestThresholdDist = 0.05
onlyClosestCorrespondences = true
onlyUniqueRobust = true
ICP_algorithm = icpClassic
corresponding_points_decimation = 5
)ini";

}  // namespace detail
namespace {

struct IniEntry {
  std::string section, key, value;
  int line = 0;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// Sections, `key = value` lines, comments (`#` or `;` lines, `//` after a value), as MRPT reads them.
std::vector<IniEntry> parse_ini(const std::string& text, const std::string& file) {
  std::vector<IniEntry> entries;
  std::istringstream in(text);
  std::string section;
  int number = 0;
  for (std::string raw; std::getline(in, raw);) {
    ++number;
    std::string line = trim(raw.substr(0, raw.find("//")));
    if (line.empty() || line[0] == '#' || line[0] == ';') continue;
    const std::string where = file + ":" + std::to_string(number) + ": ";
    if (line[0] == '[') {
      if (line.back() != ']' || line.size() < 3) throw RobotError(where + "a section is '[name]', not '" + line + "'");
      section = trim(line.substr(1, line.size() - 2));
      continue;
    }
    const auto eq = line.find('=');
    if (eq == std::string::npos || trim(line.substr(0, eq)).empty())
      throw RobotError(where + "expected 'key = value' or '[section]', not '" + line + "'");
    if (section.empty()) throw RobotError(where + "'" + trim(line.substr(0, eq)) + "' comes before any [section]");
    entries.push_back({section, trim(line.substr(0, eq)), trim(line.substr(eq + 1)), number});
  }
  return entries;
}

enum class Kind { Integer, Real, Flag, IntegerOrFlag, Choice, Text };
struct KeyKind {
  Kind kind = Kind::Text;
  std::vector<std::string> choices;
};

bool parses_as_real(const std::string& v) {
  if (v.empty()) return false;
  char* end = nullptr;
  const double d = std::strtod(v.c_str(), &end);
  return *end == '\0' && std::isfinite(d);
}
bool parses_as_integer(const std::string& v) {
  if (v.empty()) return false;
  char* end = nullptr;
  const long long n = std::strtoll(v.c_str(), &end, 10);
  return *end == '\0' && n > -(1LL << 31) && n < (1LL << 31);
}
bool is_flag(const std::string& v) {
  const std::string l = lower(v);
  return l == "true" || l == "false" || l == "yes" || l == "no" || l == "0" || l == "1";
}

KeyKind kind_of_default(const std::string& value) {
  if (value == "0" || value == "1") return {Kind::IntegerOrFlag, {}};  // a count or a switch: both read
  if (is_flag(value)) return {Kind::Flag, {}};
  if (parses_as_integer(value)) return {Kind::Integer, {}};
  if (parses_as_real(value)) return {Kind::Real, {}};
  return {Kind::Text, {}};
}

// MRPT's names of these enumerators (an out-of-range value cast to the enum would be undefined).
template <typename Enum>
std::vector<std::string> enum_names(std::initializer_list<Enum> values) {
  std::vector<std::string> names;
  for (const Enum v : values) names.push_back(mrpt::typemeta::TEnumType<Enum>::value2name(v));
  return names;
}

// "section/key" (lower case) -> what it holds.
std::map<std::string, KeyKind> known_keys() {
  std::map<std::string, KeyKind> keys;
  mrpt::config::CConfigFileMemory icp;
  mrpt::slam::CICP::TConfigParams().saveToConfigFile(icp, "ICP");
  std::vector<std::string> names;
  icp.getAllKeys("ICP", names);
  for (const auto& k : names) keys["icp/" + lower(k)] = kind_of_default(trim(icp.read_string("ICP", k, "")));
  keys["icp/thresholdang_deg"] = {Kind::Real, {}};  // read in degrees beside thresholdAng (radians)
  keys["icp/icp_algorithm"] = {Kind::Choice, enum_names({mrpt::slam::icpClassic, mrpt::slam::icpLevenbergMarquardt})};
  keys["icp/icp_covariance_method"] = {Kind::Choice,
                                       enum_names({mrpt::slam::icpCovLinealMSE, mrpt::slam::icpCovFiniteDifferences})};
  for (const auto& e : parse_ini(detail::kDefaultIcpSlamIni, "default"))
    keys.emplace(lower(e.section) + "/" + lower(e.key), kind_of_default(e.value));
  return keys;
}

// The one problem with a value of this kind, or "".
std::string value_problem(const KeyKind& k, const std::string& v) {
  switch (k.kind) {
    case Kind::Integer:
      return parses_as_integer(v) ? "" : "is not a whole number";
    case Kind::Real:
      return parses_as_real(v) ? "" : "is not a finite number";
    case Kind::Flag:
      return is_flag(v) ? "" : "is not true/false (or 1/0, yes/no)";
    case Kind::IntegerOrFlag:
      return parses_as_integer(v) || is_flag(v) ? "" : "is not a whole number (or true/false)";
    case Kind::Choice: {
      const bool ok = std::find(k.choices.begin(), k.choices.end(), v) != k.choices.end() ||
                      (parses_as_integer(v) && std::atoi(v.c_str()) >= 0 && std::atoi(v.c_str()) < int(k.choices.size()));
      std::string all;
      for (const auto& c : k.choices) all += (all.empty() ? "" : ", ") + c;
      return ok ? "" : "is not one of " + all;
    }
    case Kind::Text:
      return "";
  }
  return "";
}

// What MRPT runs in bounded time and memory, per "section/key": typed values outside these never ended
// (thresholdDist = 1e308, smallestThresholdDist = 0, pointsMap_count = -1) or crashed inside MRPT
// (pointsMap_count = 100000).
struct Range {
  double lo, hi;
};
const std::map<std::string, Range>& value_ranges() {
  static const std::map<std::string, Range> ranges{
      {"icp/maxiterations", {1, 1000}},
      {"icp/thresholddist", {1e-3, 100}},
      {"icp/thresholdang", {0, 1.6}},
      {"icp/thresholdang_deg", {0, 90}},
      {"icp/alfa", {0.01, 0.99}},
      {"icp/smallestthresholddist", {1e-4, 100}},
      {"icp/minabsstep_trans", {1e-12, 1}},
      {"icp/minabsstep_rot", {1e-12, 1}},
      {"icp/corresponding_points_decimation", {1, 1000}},
      {"icp/ransac_minsetsize", {0, 1000}},
      {"icp/ransac_maxsetsize", {0, 10000}},
      {"icp/ransac_nsimulations", {0, 10000}},
      {"mappingapplication/localizationlindistance", {0, 100}},
      {"mappingapplication/localizationangdistance", {0, 360}},
      {"mappingapplication/insertionlindistance", {0, 100}},
      {"mappingapplication/insertionangdistance", {0, 360}},
      {"mappingapplication/minicpgoodnesstoaccept", {0, 1}},
      {"mappingapplication/occupancygrid_count", {0, 4}},
      {"mappingapplication/gasgrid_count", {0, 4}},
      {"mappingapplication/beaconmap_count", {0, 4}},
      {"mappingapplication/landmarksmap_count", {0, 4}},
      {"mappingapplication/pointsmap_count", {1, 4}},
      {"mappingapplication_pointsmap_00_insertopts/mindistbetweenlaserpoints", {0, 10}},
  };
  return ranges;
}

// "must be LO..HI" when a number lies outside what MRPT runs in bounded time, or "".
std::string range_problem(const std::string& key, const std::string& v) {
  const auto r = value_ranges().find(key);
  if (r == value_ranges().end()) return "";
  if (!parses_as_real(v)) return is_flag(v) ? "" : "is not a finite number";
  const double d = std::strtod(v.c_str(), nullptr);
  if (d >= r->second.lo && d <= r->second.hi) return "";
  std::ostringstream out;
  out << "must be " << r->second.lo << ".." << r->second.hi << " (outside, MRPT's ICP-SLAM does not end or runs out of memory)";
  return out.str();
}

}  // namespace

std::vector<std::string> check_icp_slam_config(const std::filesystem::path& ini) {
  if (const std::string kind = config::input_file_problem(ini); !kind.empty())
    throw RobotError(ini.string() + (kind == "does not exist" ? std::string(": no such icp-slam config") : ": " + kind));
  std::ifstream in(ini);
  if (!in) throw RobotError(ini.string() + ": cannot open the icp-slam config");
  std::stringstream text;
  text << in.rdbuf();
  const auto entries = parse_ini(text.str(), ini.string());
  const auto keys = known_keys();
  bool has_mapping = false, has_icp = false;
  std::vector<std::string> warnings;
  std::map<std::string, int> first_line;  // "section/key" -> where it was first given
  for (const IniEntry& e : entries) {
    if (const auto [at, added] = first_line.emplace(lower(e.section) + "/" + lower(e.key), e.line); !added)
      throw RobotError(ini.string() + ":" + std::to_string(e.line) + ": [" + e.section + "] " + e.key +
                       " is given twice (first on line " + std::to_string(at->second) + ")");
    has_mapping |= lower(e.section) == "mappingapplication";
    has_icp |= lower(e.section) == "icp";
    const auto k = keys.find(lower(e.section) + "/" + lower(e.key));
    const std::string where = ini.string() + ":" + std::to_string(e.line) + ": [" + e.section + "] " + e.key;
    if (k != keys.end())
      if (const std::string problem = value_problem(k->second, e.value); !problem.empty())
        throw RobotError(where + " = '" + e.value + "' " + problem);
    if (const std::string problem = range_problem(lower(e.section) + "/" + lower(e.key), e.value); !problem.empty())
      throw RobotError(where + " = '" + e.value + "' " + problem);
    if (k == keys.end() && lower(e.section) == "icp") warnings.push_back(where + ": not a setting of MRPT's ICP, ignored");
  }
  if (!has_mapping || !has_icp)
    throw RobotError(ini.string() + ": an icp-slam config needs [MappingApplication] and [ICP] sections");
  return warnings;
}

}  // namespace projbot::robot
