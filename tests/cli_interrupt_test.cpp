// Long commands through the executable stopped by Ctrl-C or SIGTERM: what was measured is kept and
// written, the exit code says which signal; and progress shown on a terminal only.

#include "cli_fixture.hpp"

using namespace cli_fixture;

// Ctrl-C in the live engine: it stops at the next frame, prints its summary, writes the whole profile
// and exits 130. The goal, within a second, is a figure for the closing note, not asserted here: beside a
// build and a benchmark the stop once took 1.19 s; what is asserted is that it stops, promptly.
TEST_F(CliTest, RunInterruptedKeepsTheProfile) {
  const fs::path csv = dir_ / "p.csv";
  Background run({"run", "--headless", "--profile", csv.string()}, dir_ / "run.log");
  ASSERT_GT(run.pid, 0);
  ASSERT_TRUE(run.wait_for_output("device:", std::chrono::seconds(60))) << run.output();
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const auto [code, seconds] = run.signal_and_wait(SIGINT, std::chrono::seconds(30));
  EXPECT_EQ(code, 130) << run.output();
  EXPECT_LT(seconds, 5.0);
  const std::string out = run.output();
  EXPECT_NE(out.find("frame time p50"), std::string::npos) << out;
  EXPECT_NE(out.find("per-frame profile written to"), std::string::npos) << out;
  std::ifstream in(csv);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line,
            "frame,start_ms,pose_age_ms,target,capture_ms,display_ms,error_mm,clock_s,content_s,video_pts_s,x_mm,y_mm,z_mm");
  int rows = 0, lit = 0;
  for (; std::getline(in, line); ++rows) {
    ASSERT_EQ(std::count(line.begin(), line.end(), ','), 12) << line;
    std::vector<std::string> f;
    std::istringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
    if (f.size() < 6 || f[2].empty()) continue;  // a blank frame (the last cell, empty, is not read)
    ++lit;
    // Display one refresh after the pose was read, which is at or after the frame's start (later when
    // acquiring an image waited); the capture before that read, so at least a refresh before display (not
    // before the frame's start: a pose captured while the frame waited for its image is read, 3304 ms
    // against a start at 3294 in a clean-clone CI). The refresh is the measured present cadence, the
    // median of the last 31 frame intervals: about 16.7 ms at 60 Hz, a little under when frames catch up
    // after a late one (16.47 ms in a clean-clone CI). The age at least the time between capture and
    // display (more when the frame took longer than a refresh).
    const double start = std::stod(f[1]), age = std::stod(f[2]), capture = std::stod(f[4]), display = std::stod(f[5]);
    EXPECT_LT(capture, display - 15.0) << line;
    EXPECT_GE(display - start, 15.0) << line;
    EXPECT_LT(display - start, 16.7 + 100.0) << line;
    EXPECT_GE(age, display - capture - 0.01) << line;
  }
  EXPECT_GT(lit, 0);
  EXPECT_GT(rows, 100) << "about 5 s at 60 Hz";
}

// MRPT's own log lines only with --verbose, and then on stderr (stdout carries the results).
TEST_F(CliTest, MrptLogsOnlyWithVerbose) {
  const std::string base =
      "slam --rawlog " + kRawlog + " --out-map " + (dir_ / "m").string() + " --out-trajectory " + (dir_ / "t.txt").string();
  const CliRun quiet = run_projbot(base);
  ASSERT_EQ(quiet.code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find("MRPT"), std::string::npos) << quiet.output;
  const CliRun verbose = run_projbot(base + " --verbose");
  ASSERT_EQ(verbose.code, 0) << verbose.output;
  EXPECT_NE(verbose.output.find("[MRPT CMetricMapBuilderICP]"), std::string::npos) << verbose.output;
  FILE* pipe = popen((std::string(PROJBOT_EXE) + " " + base + " --verbose 2>/dev/null").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  for (std::array<char, 512> buf{}; fgets(buf.data(), buf.size(), pipe) != nullptr;) out += buf.data();
  EXPECT_EQ(pclose(pipe), 0);
  EXPECT_NE(out.find("ICP-SLAM: 37 scans"), std::string::npos) << out;
  EXPECT_EQ(out.find("MRPT"), std::string::npos) << "MRPT lines on stdout: " << out;
}

// Ctrl-C and SIGTERM in the benchmarks: the rows measured are printed whole, the run under way is dropped
// and named, exit 130 / 143 within a second.
TEST_F(CliTest, BenchmarksInterruptedKeepTheRowsDone) {
  struct Case {
    std::vector<std::string> args;
    std::string wait_for;
    int sig;
    std::string says;
  };
  const std::vector<Case> cases{
      {{"bench", "render", "--offscreen-only", "--sizes", "64x48,64x48", "--frames", "400"},
       "sphere100k",
       SIGINT,
       "interrupted after"},
      {{"bench", "localize", "--stops", "3,3,3,3,3,3,3,3"}, "| 3 | odometry alone |", SIGTERM, "the rows above are complete"},
      {{"bench", "track", "--frames", "2000"}, "rendering 2000 frames", SIGINT, "interrupted while rendering"},
      // In the first of its two runs: the visits it finished, the second run's cells "-".
      {{"bench", "motion", "--depth-model", "kinect"},
       "prediction off: 1 ",
       SIGINT,
       "| 1 | duck | still | - | - | 0 / - | - / - | 0."},
      // Inside its first trial (PCL's pipeline runs for seconds): answered at once, the trial dropped (issue 72).
      {{"bench", "acquire", "--trials", "2"}, "|---|---|", SIGTERM, "interrupted at figure, trial 1; the rows above"}};
  for (const auto& c : cases) {
    Background run(c.args, dir_ / "bench.log");
    ASSERT_GT(run.pid, 0);
    ASSERT_TRUE(run.wait_for_output(c.wait_for, std::chrono::seconds(120))) << run.output();
    const auto [code, seconds] = run.signal_and_wait(c.sig, std::chrono::seconds(30));
    EXPECT_EQ(code, 128 + c.sig) << run.output();
    // Promptly, not at the end of the run (seconds more): 1.06 s was seen with two suites at once.
    EXPECT_LT(seconds, 2.0) << c.args[1];
    EXPECT_NE(run.output().find(c.says), std::string::npos) << run.output();
  }
}

// Ctrl-C in a tour: the visits finished so far are in the report, marked interrupted; exit 130.
TEST_F(CliTest, TourInterruptedKeepsTheFinishedVisits) {
  const fs::path report = dir_ / "r.json";
  Background tour({"tour", "--visits", "6", "--report", report.string()}, dir_ / "tour.log");
  ASSERT_GT(tour.pid, 0);
  ASSERT_TRUE(tour.wait_for_output("visit 1 (", std::chrono::seconds(120))) << tour.output();
  const auto [code, seconds] = tour.signal_and_wait(SIGINT, std::chrono::seconds(120));
  EXPECT_EQ(code, 130) << tour.output();
  std::ifstream in(report);
  ASSERT_TRUE(in) << tour.output();
  const auto json = nlohmann::json::parse(in);
  EXPECT_TRUE(json.at("interrupted").get<bool>());
  EXPECT_GE(json.at("visits").size(), 1U);
  EXPECT_LT(json.at("visits").size(), 6U);
  EXPECT_NE(tour.output().find("interrupted"), std::string::npos);
}

// Ctrl-C while recording: the stop in progress ends there and every stop is kept, marked interrupted; the
// recording replays as it is; exit 130.
TEST_F(CliTest, RecordInterruptedKeepsTheStopsAndReplays) {
  const fs::path rec = dir_ / "rec";
  Background record({"record", "--out", rec.string(), "--visits", "6", "--dwell", "3"}, dir_ / "record.log");
  ASSERT_GT(record.pid, 0);
  ASSERT_TRUE(record.wait_for_output("stop 1: duck, ", std::chrono::seconds(120))) << record.output();
  const auto [code, seconds] = record.signal_and_wait(SIGINT, std::chrono::seconds(60));
  EXPECT_EQ(code, 130) << record.output();
  std::ifstream in(rec / "recording.yaml");
  std::stringstream yaml;
  yaml << in.rdbuf();
  EXPECT_NE(yaml.str().find("interrupted: true"), std::string::npos) << yaml.str();
  EXPECT_NE(yaml.str().find("frames: \"stop02\""), std::string::npos) << yaml.str();  // the stop in progress, cut short
  EXPECT_EQ(yaml.str().find("frames: \"stop04\""), std::string::npos) << yaml.str();
  const CliRun replay = run_projbot("run --headless --replay " + rec.string(), 120);
  EXPECT_EQ(replay.code, 0) << replay.output;
  EXPECT_NE(replay.output.find(" deg; 0 found or lost in one and not the other; 0 recorded rows for frames the replay did not "
                               "reach"),
            std::string::npos)
      << replay.output;
  // The poses read as strictly as any input (issue 47: these replayed as "largest difference 0.0000 mm").
  std::ifstream csv_in(rec / "poses.csv");
  std::stringstream csv;
  csv << csv_in.rdbuf();
  const std::string good = csv.str();
  const std::string first_row = good.substr(good.find('\n') + 1, good.find('\n', good.find('\n') + 1) - good.find('\n'));
  const auto replay_with = [&](const std::string& text) {
    std::ofstream(rec / "poses.csv", std::ios::trunc) << text;
    return run_projbot("run --headless --replay " + rec.string(), 120);
  };
  const std::string nan = good.substr(0, good.rfind(',')) + ",nan\n";  // the last row's last number NaN
  const CliRun with_nan = replay_with(nan);
  EXPECT_EQ(with_nan.code, 1) << with_nan.output;
  EXPECT_NE(with_nan.output.find("poses.csv:"), std::string::npos) << with_nan.output;
  EXPECT_NE(with_nan.output.find("a value is not a finite number"), std::string::npos) << with_nan.output;
  const CliRun twice = replay_with(good + first_row);
  EXPECT_EQ(twice.code, 1) << twice.output;
  EXPECT_NE(twice.output.find("a second row for visit"), std::string::npos) << twice.output;
  std::string beyond = first_row;  // the first row moved to a frame that does not exist
  const auto c1 = beyond.find(','), c2 = beyond.find(',', c1 + 1);
  beyond.replace(c1 + 1, c2 - c1 - 1, "99999");
  const CliRun unreached = replay_with(good + beyond);
  EXPECT_EQ(unreached.code, 0) << unreached.output;
  EXPECT_NE(unreached.output.find("; 1 recorded rows for frames the replay did not reach"), std::string::npos)
      << unreached.output;
}

// Ctrl-C in ICP-SLAM: the scans done so far are mapped and their trajectory written; exit 130.
TEST_F(CliTest, SlamInterruptedKeepsTheScansDone) {
  const std::string rawlog = std::string(PROJBOT_SHARED_DATA) + "/mrpt/range_030_bearing_015.rawlog";  // 1460 scans, ~2.5 s
  const fs::path trajectory = dir_ / "t.txt";
  Background slam({"slam", "--rawlog", rawlog, "--out-map", (dir_ / "map").string(), "--out-trajectory", trajectory.string()},
                  dir_ / "slam.log");
  ASSERT_GT(slam.pid, 0);
  ASSERT_TRUE(slam.wait_for_output("mapping 1460 scans", std::chrono::seconds(60))) << slam.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto [code, seconds] = slam.signal_and_wait(SIGINT, std::chrono::seconds(30));
  if (code == 0) GTEST_SKIP() << "the run ended before the signal (a very fast machine): " << slam.output();
  EXPECT_EQ(code, 130) << slam.output();
  EXPECT_NE(slam.output().find("ICP-SLAM interrupted after"), std::string::npos) << slam.output();
  EXPECT_TRUE(fs::exists(dir_ / "map" / "map.simplemap.gz"));
  EXPECT_LT(trajectory_lines(trajectory), 1460);
}

// Ctrl-C while slam still reads its rawlog: nothing is written, an earlier map and trajectory stay as they
// were (they were once replaced by an empty map, "0 of 1460 scans").
TEST_F(CliTest, SlamInterruptedWhileReadingWritesNothing) {
  const fs::path rawlog = dir_ / "long.rawlog";  // the dataset five times over: a read long enough to interrupt
  {
    std::ifstream in(std::string(PROJBOT_SHARED_DATA) + "/mrpt/range_030_bearing_015.rawlog", std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    std::ofstream out(rawlog, std::ios::binary);
    for (int i = 0; i < 5; ++i) out << bytes.str();
  }
  const CliRun first =
      run_projbot("slam --rawlog " + std::string(PROJBOT_SHARED_DATA) + "/mrpt/localization_demo.rawlog --out-map " +
                  (dir_ / "map").string() + " --out-trajectory " + (dir_ / "t.txt").string());
  ASSERT_EQ(first.code, 0) << first.output;
  const auto map_size = fs::file_size(dir_ / "map" / "map.simplemap.gz");
  const auto lines = trajectory_lines(dir_ / "t.txt");
  Background slam(
      {"slam", "--rawlog", rawlog.string(), "--out-map", (dir_ / "map").string(), "--out-trajectory", (dir_ / "t.txt").string()},
      dir_ / "slam.log");
  ASSERT_GT(slam.pid, 0);
  ASSERT_TRUE(slam.wait_for_output("reading ", std::chrono::seconds(60))) << slam.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  if (slam.output().find("mapping") != std::string::npos) GTEST_SKIP() << "read before the signal: " << slam.output();
  const auto [code, seconds] = slam.signal_and_wait(SIGINT, std::chrono::seconds(60));
  EXPECT_EQ(code, 130) << slam.output();
  EXPECT_NE(slam.output().find("nothing written"), std::string::npos) << slam.output();
  EXPECT_EQ(fs::file_size(dir_ / "map" / "map.simplemap.gz"), map_size);
  EXPECT_EQ(trajectory_lines(dir_ / "t.txt"), lines);
}

// Ctrl-C in localize: the trajectory of the scans done is written, exit 130.
TEST_F(CliTest, LocalizeInterruptedKeepsTheScansDone) {
  const std::string rawlog = std::string(PROJBOT_SHARED_DATA) + "/mrpt/range_030_bearing_015.rawlog";  // 1460 scans
  const CliRun slam = run_projbot("slam --rawlog " + rawlog + " --out-map " + (dir_ / "map").string() + " --out-trajectory " +
                                  (dir_ / "slam.txt").string());
  ASSERT_EQ(slam.code, 0) << slam.output;
  const fs::path trajectory = dir_ / "loc.txt";
  Background loc({"localize", "--map", (dir_ / "map").string(), "--rawlog", rawlog, "--out-trajectory", trajectory.string()},
                 dir_ / "loc.log");
  ASSERT_GT(loc.pid, 0);
  ASSERT_TRUE(loc.wait_for_output("localising 1460 scans", std::chrono::seconds(60))) << loc.output();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const auto [code, seconds] = loc.signal_and_wait(SIGINT, std::chrono::seconds(30));
  if (code == 0) GTEST_SKIP() << "the run ended before the signal (a very fast machine): " << loc.output();
  EXPECT_EQ(code, 130) << loc.output();
  EXPECT_LT(seconds, 1.0);
  EXPECT_NE(loc.output().find("localisation interrupted after"), std::string::npos) << loc.output();
  EXPECT_LT(trajectory_lines(trajectory), 1460);
}

// A moved target gets a spectator's picture at the end of its visit too: the demo's box, moved on its
// second visit (the tour's fourth), is seen elsewhere with the light left where it stood.
TEST_F(CliTest, TourShowsAMovedTargetAtTheEndOfItsVisit) {
  const fs::path frames = dir_ / "frames";
  const CliRun r =
      run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml --visits 4 --frames " + frames.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(frames / "visit02_box_spectator_end.png"));  // not moved on its first visit
  const auto arrival = projbot::assets::read_image(frames / "visit04_box_spectator.png");
  const auto end = projbot::assets::read_image(frames / "visit04_box_spectator_end.png");
  ASSERT_EQ(end.width, arrival.width);
  ASSERT_EQ(end.height, arrival.height);
  std::size_t changed = 0;
  for (std::size_t i = 0; i < end.rgba.size(); i += 4)
    changed += std::abs(end.rgba[i] - arrival.rgba[i]) + std::abs(end.rgba[i + 1] - arrival.rgba[i + 1]) > 30 ? 1 : 0;
  EXPECT_GT(changed, end.rgba.size() / 4 / 200) << "the box moved 17 cm: more than 0.5 % of the picture changes";
}

namespace {

// A sphere of `rings` x `segments` quads (2 triangles each), 0.1 m across, as a binary PLY: a model large
// enough that reading and preparing it takes seconds (1M triangles: about 4 s to read, 3 s to prepare).
void write_sphere_ply(const fs::path& file, int rings, int segments) {
  std::ofstream out(file, std::ios::binary);
  const int vertices = (rings + 1) * segments, faces = 2 * rings * segments;
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << vertices
      << "\nproperty float x\nproperty float y\nproperty float z\nelement face " << faces
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const double th = M_PI * i / rings, ph = 2.0 * M_PI * j / segments;
      const std::array<float, 3> p{static_cast<float>(0.05 * std::sin(th) * std::cos(ph)),
                                   static_cast<float>(0.05 * std::cos(th)),
                                   static_cast<float>(0.05 * std::sin(th) * std::sin(ph))};
      out.write(reinterpret_cast<const char*>(p.data()), sizeof p);
    }
  const auto face = [&out](int a, int b, int c) {
    const std::uint8_t three = 3;
    const std::array<std::int32_t, 3> f{a, b, c};
    out.write(reinterpret_cast<const char*>(&three), 1);
    out.write(reinterpret_cast<const char*>(f.data()), sizeof f);
  };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const int a = i * segments + j, b = a + segments, c = i * segments + (j + 1) % segments + segments, d = c - segments;
      face(a, b, c);
      face(a, c, d);
    }
}

}  // namespace

// Ctrl-C while a model of a million triangles is read and prepared (issue 88): answered within a second
// wherever the set-up is (it took 4-13 s: the read, the ray-caster, the surface samples, the upload
// ran to their ends), exit 130, nothing written. The bound is loose for a loaded machine; the figures are
// the closing note's.
TEST_F(CliTest, TourStopsPromptlyWhileABigModelIsLoaded) {
  write_sphere_ply(dir_ / "sphere.ply", 500, 1000);
  std::string scene = shipped_scene("shop.yaml");
  const std::size_t duck = scene.find(std::string(PROJBOT_ASSET_DIR) + "/models/Duck/Duck.glb");
  const std::size_t box = scene.find("  - name: box");
  ASSERT_TRUE(duck != std::string::npos && box != std::string::npos);
  scene.replace(duck, box - duck,
                (dir_ / "sphere.ply").string() +
                    "\n    world_pose: {translation: [5.0, 4.6, 0.95], rpy_deg: [0, 0, 0]}\n    support: {width: 0.6, depth: 0.5}"
                    "\n    stop: [5.0, 3.2, 90]\n    markers: [[0.0, -0.05, 0.0], [0.05, 0.0, 0.0]]\n");
  write("big.yaml", scene);
  for (const int after_ms : {300, 2500, 5000}) {
    Background tour({"tour", "--scene", (dir_ / "big.yaml").string(), "--report", (dir_ / "r.json").string()}, dir_ / "tour.log");
    ASSERT_GT(tour.pid, 0);
    ASSERT_TRUE(tour.wait_for_output("Tour of", std::chrono::seconds(60))) << tour.output();
    std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
    const auto [code, seconds] = tour.signal_and_wait(SIGINT, std::chrono::seconds(60));
    EXPECT_EQ(code, 130) << tour.output();
    EXPECT_LT(seconds, 3.0) << "Ctrl-C " << after_ms << " ms into the set-up: " << tour.output();
    // Stopped in the set-up: nothing written; once the tour began, its report (no visit finished).
    const bool set_up = tour.output().find("nothing written") == std::string::npos;
    EXPECT_TRUE(after_ms > 300 || !set_up) << "the read takes seconds: " << tour.output();
    EXPECT_EQ(fs::exists(dir_ / "r.json"), set_up) << tour.output();
    fs::remove(dir_ / "r.json");
  }
}

// Ctrl-C while bench dataset estimates (from 50 mm / 15 deg an acquisition takes up to 1.3 s of CPU time,
// 1.6 s of wall time beside a build): the estimate under way ends at once and is dropped, the rows done
// are printed and reported, the report says it was interrupted.
TEST_F(CliTest, BenchDatasetDropsTheEstimateUnderWayAtAStop) {
  const std::string ycbv = std::string(PROJBOT_SHARED_DATA) + "/ycbv-bop";
  Background run({"bench", "dataset", ycbv, "--scenes", "000002", "--perturb", "50,15", "--report", (dir_ / "r.json").string()},
                 dir_ / "bench.log");
  ASSERT_GT(run.pid, 0);
  std::this_thread::sleep_for(std::chrono::seconds(4));  // its models read, estimates under way
  const auto [code, seconds] = run.signal_and_wait(SIGINT, std::chrono::seconds(30));
  EXPECT_EQ(code, 130) << run.output();
  EXPECT_LT(seconds, 2.0) << run.output();  // 0.2-0.3 s here, quiet or beside two busy cores
  EXPECT_NE(run.output().find("the rows above are complete"), std::string::npos) << run.output();
  std::ifstream in(dir_ / "r.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_TRUE(report.at("interrupted").get<bool>());
  for (const auto& row : report.at("instances")) EXPECT_TRUE(row.at("T_est").size() == 16U);
}
