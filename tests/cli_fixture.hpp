#pragma once
// What the executable's tests share: a scratch folder per test, projbot run in the background (for
// the tests that signal it), and the shared data they read.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "cli_run.hpp"
#include "projbot/assets/image.hpp"

namespace fs = std::filesystem;

namespace cli_fixture {

// projbot started in the background with its output in a file, for tests that signal it.
struct Background {
  pid_t pid = -1;
  std::filesystem::path log;

  Background(const std::vector<std::string>& args, std::filesystem::path log_file) : log(std::move(log_file)) {
    std::vector<std::string> all{PROJBOT_EXE};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    // As from a terminal: no signal blocked, SIGINT and SIGTERM at their defaults (a test runner started
    // in the background may pass them on ignored or blocked).
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    sigset_t none, defaults;
    sigemptyset(&none);
    sigemptyset(&defaults);
    sigaddset(&defaults, SIGINT);
    sigaddset(&defaults, SIGTERM);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
    if (posix_spawn(&pid, PROJBOT_EXE, &actions, &attr, argv.data(), environ) != 0) pid = -1;
    posix_spawnattr_destroy(&attr);
    posix_spawn_file_actions_destroy(&actions);
  }
  ~Background() {
    if (pid > 0 && waitpid(pid, nullptr, WNOHANG) == 0) {
      kill(pid, SIGKILL);
      waitpid(pid, nullptr, 0);
    }
  }
  std::string output() const {
    std::ifstream in(log);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  // Waits (up to `limit`) until the output contains `text`.
  bool wait_for_output(const std::string& text, std::chrono::seconds limit) const {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      if (output().find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return false;
  }
  // Sends `sig`, waits for the exit; returns the exit code (-1 for a signal death or a timeout) and
  // the seconds from the signal to the exit.
  std::pair<int, double> signal_and_wait(int sig, std::chrono::seconds limit) {
    const auto t0 = std::chrono::steady_clock::now();
    kill(pid, sig);
    int status = 0;
    while (waitpid(pid, &status, WNOHANG) == 0) {
      if (std::chrono::steady_clock::now() - t0 > limit) return {-1, 1e9};
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    pid = -1;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, s};
  }
};

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    write("bad.pcd", "# .PCD v0.7\nFIELDS x y z\nthis is not a point cloud\n");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

// The lines of a trajectory file written by slam or localize; each must be `timestamp x y phi`.
inline int trajectory_lines(const fs::path& file) {
  std::ifstream in(file);
  int lines = 0;
  for (std::string line; std::getline(in, line); ++lines) {
    double ts, x, y, phi;
    EXPECT_EQ(std::sscanf(line.c_str(), "%lf %lf %lf %lf", &ts, &x, &y, &phi), 4) << file << ": " << line;
  }
  return lines;
}

inline const std::string kDuck = std::string(PROJBOT_SHARED_DATA) + "/gltf/Duck/glTF-Binary/Duck.glb";
inline const std::string kRawlog = std::string(PROJBOT_SHARED_DATA) + "/mrpt/localization_demo.rawlog";

// A shipped scene's text (assets/scenes/NAME) with its models' paths made absolute, for a test's own site
// file written elsewhere.
inline std::string shipped_scene(const std::string& name) {
  std::ifstream in(fs::path(PROJBOT_ASSET_DIR) / "scenes" / name);
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  for (std::size_t at = 0; (at = text.find("../models/", at)) != std::string::npos;)
    text.replace(at, 3, std::string(PROJBOT_ASSET_DIR) + "/");
  return text;
}

}  // namespace cli_fixture
