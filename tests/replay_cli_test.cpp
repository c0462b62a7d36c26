// `projbot record` then `projbot run --replay`, through the executable (issues 12, 43 and 44): the recorded
// session runs again with no device and no twin, giving the recording's poses frame for frame, the
// reflectance learnt while recording, and the same content frame for frame on the recording's clock.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cli_run.hpp"
#include "projbot/assets/image.hpp"

namespace {

namespace fs = std::filesystem;

class ReplayCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_replay_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace

namespace {

// The display's two targets, recorded at 2 stops by `projbot record` into dir/rec.
// Returns the folder and the frames recorded, as record reports them.
std::pair<fs::path, int> record_display(const fs::path& dir) {
  const fs::path rec = dir / "rec";
  const CliRun r = run_projbot("record --out " + rec.string() + " --visits 2 --dwell 1 --config " +
                                   std::string(PROJBOT_ASSET_DIR) + "/scenes/display.yaml",
                               120);
  EXPECT_EQ(r.code, 0) << r.output;
  return {rec, static_cast<int>(number_after(r.output, "recorded 2 stop(s), "))};
}

int data_rows(const fs::path& csv) {
  std::ifstream in(csv);
  int rows = -1;  // the header
  for (std::string line; std::getline(in, line);) ++rows;
  return rows;
}

}  // namespace

// Issue 12's replay: `run --replay` runs the recorded session with no device and no twin (the base and
// pan-tilt answer what they answered, each stop's dump plays) and its trackers give the recording's poses
// frame for frame (measured: every pose identical, 0.0000 mm).
TEST_F(ReplayCli, RunReplaysARecordingFrameForFrame) {
  const auto [rec, frames] = record_display(dir_);
  const int poses = data_rows(rec / "poses.csv");
  // 2 stops with a frame or more each (how many a second holds depends on how fast this machine tracks in
  // lockstep), and a pose per frame for each of the 2 lit targets (the neighbour too).
  EXPECT_GE(frames, 2);
  EXPECT_EQ(poses, 2 * frames);
  const CliRun r = run_projbot("run --headless --replay " + rec.string(), 120);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("no devices configured"), std::string::npos) << r.output;  // nor the twin
  EXPECT_EQ(number_after(r.output, "against the recording's: "), poses) << r.output;
  EXPECT_LT(number_after(r.output, "largest difference "), 0.1) << r.output;  // mm, the goal
  EXPECT_NE(r.output.find(" deg; 0 found or lost in one and not the other"), std::string::npos) << r.output;
  EXPECT_GT(number_after(r.output, "pose age at display (depth capture to expected display), "), 20.0) << r.output;
  // The twin's camera measured both targets' reflectance (display.yaml: the default light grey surface,
  // albedo 0.75, sRGB 225) and the replay compensates with what was learnt.
  for (const char* name : {"box", "duck"}) {
    const projbot::assets::Image map = projbot::assets::read_image(rec / "reflectance" / (std::string(name) + ".png"));
    double sum = 0.0;
    for (std::size_t i = 0; i < map.rgba.size(); i += 4) sum += (map.rgba[i] + map.rgba[i + 1] + map.rgba[i + 2]) / 3.0;
    EXPECT_NEAR(sum / static_cast<double>(map.rgba.size() / 4), 225.0, 20.0) << name;
  }
  EXPECT_NE(r.output.find("compensated with the reflectance learnt while recording: box (reflectance/box.png) duck "
                          "(reflectance/duck.png)"),
            std::string::npos)
      << r.output;

  // What the replay cannot do is named: options that do not apply, a scene whose tour went elsewhere, a
  // frame file gone, a recording that is not one, a learnt reflectance map gone.
  EXPECT_EQ(run_projbot("run --headless --replay " + rec.string() + " --visits 1").code, 2);
  const CliRun other = run_projbot(
      "run --headless --replay " + rec.string() + " --config " + std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml", 120);
  EXPECT_EQ(other.code, 1) << other.output;
  EXPECT_NE(other.output.find("a different scene or tour?"), std::string::npos) << other.output;
  std::ifstream index(rec / "stop02" / "INDEX.txt");
  std::string first;
  std::getline(index, first);
  fs::remove(rec / "stop02" / first);
  const CliRun gone = run_projbot("run --headless --replay " + rec.string(), 120);
  EXPECT_EQ(gone.code, 1) << gone.output;
  EXPECT_NE(gone.output.find((rec / "stop02" / first).string() + ": cannot open"), std::string::npos) << gone.output;
  EXPECT_NE(gone.output.find("(the projection was blanked"), std::string::npos) << gone.output;
  fs::copy_file(rec / "poses.csv", dir_ / "poses.csv");
  std::ofstream(rec / "poses.csv", std::ios::trunc).flush();  // emptied
  const CliRun empty = run_projbot("run --headless --replay " + rec.string());
  EXPECT_EQ(empty.code, 1) << empty.output;
  EXPECT_NE(empty.output.find("poses.csv:1: not the poses of a recording"), std::string::npos) << empty.output;
  fs::copy_file(dir_ / "poses.csv", rec / "poses.csv", fs::copy_options::overwrite_existing);
  std::ofstream(rec / "recording.yaml", std::ios::app) << "extra: 1\n";
  const CliRun bad = run_projbot("run --headless --replay " + rec.string());
  EXPECT_EQ(bad.code, 1) << bad.output;
  EXPECT_NE(bad.output.find("recording.yaml:"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("extra: unknown key"), std::string::npos) << bad.output;
  const CliRun none = run_projbot("run --headless --replay " + (dir_ / "nothing").string());
  EXPECT_EQ(none.code, 1) << none.output;
  EXPECT_NE(none.output.find("no such recording folder"), std::string::npos) << none.output;
  fs::remove(rec / "reflectance" / "box.png");
  const CliRun no_map = run_projbot("run --headless --replay " + rec.string());
  EXPECT_EQ(no_map.code, 1) << no_map.output;
  EXPECT_NE(no_map.output.find("reflectance.box: no such file: "), std::string::npos) << no_map.output;
}

namespace {

// A --profile CSV's rows, each split into its cells (the header left out).
std::vector<std::vector<std::string>> profile_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string c; std::getline(row, c, ',');) cells.push_back(c);
    cells.resize(13);  // trailing empty cells of a blank frame
    rows.push_back(std::move(cells));
  }
  return rows;
}

}  // namespace

// Issue 44, one clock: a replay runs on the recording's clock, so it draws the same frames, poses and
// content every time, however fast the machine. The shipped content scene (a 30 fps clip on both targets
// from the tour's start) recorded at 2 stops and replayed twice: frame for frame the same run clock,
// target, pose age, content time, video frame and position; each frame one 60 Hz refresh of the clock;
// each video frame shown the one due at its content time (the decoder waited for, never repeated).
TEST_F(ReplayCli, AReplayDrawsTheSameContentFrameForFrameOnTheRecordingsClock) {
  const fs::path rec = dir_ / "rec";
  const CliRun r = run_projbot("record --out " + rec.string() + " --visits 2 --dwell 1 --config " +
                                   std::string(PROJBOT_ASSET_DIR) + "/scenes/content.yaml",
                               180);
  ASSERT_EQ(r.code, 0) << r.output;
  std::vector<std::vector<std::vector<std::string>>> runs;
  for (const char* name : {"a.csv", "b.csv"}) {
    const CliRun replay = run_projbot("run --headless --replay " + rec.string() + " --profile " + (dir_ / name).string(), 300);
    ASSERT_EQ(replay.code, 0) << replay.output;
    EXPECT_NE(replay.output.find(" deg; 0 found or lost in one and not the other"), std::string::npos) << replay.output;
    EXPECT_NE(replay.output.find(" 0 repeated"), std::string::npos) << replay.output;  // content's summary
    runs.push_back(profile_rows(dir_ / name));
  }
  const auto& a = runs[0];
  ASSERT_EQ(a.size(), runs[1].size());
  ASSERT_GT(a.size(), 120U);  // two dwells of 1 s at 60 Hz, and the drives
  std::set<std::string> lit;
  double lead_s = std::nan("");
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (const std::size_t c : {2, 3, 7, 8, 9, 10, 11, 12})  // pose age, target, clock, content, video, position
      EXPECT_EQ(a[i][c], runs[1][i][c]) << "frame " << i << ", column " << c;
    EXPECT_NEAR(std::stod(a[i][7]), static_cast<double>(i + 1) / 60.0, 1e-6) << i;  // one refresh a frame
    if (a[i][3].empty()) continue;                                                  // blank: driving, acquiring
    lit.insert(a[i][3]);
    // Content from the tour's start, on the frame's display time: a fixed lead over the frame's start.
    const double content = std::stod(a[i][8]), pts = std::stod(a[i][9]);
    if (std::isnan(lead_s)) lead_s = content - std::stod(a[i][7]);
    EXPECT_NEAR(content - std::stod(a[i][7]), lead_s, 1e-5) << i;
    EXPECT_LE(pts, content + 1e-5) << i;  // the frame due: the last one presented at or before it
    EXPECT_GT(pts + 1.0 / 30.0, content + 1e-5) << i;
  }
  EXPECT_EQ(lit, (std::set<std::string>{"duck", "box"}));
  EXPECT_GT(lead_s, 0.0);  // one refresh ahead, and the projector's input lag
  EXPECT_LT(lead_s, 0.1);
}
