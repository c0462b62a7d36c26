// The hostile-input suite (ctest label `hostile`, also run under ASan/UBSan): bad files of every format
// projbot reads and bad arguments of every command, through the executable. Every case must end with
// exit 1 (bad input) or 2 (bad usage), never a signal; print a message naming the file or option; and
// leave its scratch folder exactly as it was (no output created, no previous output changed).

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <map>
#include <random>
#include <sstream>

#include "cli_run.hpp"
#include "hostile_cases.hpp"

namespace {

using namespace hostile;

std::string expand(std::string s, const fs::path& dir) {
  s = replace_all(s, "{duck}", "{data}/gltf/Duck/glTF-Binary/Duck.glb");
  s = replace_all(s, "{rawlog}", "{data}/mrpt/localization_demo.rawlog");
  s = replace_all(s, "{dir}", dir.string());
  s = replace_all(s, "{data}", PROJBOT_SHARED_DATA);
  s = replace_all(s, "{made}", PROJBOT_GENERATED_ASSET_DIR);  // what the build made for assets/
  return replace_all(s, "{src}", PROJBOT_SOURCE_DIR);
}

std::string content(const std::string& spec) {
  if (spec.rfind("@random:", 0) == 0) {
    std::mt19937 rng(7);
    std::string bytes(std::stoul(spec.substr(8)), '\0');
    for (auto& c : bytes) c = static_cast<char>(rng() & 0xff);
    return bytes;
  }
  if (spec.rfind("@head:", 0) == 0) {
    const auto colon = spec.find(':', 6);
    std::ifstream in(spec.substr(colon + 1), std::ios::binary);
    std::string bytes(std::stoul(spec.substr(6, colon - 6)), '\0');
    in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
    return bytes;
  }
  return spec;
}

// Every file under `dir`: its path, size and bytes.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    std::string bytes;
    if (e.is_regular_file()) {
      std::ifstream in(e.path(), std::ios::binary);
      std::stringstream s;
      s << in.rdbuf();
      bytes = s.str();
    }
    files[e.path().string()] = (e.is_directory() ? "dir:" : "file:") + bytes;
  }
  return files;
}

class HostileTest : public ::testing::TestWithParam<Hostile> {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_hostile_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "goodmap");
    // Outputs of an earlier run, which a failed run must leave as they are.
    for (const char* name : {"prev.png", "prev.json", "prev.csv", "prev.txt"}) std::ofstream(dir_ / name) << "earlier output\n";
    fs::copy_file(fs::path(PROJBOT_SHARED_DATA) / "mrpt" / "localization_demo.simplemap.gz",
                  dir_ / "goodmap" / "map.simplemap.gz");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_P(HostileTest, ExitsCleanlyNamingTheProblemAndWritesNothing) {
  const Hostile& h = GetParam();
  for (const auto& [name, spec] : h.files.list) {
    fs::create_directories((dir_ / name).parent_path());
    if (spec == "@fifo")
      ASSERT_EQ(::mkfifo((dir_ / name).c_str(), 0644), 0);
    else if (spec.rfind("@link:", 0) == 0)
      fs::create_symlink(spec.substr(6), dir_ / name);
    else
      std::ofstream(dir_ / name, std::ios::binary) << content(expand(spec, dir_));
  }
  const auto before = snapshot(dir_);
  const CliRun r = run_projbot(expand(h.args, dir_), 120);
  EXPECT_EQ(r.code, h.code) << r.output;
  EXPECT_TRUE(r.code == 1 || r.code == 2) << "exit " << r.code << ": " << r.output;
  for (const auto& part : h.must_contain)
    EXPECT_NE(r.output.find(expand(part, dir_)), std::string::npos) << "'" << part << "' not in: " << r.output;
  for (const char* crash : {"terminate called", "AddressSanitizer", "runtime error:", "Assertion", "core dumped"})
    EXPECT_EQ(r.output.find(crash), std::string::npos) << crash << " in: " << r.output;
  // A library's own exception text says nothing to someone mending the file (issue 72).
  for (const char* bare : {"[json.exception.", "std::bad_alloc"})
    EXPECT_EQ(r.output.find(bare), std::string::npos) << bare << " in: " << r.output;
  const auto after = snapshot(dir_);
  for (const auto& [path, bytes] : after) {
    const auto was = before.find(path);
    EXPECT_TRUE(was != before.end()) << path << " was created";
    if (was != before.end()) {
      EXPECT_TRUE(was->second == bytes) << path << " was changed";
    }
  }
  for (const auto& [path, bytes] : before) EXPECT_TRUE(after.count(path) == 1) << path << " was removed";
}

std::vector<Hostile> all_cases() {
  std::vector<Hostile> cases;
  for (auto list : {usage_cases(), clash_cases(), cloud_cases(), file_cases(), argument_cases()})
    cases.insert(cases.end(), list.begin(), list.end());
  return cases;
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cases, HostileTest, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Hostile>& param_info) { return param_info.param.name; });

TEST(HostileSuite, HasAtLeast120Cases) { EXPECT_GE(all_cases().size(), 120u); }
