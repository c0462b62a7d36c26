// The hostile-input suite (ctest label `hostile`, also run under ASan/UBSan): bad files of every format
// projbot reads and bad arguments of every command, through the executable. Every case must end with
// exit 1 (bad input) or 2 (bad usage), never a signal; print a message naming the file or option; and
// leave its scratch folder exactly as it was (no output created, no previous output changed).

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "cli_run.hpp"

namespace fs = std::filesystem;

namespace {

// Files written into the scratch folder before a case runs; a plain string is the scene `bad.yaml`.
// A content "@head:N:PATH" is the first N bytes of PATH, "@random:N" N random bytes; {dir}, {data} and
// {src} are replaced in paths and contents. "@fifo" makes a FIFO, "@link:TARGET" a symbolic link.
struct Files {
  std::vector<std::pair<std::string, std::string>> list;
  Files() = default;
  Files(const char* yaml) : Files(std::string(yaml)) {}
  Files(const std::string& yaml) {
    if (!yaml.empty()) list.emplace_back("bad.yaml", yaml);
  }
  Files(std::initializer_list<std::pair<std::string, std::string>> files) : list(files) {}
};

struct Hostile {
  std::string name;
  std::string args;
  Files files;
  int code;  // 1: bad input, 2: bad usage
  std::vector<std::string> must_contain;
};

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = 0; (at = s.find(from, at)) != std::string::npos; at += to.size()) s.replace(at, from.size(), to);
  return s;
}

std::string expand(std::string s, const fs::path& dir) {
  s = replace_all(s, "{duck}", "{data}/gltf/Duck/glTF-Binary/Duck.glb");
  s = replace_all(s, "{rawlog}", "{data}/mrpt/localization_demo.rawlog");
  s = replace_all(s, "{dir}", dir.string());
  s = replace_all(s, "{data}", PROJBOT_SHARED_DATA);
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

// A PNG whose header claims `w` x `h` pixels (an IHDR, no data: the size is refused before any decoding).
std::string png_claiming(std::uint32_t w, std::uint32_t h) {
  std::string s("\x89PNG\r\n\x1a\n", 8);
  const auto be32 = [&](std::uint32_t v) {
    for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
  };
  be32(13);
  s += "IHDR";
  be32(w);
  be32(h);
  s += std::string("\x08\x06\x00\x00\x00", 5);
  be32(0);  // stb does not check the CRC
  be32(0);
  s += "IEND";
  be32(0xae426082u);
  return s;
}

// A pose folder of 14 capture images, each a real PNG cut before its IEND chunk.
Files truncated_captures() {
  Files f;
  for (int i = 0; i < 14; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "cap/p0/%02d.png", i);
    f.list.emplace_back(name, "@head:78:{src}/tests/fuzz/corpus/depth_png/gray16_4x3.png");
  }
  return f;
}

// Outputs that would destroy an input (issue 47): refused before any work, exit 2, naming both; inputs that
// are not regular files refused by kind, exit 1, before anything opens them (a FIFO would block).
std::vector<Hostile> clash_cases() {
  const std::string whole_rawlog = "@head:4000000:{rawlog}";
  std::string chain = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [)";
  for (int i = 0; i < 20000; ++i) chain += R"({"children": [)" + std::to_string(i + 1) + "]},";
  chain += "{}]}";
  std::string doubling = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [)";  // 2^40 placements
  for (int i = 0; i < 40; ++i) doubling += R"({"children": [)" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]},";
  doubling += "{}]}";
  return {
      Hostile{"ply_more_vertices_than_declared",
              "align --model {duck} --scan {dir}/c.ply",
              Files{{"c.ply",
                     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                     "end_header\n0 0 1\n0 1 1\n1 0 1\n1 1 1\n"}},
              1,
              {"c.ply: the header declares 2 elements (2 vertices), the body holds 4 lines"}},
      Hostile{"gltf_texture_20000_pixels_a_side",
              "align --model {dir}/big.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"big.gltf", R"({"asset": {"version": "2.0"}, "images": [{"uri": "big.png"}]})"},
                    {"big.png", png_claiming(20000, 20000)}},
              1,
              {"big.gltf: image 0: 20000x20000 pixels, larger than the 16384 pixels a side a texture may have"}},
      Hostile{"gltf_shared_children_doubling_40_levels",
              "align --model {dir}/dag.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"dag.gltf", doubling}},
              1,
              {"dag.gltf: the node hierarchy places more than 100000 nodes"}},
      Hostile{"slam_ini_threshold_without_end",
              "slam --rawlog {rawlog} --config {dir}/huge.ini --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"huge.ini", "[MappingApplication]\npointsMap_count=1\n[ICP]\nthresholdDist = 1e308\n"}},
              1,
              {"huge.ini:4: [ICP] thresholdDist = '1e308' must be 0.001..100"}},
      Hostile{"slam_ini_points_maps_that_crashed_mrpt",
              "slam --rawlog {rawlog} --config {dir}/maps.ini --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"maps.ini", "[MappingApplication]\npointsMap_count = 100000\n[ICP]\nmaxIterations = 80\n"}},
              1,
              {"maps.ini:2: [MappingApplication] pointsMap_count = '100000' must be 1..4"}},
      Hostile{"slam_ground_truth_backwards",
              "slam --rawlog {rawlog} --ground-truth {dir}/gt.txt --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"gt.txt", "2 0 0 0\n1 0 0 0\n"}},
              1,
              {"gt.txt:2: timestamp 1.000000 does not come after"}},
      Hostile{"localize_ground_truth_1e308",
              "localize --map {dir}/goodmap --rawlog {rawlog} --ground-truth {dir}/gt.txt --out-trajectory {dir}/t.txt",
              Files{{"gt.txt", "1 1e308 0 0\n"}},
              1,
              {"gt.txt:1: x and y must lie within 1000 km"}},
      Hostile{"scene_key_given_twice",
              "render --scene {dir}/bad.yaml --out {dir}/x.png",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\nprojector: {width: 8}\n",
              1,
              {"bad.yaml:3: 'projector' is given twice in one mapping"}},
      Hostile{"scene_near_tiny",
              "render --scene {dir}/bad.yaml --out {dir}/x.png",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, near: 1e-300, far: 10}\ntargets: []\n",
              1,
              {"bad.yaml", "0.0001 m <= near"}},
      Hostile{"scene_slip_scale_1e308",
              "tour --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\n"
              "robot: {drift: {slip_scale: 1e308}}\n",
              1,
              {"robot.drift.slip_scale: must be 0..0.5"}},
      Hostile{"gltf_node_chain_20000_deep",
              "align --model {dir}/chain.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"chain.gltf", chain}},
              1,
              {"chain.gltf: node 256: the node hierarchy is deeper than 256 levels"}},
      Hostile{"slam_out_map_holds_the_rawlog",
              "slam --rawlog {dir}/rec/laser.rawlog --out-map {dir}/rec --out-trajectory {dir}/t.txt",
              Files{{"rec/laser.rawlog", whole_rawlog}},
              2,
              {"--out-map {dir}/rec holds the input --rawlog {dir}/rec/laser.rawlog"}},
      Hostile{"slam_out_map_holds_other_files",
              "slam --rawlog {rawlog} --out-map {dir}/mine --out-trajectory {dir}/t.txt",
              Files{{"mine/notes.txt", "the user's\n"}},
              2,
              {"--out-map {dir}/mine: holds 'notes.txt', which this command did not write"}},
      Hostile{"slam_trajectory_over_the_rawlog",
              "slam --rawlog {dir}/r.rawlog --out-map {dir}/m --out-trajectory {dir}/r.rawlog",
              Files{{"r.rawlog", whole_rawlog}},
              2,
              {"--out-trajectory {dir}/r.rawlog is also the input --rawlog"}},
      Hostile{"localize_trajectory_over_the_map",
              "localize --map {dir}/goodmap --rawlog {rawlog} --out-trajectory {dir}/goodmap/map.simplemap.gz",
              "",
              2,
              {"is inside the input folder --map {dir}/goodmap"}},
      // Issue 43: the appearance bench's arguments and a scene's photometry.
      Hostile{"bench_appearance_report_over_the_scene",
              "bench appearance --scene {dir}/bad.yaml --report {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--report {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"tour_compensation_maybe", "tour --compensation maybe", "", 2, {"--compensation must be on or off, not 'maybe'"}},
      Hostile{"run_compensation_empty", "run --sim --headless --compensation ''", "", 2, {"--compensation must be on or off"}},
      Hostile{"calibrate_photometric_no_out", "calibrate photometric --sim", "", 2, {"--out FILE is required"}},
      Hostile{
          "calibrate_photometric_noise_nan", "calibrate photometric --sim --noise nan --out {dir}/p.yaml", "", 2, {"--noise"}},
      Hostile{"calibrate_photometric_out_over_scene",
              "calibrate photometric --sim --scene {dir}/bad.yaml --out {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--out {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"bench_appearance_reflectance_bad",
              "bench appearance --reflectance guessed",
              "",
              2,
              {"--reflectance must be scene or measured, not 'guessed'"}},
      Hostile{"bench_appearance_dwell_zero", "bench appearance --dwell 0", "", 2, {"--dwell must be 0.1..600 seconds"}},
      Hostile{"bench_appearance_gamma_nan",
              "bench appearance --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, gamma: .nan}\ntargets: []\n",
              1,
              {"bad.yaml:1:", "projector.gamma"}},
      Hostile{"scene_albedo_negative",
              "tour --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n"
              "targets:\n  - {name: a, model: a.glb, pose: {translation: [0, 0, 1]}, surface: {albedo: [-1, 0, 0]}}\n",
              1,
              {"targets[0].surface.albedo: each of r, g, b must be 0..1"}},
      // Issue 44: a target's video, bad at load: one line naming the file, exit 1, nothing written.
      Hostile{"bench_content_video_missing",
              "bench content --scene {dir}/bad.yaml --report {dir}/r.json",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: missing.mp4}}\n",
              1,
              {"missing.mp4: does not exist"}},
      Hostile{"bench_content_video_noise",
              "bench content --scene {dir}/bad.yaml --report {dir}/r.json",
              Files{{"bad.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, "
                     "scale: 0.25, pose: {translation: [0, 0, 1]}, content: {video: noise.mp4}}\n"},
                    {"noise.mp4", "@random:20000"}},
              1,
              {"noise.mp4: not a video FFmpeg can read"}},
      Hostile{"bench_content_video_truncated",
              "bench content --scene {dir}/bad.yaml",
              Files{{"bad.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, "
                     "scale: 0.25, pose: {translation: [0, 0, 1]}, content: {video: cut.mp4}}\n"},
                    {"cut.mp4", "@head:4000:{src}/assets/videos/countdown.mp4"}},
              1,
              {"cut.mp4: "}},
      Hostile{"bench_content_video_mov_table_713mb",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: {src}/tests/hostile/mp4_table_713mb.mp4}}\n",
              1,
              {"mp4_table_713mb.mp4: "}},
      Hostile{"bench_content_video_is_a_folder",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: goodmap}}\n",
              1,
              {"goodmap: is not a regular file"}},
      Hostile{"bench_content_material_missing",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: {src}/assets/videos/countdown.mp4, material: glass}}\n",
              1,
              {"no material 'glass' for the content"}},
      Hostile{"bench_content_without_content",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\n",
              1,
              {"no target has `content:` to play"}},
      Hostile{"render_content_time_negative",
              "render --out {dir}/x.png --content-time -1",
              "",
              2,
              {"--content-time must be 0..1e6 seconds"}},
      Hostile{"bench_content_seconds_zero", "bench content --seconds 0", "", 2, {"--seconds must be 0.1..86400"}},
      Hostile{"scene_content_timeline_backwards",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {timeline: [{at_s: 1, base_color_factor: [1, 1, 1, 1]}, {at_s: "
              "0.5, base_color_factor: [0, 0, 0, 1]}]}}\n",
              1,
              {"content.timeline[1].at_s: must come after the key before it"}},
      Hostile{"scene_content_timeline_colour_over_one",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {timeline: [{at_s: 0, base_color_factor: [2, 1, 1, 1]}]}}\n",
              1,
              {"content.timeline[0].base_color_factor: each of r, g, b, a must be 0..1"}},
      Hostile{"scene_content_start_tomorrow",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: a.mp4, start: tomorrow}}\n",
              1,
              {"content.start: expected arrival, tour or 0..1e6 seconds", "'tomorrow'"}},
      Hostile{"tour_report_over_the_scene",
              "tour --scene {dir}/bad.yaml --report {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--report {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"tour_report_over_the_scene_through_a_link",
              "tour --scene {dir}/link.yaml --report {dir}/bad.yaml",
              Files{{"bad.yaml", "a: 1\n"}, {"link.yaml", "@link:bad.yaml"}},
              2,
              {"is also the input --scene {dir}/link.yaml"}},
      Hostile{"render_profile_over_the_scene",
              "render --scene {dir}/bad.yaml --out {dir}/x.png --profile {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--profile {dir}/bad.yaml is also the input --scene"}},
      Hostile{"render_out_and_profile_one_file", "render --out {dir}/x.png --profile {dir}/x.png", "", 2, {"are the same path"}},
      Hostile{"calibrate_solve_out_over_its_manifest",
              "calibrate solve {dir}/cap --out {dir}/cap/capture.yaml",
              Files{{"cap/capture.yaml", "projector: [8, 8]\n"}},
              2,
              {"--out {dir}/cap/capture.yaml is inside the input folder the folder {dir}/cap"}},
      Hostile{"run_replay_profile_over_its_poses",
              "run --headless --replay {dir}/rec --profile {dir}/rec/poses.csv",
              Files{{"rec/poses.csv", "frame\n"}, {"rec/recording.yaml", "a: 1\n"}},
              2,
              {"--profile {dir}/rec/poses.csv is inside the input folder --replay {dir}/rec"}},
      Hostile{"tour_scene_is_a_fifo",
              "tour --scene {dir}/f.yaml",
              Files{{"f.yaml", "@fifo"}},
              1,
              {"--scene {dir}/f.yaml: is a FIFO, not a regular file"}},
      Hostile{"align_scan_is_a_fifo",
              "align --model {duck} --scan {dir}/f.pcd",
              Files{{"f.pcd", "@fifo"}},
              1,
              {"--scan {dir}/f.pcd: is a FIFO, not a regular file"}},
      Hostile{"gltf_buffer_is_a_fifo",
              "align --model {dir}/m.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"m.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "f.bin", "byteLength": 12}]})"},
                    {"f.bin", "@fifo"}},
              1,
              {"f.bin' is a FIFO, not a regular file"}},
      Hostile{"scene_model_is_a_fifo",
              "render --scene {dir}/s.yaml --out {dir}/x.png",
              Files{{"s.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n"
                     "targets:\n  - {name: a, model: f.glb, pose: {translation: [0, 0, 1]}}\n"},
                    {"f.glb", "@fifo"}},
              1,
              {"f.glb: is a FIFO, not a regular file"}},
      Hostile{"render_scene_is_dev_zero",
              "render --scene /dev/zero --out {dir}/x.png",
              "",
              1,
              {"--scene /dev/zero: is a character device, not a regular file"}},
      Hostile{"slam_rawlog_is_dev_zero",
              "slam --rawlog /dev/zero --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "",
              1,
              {"--rawlog /dev/zero: is a character device"}},
  };
}

const std::string kProj = "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n";
const std::string kRoomProjector = "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, near: 0.1, far: 10}\n";
const std::string kRoom = kRoomProjector + "room: {width: 6, depth: 5, obstacles: [[0, 0, 1, 1]]}\n";
const std::string kDuckTarget =
    "  - {name: duck, model: {data}/gltf/Duck/glTF-Binary/Duck.glb, scale: 0.25, recenter: true,\n"
    "     world_pose: {translation: [3, 3.5, 0.9], rpy_deg: [90, 0, 0]}, stop: [3, 2, 90]}\n";
const std::string kTour = kRoom + "robot: {start: [2, 2, 0]}\ntargets:\n" + kDuckTarget + "tour: {visits: [duck]}\n";
std::string with(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("hostile_test: '" + from + "' not in the scene");
  return text.substr(0, at) + to + text.substr(at + from.size());
}

std::string pcd(const std::string& fields, const std::string& dims, const std::string& data, const std::string& body) {
  return "VERSION 0.7\n" + fields + dims + "VIEWPOINT 0 0 0 1 0 0 0\nDATA " + data + "\n" + body;
}
const std::string kXyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
std::string dims(long long w, long long h, long long n) {
  return "WIDTH " + std::to_string(w) + "\nHEIGHT " + std::to_string(h) + "\nPOINTS " + std::to_string(n) + "\n";
}
const std::string kPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
const std::string kGood16 = "{src}/tests/fuzz/corpus/depth_png/gray16_4x3.png";
const std::string kIni = "[MappingApplication]\nlocalizationLinDistance = 0.2\n[ICP]\nmaxIterations = 80\nthresholdDist = 0.3\n";

// Point clouds: the file as --scan (model: the Duck) and as --model (scan: a real bunny scan).
std::vector<Hostile> cloud_cases() {
  const std::vector<std::tuple<std::string, std::string, std::string>> files{
      {"empty.pcd", "", "malformed PCD file"},
      {"header_only.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 5\nHEIGHT 1\n", "malformed PCD file"},
      {"random.pcd", "@random:3000", "malformed PCD file"},
      {"huge_claim.pcd", pcd(kXyz, dims(2000000000, 1, 2000000000), "binary", std::string(4800, '\x01')), "malformed PCD file"},
      {"no_xyz.pcd", pcd("FIELDS a b c\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n", dims(1, 1, 1), "ascii", "1 2 3\n"),
       "needs x, y and z"},
      {"wh_mismatch.pcd", pcd(kXyz, dims(3, 2, 5), "ascii", "1 2 3\n"), "malformed PCD file"},
      {"binary_short.pcd", pcd(kXyz, dims(4, 1, 4), "binary", std::string(20, '\x02')), "malformed PCD file"},
      {"compressed_short.pcd", pcd(kXyz, dims(4, 1, 4), "binary_compressed", std::string(8, '\x03')), "malformed PCD file"},
      {"bad_type.pcd", pcd("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nCOUNT 1 1 1\n", dims(1, 1, 1), "ascii", "1 2 3\n"),
       "malformed PCD file"},
      {"negative_width.pcd", pcd(kXyz, "WIDTH -4\nHEIGHT 1\nPOINTS 4\n", "ascii", "1 2 3\n"), "malformed PCD file"},
      {"words.pcd", pcd(kXyz, dims(2, 1, 2), "ascii", "a b c\nd e f\n"), "pcd"},
      {"sizes_short.pcd", pcd("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nCOUNT 1 1 1\n", dims(1, 1, 1), "ascii", "1 2 3\n"),
       "malformed PCD file"},
      {"all_nan.pcd", pcd(kXyz, dims(2, 1, 2), "ascii", "nan nan nan\nnan nan nan\n"), "0 valid points"},
      {"stoi.pcd", "@head:100000:{src}/tests/hostile/pcd_header_stoi.pcd", "malformed PCD file"},
      {"uninitialised.pcd", "@head:100000:{src}/tests/hostile/pcl_pcd_uninitialised.pcd", "PCD file"},
      {"empty.ply", "", "ply"},
      {"header_only.ply", kPly, "ply"},
      {"random.ply", "@random:2000", "ply"},
      {"assert.ply", "@head:100000:{src}/tests/hostile/pcl_ply_assert.ply", "assert.ply:7: PLY header: 'eleme3z face 1'"},
      {"short.ply", kPly + "0 0 1\n1 0 1\n", "ply"},
      {"binary_short.ply", replace_all(kPly, "ascii", "binary_little_endian") + std::string(10, '\x01'), "ply"}};
  std::vector<Hostile> cases;
  for (const auto& [name, bytes, message] : files) {
    const std::string id = replace_all(name, ".", "_");
    cases.push_back({"scan_" + id, "align --model {duck} --scan {dir}/" + name, Files{{name, bytes}}, 1, {name, message}});
    cases.push_back({"model_" + id,
                     "align --model {dir}/" + name + " --scan {data}/bunny/bun4.pcd",
                     Files{{name, bytes}},
                     1,
                     {name, message}});
  }
  return cases;
}

// Depth images, 3-D models, scenes, rawlogs, .ini files, maps and trajectories.
const std::vector<Hostile> kFileCases{
    Hostile{"pcd_folder", "align --model {duck} --scan {dir}/goodmap", {}, 2, {"goodmap", "--scan must be"}},
    Hostile{"png_8bit",
            "align --model {duck} --scan {dir}/rgba.png",
            Files{{"rgba.png", "@head:100000:{data}/gltf/BoxTextured/glTF/CesiumLogoFlat.png"}},
            1,
            {"rgba.png", "16-bit single-channel"}},
    Hostile{"png_truncated",
            "align --model {duck} --scan {dir}/cut.png",
            Files{{"cut.png", "@head:40:" + kGood16}},
            1,
            {"cut.png", "corrupt PNG"}},
    Hostile{"png_huge_idat",
            "align --model {duck} --scan {src}/tests/hostile/png_huge_idat.png",
            {},
            1,
            {"png_huge_idat.png", "claims 553670912 bytes"}},
    Hostile{"png_truncated_chunk",
            "align --model {duck} --scan {src}/tests/hostile/png_truncated_chunk.png",
            {},
            1,
            {"png_truncated_chunk.png", "corrupt PNG"}},
    Hostile{"png_random",
            "align --model {duck} --scan {dir}/r.png",
            Files{{"r.png", "@random:5000"}},
            1,
            {"r.png", "cannot read PNG"}},
    Hostile{"png_empty", "align --model {duck} --scan {dir}/e.png", Files{{"e.png", ""}}, 1, {"e.png", "empty"}},
    Hostile{
        "png_too_small_for_intrinsics", "align --model {duck} --scan " + kGood16, {}, 1, {"gray16_4x3.png", "4x3", "640x480"}},
    Hostile{"tiff_random", "align --model {duck} --scan {dir}/r.tiff", Files{{"r.tiff", "@random:5000"}}, 1, {"r.tiff"}},
    Hostile{"tiff_empty", "align --model {duck} --scan {dir}/e.tiff", Files{{"e.tiff", ""}}, 1, {"e.tiff"}},
    // A 145-byte file whose header claims 11012 x 15352 pixels: it was a 676 MB allocation (a fuzzer's find).
    Hostile{"tiff_claims_more_than_it_holds",
            "align --model {duck} --scan {src}/tests/hostile/tiff_claims_169M_pixels.tiff",
            {},
            1,
            {"tiff_claims_169M_pixels.tiff", "11012x15352", "145 bytes"}},
    Hostile{"tiff_truncated",
            "align --model {duck} --scan {dir}/cut.tiff",
            Files{{"cut.tiff", "@head:30:{src}/tests/fuzz/corpus/depth_tiff/gray16_4x3.tiff"}},
            1,
            {"cut.tiff"}},
    Hostile{"tiff_size_mismatch",
            "align --model {duck} --scan {src}/tests/fuzz/corpus/depth_tiff/gray16_4x3.tiff",
            {},
            1,
            {"gray16_4x3.tiff", "4x3", "640x480"}},
    Hostile{"glb_bad_magic",
            "render --model {dir}/m.glb --out {dir}/prev.png",
            Files{{"m.glb", "glTX" + std::string(60, '\0')}},
            1,
            {"m.glb"}},
    Hostile{
        "glb_truncated", "render --model {dir}/m.glb --out {dir}/prev.png", Files{{"m.glb", "@head:300:{duck}"}}, 1, {"m.glb"}},
    Hostile{"gltf_empty", "render --model {dir}/m.gltf --out {dir}/prev.png", Files{{"m.gltf", ""}}, 1, {"m.gltf"}},
    Hostile{"gltf_garbage",
            "render --model {dir}/m.gltf --out {dir}/prev.png",
            Files{{"m.gltf", "{\"asset\": [1, 2"}},
            1,
            {"m.gltf"}},
    Hostile{"gltf_missing_buffer",
            "render --model {dir}/m.gltf --out {dir}/prev.png",
            Files{{"m.gltf", "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"nothere.bin\"}]}"}},
            1,
            {"m.gltf"}},
    Hostile{"gltf_no_meshes",
            "render --model {dir}/m.gltf --out {dir}/prev.png",
            Files{{"m.gltf", "{\"asset\":{\"version\":\"2.0\"}}"}},
            1,
            {"m.gltf"}},
    Hostile{"gltf_index_out_of_range",
            "render --model {src}/tests/hostile/gltf_index_out_of_range.gltf --out {dir}/prev.png",
            {},
            1,
            {"gltf_index_out_of_range.gltf"}},
    Hostile{"gltf_accessor_beyond_buffer",
            "render --model {src}/tests/hostile/gltf_accessor_beyond_buffer.gltf --out {dir}/prev.png",
            {},
            1,
            {"gltf_accessor_beyond_buffer.gltf"}},
    Hostile{"gltf_folder", "render --model {dir}/goodmap --out {dir}/prev.png", {}, 1, {"goodmap", "folder"}},
    Hostile{"gltf_random_as_align_model",
            "align --model {dir}/m.glb --scan {data}/bunny/bun4.pcd",
            Files{{"m.glb", "@random:4000"}},
            1,
            {"m.glb"}},
    Hostile{"scene_empty", "render --scene {dir}/bad.yaml --out {dir}/prev.png", Files{{"bad.yaml", ""}}, 1, {"bad.yaml"}},
    Hostile{"scene_syntax", "render --scene {dir}/bad.yaml --out {dir}/prev.png", "projector: {width: 64\n", 1, {"bad.yaml"}},
    Hostile{"scene_binary",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            Files{{"bad.yaml", "@random:3000"}},
            1,
            {"bad.yaml"}},
    Hostile{"scene_wrong_type",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            with(kProj, "width: 64", "width: wide") + "targets: []\n",
            1,
            {"bad.yaml:1", "width"}},
    Hostile{"scene_negative_width",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            with(kProj, "width: 64", "width: -64") + "targets: []\n",
            1,
            {"bad.yaml", "size -64x48"}},
    Hostile{"scene_nan_fx",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            with(kProj, "fx: 50", "fx: .nan") + "targets: []\n",
            1,
            {"bad.yaml", "fx"}},
    Hostile{"scene_inf_far",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            with(kProj, "cy: 24", "cy: 24, far: .inf") + "targets: []\n",
            1,
            {"bad.yaml", "far"}},
    Hostile{"scene_near_beyond_far",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            with(kProj, "cy: 24", "cy: 24, near: 5, far: 1") + "targets: []\n",
            1,
            {"bad.yaml", "near"}},
    Hostile{"scene_scale_huge",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "scale: 0.25", "scale: 1e30"),
            1,
            {"bad.yaml", "scale"}},
    Hostile{"scene_scale_zero",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "scale: 0.25", "scale: 0"),
            1,
            {"bad.yaml", "scale"}},
    Hostile{"scene_target_without_pose",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            kProj + "targets:\n  - {name: a, model: {duck}}\n",
            1,
            {"bad.yaml", "pose"}},
    Hostile{"scene_duplicate_names",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "tour:", kDuckTarget + "tour:"),
            1,
            {"bad.yaml", "duck"}},
    Hostile{"scene_unknown_visit",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "visits: [duck]", "visits: [duck, cat]"),
            1,
            {"bad.yaml", "cat"}},
    Hostile{"scene_stop_outside_room",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "stop: [3, 2, 90]", "stop: [30, 2, 90]"),
            1,
            {"bad.yaml", "duck", "stop"}},
    Hostile{"scene_stop_in_obstacle",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "stop: [3, 2, 90]", "stop: [0.5, 0.5, 90]"),
            1,
            {"bad.yaml", "duck", "obstacle"}},
    Hostile{"scene_start_outside_room",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "start: [2, 2, 0]", "start: [-2, 2, 0]"),
            1,
            {"bad.yaml", "start"}},
    // A set-up that fails (here: a device that is not there) leaves no recording folder behind.
    Hostile{"record_absent_device_makes_no_folder",
            "record --out {dir}/newrec --config {dir}/bad.yaml",
            kTour + "devices:\n  pan_tilt: {port: /dev/ttyUSB97}\n  base: {domain: 3}\n",
            1,
            {"/dev/ttyUSB97"}},
    Hostile{"scene_start_in_obstacle",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "start: [2, 2, 0]", "start: [0.5, 0.5, 0]"),
            1,
            {"bad.yaml", "start", "obstacle"}},
    Hostile{"scene_model_is_folder",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            kProj + "targets:\n  - {name: a, model: {dir}/goodmap, pose: {translation: [0, 0, 1]}}\n",
            1,
            {"goodmap"}},
    Hostile{"scene_deep_nesting",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            "a: " + std::string(20000, '['),
            1,
            {"bad.yaml"}},
    Hostile{"scene_rpy_two_numbers",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            kProj + "targets:\n  - {name: a, model: {duck}, pose: {translation: [0, 0, 1], rpy_deg: [1, 2]}}\n",
            1,
            {"bad.yaml", "rpy_deg"}},
    Hostile{"scene_translation_nan",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            kProj + "targets:\n  - {name: a, model: {duck}, pose: {translation: [0, .nan, 1]}}\n",
            1,
            {"bad.yaml", "translation"}},
    Hostile{"scene_tab_indent",
            "render --scene {dir}/bad.yaml --out {dir}/prev.png",
            kProj + "targets:\n\t- {name: a}\n",
            1,
            {"bad.yaml"}},
    Hostile{"scene_room_negative",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, "room: {width: 6", "room: {width: -6"),
            1,
            {"bad.yaml", "room"}},
    Hostile{"scene_target_without_stop",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            with(kTour, ", stop: [3, 2, 90]", ""),
            1,
            {"bad.yaml", "duck", "stop"}},
    Hostile{"scene_list_as_key",
            "render --scene {src}/tests/hostile/scene_list_as_key.yaml --out {dir}/prev.png",
            {},
            1,
            {"scene_list_as_key.yaml:2", "a key must be a plain name"}},
    Hostile{"scene_folder", "render --scene {dir}/goodmap --out {dir}/prev.png", {}, 1, {"goodmap", "folder"}},
    Hostile{"run_config_syntax", "run --headless --config {dir}/bad.yaml --profile {dir}/prev.csv", "tour: [\n", 1, {"bad.yaml"}},
    Hostile{"rawlog_empty",
            "slam --rawlog {dir}/e.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"e.rawlog", ""}},
            1,
            {"e.rawlog"}},
    Hostile{"rawlog_random",
            "slam --rawlog {dir}/r.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"r.rawlog", "@random:5000"}},
            1,
            {"r.rawlog", "rawlog"}},
    Hostile{"rawlog_text",
            "slam --rawlog {dir}/t.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"t.rawlog", "scan 1 2 3\n"}},
            1,
            {"t.rawlog", "rawlog"}},
    Hostile{"rawlog_reader_crash",
            "slam --rawlog {src}/tests/hostile/mrpt_reader_crash.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            {},
            1,
            {"mrpt_reader_crash.rawlog", "MRPT's reader crashed on it"}},
    Hostile{"rawlog_endless",
            "slam --rawlog {src}/tests/hostile/mrpt_endless_actions.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            {},
            1,
            {"mrpt_endless_actions.rawlog", "corrupt MRPT rawlog?"}},
    Hostile{"rawlog_truncated_gzip",
            "slam --rawlog {dir}/cut.rawlog --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"cut.rawlog", "@head:11000:{rawlog}"}},
            1,
            {"cut.rawlog"}},
    Hostile{"rawlog_folder", "slam --rawlog {dir}/goodmap --out-map {dir}/m --out-trajectory {dir}/prev.txt", {}, 1, {"goodmap"}},
    Hostile{"rawlog_localize_random",
            "localize --map {dir}/goodmap --rawlog {dir}/r.rawlog --out-trajectory {dir}/prev.txt",
            Files{{"r.rawlog", "@random:5000"}},
            1,
            {"r.rawlog"}},
    Hostile{"ini_non_numeric",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", with(kIni, "= 80", "= abc")}},
            1,
            {"c.ini:4", "maxIterations", "whole number"}},
    Hostile{"ini_fraction",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", with(kIni, "= 80", "= 8.5")}},
            1,
            {"c.ini:4", "maxIterations"}},
    Hostile{"ini_bad_number",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", with(kIni, "= 0.3", "= 0.3m")}},
            1,
            {"c.ini:5", "thresholdDist"}},
    Hostile{"ini_bad_enum",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", kIni + "ICP_algorithm = icpMagic\n"}},
            1,
            {"c.ini:6", "ICP_algorithm", "icpClassic"}},
    Hostile{"ini_no_sections",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", "maxIterations = 3\n"}},
            1,
            {"c.ini:1", "section"}},
    Hostile{"ini_garbage_line",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", kIni + "this is not a setting\n"}},
            1,
            {"c.ini:6", "key = value"}},
    Hostile{"ini_binary",
            "slam --rawlog {rawlog} --config {dir}/c.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            Files{{"c.ini", "@random:2000"}},
            1,
            {"c.ini"}},
    Hostile{"ini_missing",
            "slam --rawlog {rawlog} --config {dir}/none.ini --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            {},
            1,
            {"none.ini"}},
    Hostile{"ini_folder",
            "slam --rawlog {rawlog} --config {dir}/goodmap --out-map {dir}/m --out-trajectory {dir}/prev.txt",
            {},
            1,
            {"goodmap"}},
    Hostile{"map_folder_without_map",
            "localize --map {dir}/m --rawlog {rawlog} --out-trajectory {dir}/prev.txt",
            Files{{"m/readme.txt", "no map here\n"}},
            1,
            {"map.simplemap.gz", "no such map"}},
    Hostile{"map_garbage",
            "localize --map {dir}/m --rawlog {rawlog} --out-trajectory {dir}/prev.txt",
            Files{{"m/map.simplemap.gz", "junk"}},
            1,
            {"map.simplemap.gz"}},
    Hostile{"map_empty",
            "localize --map {dir}/m --rawlog {rawlog} --out-trajectory {dir}/prev.txt",
            Files{{"m/map.simplemap.gz", ""}},
            1,
            {"map.simplemap.gz"}},
    Hostile{"map_truncated",
            "localize --map {dir}/m --rawlog {rawlog} --out-trajectory {dir}/prev.txt",
            Files{{"m/map.simplemap.gz", "@head:15000:{data}/mrpt/localization_demo.simplemap.gz"}},
            1,
            {"map.simplemap.gz"}},
    Hostile{"map_random",
            "localize --map {dir}/m --rawlog {rawlog} --out-trajectory {dir}/prev.txt",
            Files{{"m/map.simplemap.gz", "@random:8000"}},
            1,
            {"map.simplemap.gz"}},
    Hostile{"truth_bad_line",
            "localize --map {dir}/goodmap --rawlog {rawlog} --out-trajectory {dir}/prev.txt --ground-truth {dir}/gt.txt",
            Files{{"gt.txt", "1 2 3\n"}},
            1,
            {"gt.txt:1"}},
    Hostile{"truth_nan",
            "slam --rawlog {rawlog} --out-map {dir}/m --out-trajectory {dir}/prev.txt --ground-truth {dir}/gt.txt",
            Files{{"gt.txt", "1 nan 0 0\n"}},
            1,
            {"gt.txt:1", "finite"}},
    Hostile{"truth_empty",
            "slam --rawlog {rawlog} --out-map {dir}/m --out-trajectory {dir}/prev.txt --ground-truth {dir}/gt.txt",
            Files{{"gt.txt", ""}},
            1,
            {"gt.txt"}},
    Hostile{"truth_missing",
            "localize --map {dir}/goodmap --rawlog {rawlog} --out-trajectory {dir}/prev.txt --ground-truth {dir}/none.txt",
            {},
            1,
            {"none.txt"}},
    Hostile{"bench_localize_rawlog_random",
            "bench localize --stops 3 --rawlog {dir}/r.rawlog --ground-truth {dir}/gt.txt",
            Files{{"r.rawlog", "@random:3000"}, {"gt.txt", "1 0 0 0\n"}},
            1,
            {"r.rawlog"}},
};

// Arguments of every command.
const std::vector<Hostile> kArgumentCases{
    Hostile{"render_size_zero", "render --out {dir}/prev.png --size 0x0", {}, 2, {"--size"}},
    Hostile{"render_size_huge", "render --out {dir}/prev.png --size 100000x100000", {}, 2, {"--size"}},
    Hostile{"render_frames_nan", "render --out {dir}/prev.png --frames nan", {}, 2, {"--frames"}},
    Hostile{"render_frames_huge", "render --out {dir}/prev.png --frames 1e12", {}, 2, {"--frames"}},
    Hostile{"render_near_negative", "render --out {dir}/prev.png --near -1", {}, 1, {"near"}},
    Hostile{"render_far_inf", "render --out {dir}/prev.png --far inf", {}, 2, {"--far"}},
    Hostile{"render_intrinsics_nan", "render --out {dir}/prev.png --intrinsics nan,50,32,24", {}, 1, {"--intrinsics"}},
    Hostile{"render_device_out_of_range", "render --out {dir}/prev.png --device 99", {}, 2, {"--device", "99"}},
    Hostile{"render_device_missing", "render --out {dir}/prev.png --device 5", {}, 1, {"device", "5"}},
    Hostile{"render_device_text", "render --out {dir}/prev.png --device gpu", {}, 2, {"--device"}},
    Hostile{
        "render_pose_short", "render --out {dir}/prev.png --model {duck} --pose-matrix 1,2,3", {}, 1, {"--pose-matrix", "16"}},
    Hostile{"render_pose_nan",
            "render --out {dir}/prev.png --model {duck} --pose-matrix nan,0,0,0,0,1,0,0,0,0,1,1,0,0,0,1",
            {},
            1,
            {"--pose-matrix"}},
    Hostile{
        "render_out_in_proc", "render --out /proc/projbot.png --size 64x48", {}, 2, {"/proc/projbot.png", "takes no new files"}},
    Hostile{"render_out_not_png", "render --out {dir}/prev.json --size 64x48", {}, 2, {"--out", ".png"}},
    Hostile{"render_profile_is_folder", "render --out {dir}/a.png --profile {dir}/goodmap", {}, 2, {"--profile", "is a folder"}},
    Hostile{"show_bad_present_mode", "show --present-mode bogus --frames 1", {}, 2, {"--present-mode", "bogus"}},
    Hostile{"show_frames_negative", "show --frames -1", {}, 2, {"--frames"}},
    Hostile{"show_monitor_negative", "show --fullscreen --monitor -2 --frames 1", {}, 2, {"--monitor"}},
    Hostile{"run_monitor_text", "run --headless --monitor one", {}, 2, {"--monitor"}},
    Hostile{"run_seed_text", "run --headless --seed abc", {}, 2, {"--seed"}},
    Hostile{"run_visits_negative", "run --headless --visits -3", {}, 2, {"--visits"}},
    Hostile{"run_seconds_nan", "run --headless --seconds nan", {}, 2, {"--seconds"}},
    Hostile{"run_dwell_inf", "run --headless --dwell inf", {}, 2, {"--dwell"}},
    Hostile{"run_profile_is_folder", "run --headless --profile {dir}/goodmap", {}, 2, {"--profile", "is a folder"}},
    Hostile{"run_missing_config", "run --headless --config {dir}/none.yaml", {}, 1, {"none.yaml"}},
    // The devices: section (issue 12): wrong drivers and values are file:line errors; a configured device
    // that is absent stops run (and devices) before any work, named, and nothing is written.
    Hostile{"calibration_is_dev_zero",
            "run --headless --config {dir}/bad.yaml --profile {dir}/prev.csv",
            {{"bad.yaml", "calibration: /dev/zero\n" + with(kTour, kRoomProjector, "projector: {near: 0.1, far: 10}\n")}},
            1,
            {"bad.yaml:1: calibration", "/dev/zero", "not a file"}},
    Hostile{"calibration_lens_folds",
            "tour --scene {dir}/bad.yaml --report {dir}/prev.json",
            {{"calib.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, distortion: [-2.0]}\n"
              "projector_from_camera: {translation: [0, 0, 0]}\n"},
             {"bad.yaml", "calibration: calib.yaml\n" + with(kTour, kRoomProjector, "projector: {near: 0.1, far: 10}\n")}},
            1,
            {"calib.yaml:1: projector: distortion folds the image over at panel pixel (0, 0)"}},
    Hostile{"devices_unknown_camera_driver",
            "run --headless --config {dir}/bad.yaml --profile {dir}/prev.csv",
            {{"bad.yaml", kTour + "devices: {camera: {driver: kinect2}}\n"}},
            1,
            {"bad.yaml:", "devices.camera.driver", "kinect2"}},
    Hostile{"devices_pan_tilt_baud",
            "devices --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {pan_tilt: {port: /dev/ttyUSB0, baud: 38400}}\n"}},
            1,
            {"devices.pan_tilt.baud", "9600"}},
    Hostile{"devices_absent_pan_tilt",
            "run --headless --config {dir}/bad.yaml --profile {dir}/prev.csv",
            {{"bad.yaml", kTour + "devices: {pan_tilt: {port: {dir}/no-such-port}}\n"}},
            1,
            {"devices.pan_tilt", "no-such-port", "cannot open"}},
    Hostile{"devices_absent_laser_class",
            "devices --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {laser: {class: CNoSuchLaser}}\n"}},
            1,
            {"laser (MRPT CNoSuchLaser)", "no sensor class"}},
    Hostile{"devices_not_a_laser",
            "run --headless --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {laser: {class: CGPSInterface, map: {dir}}, base: {}}\n"}, {"map.simplemap.gz", "x"}},
            1,
            {"devices.laser", "not a 2-D laser"}},
    Hostile{"devices_laser_without_base",
            "run --headless --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {laser: {class: CHokuyoURG, map: {dir}}}\n"}, {"map.simplemap.gz", "x"}},
            1,
            {"devices.laser localises the configured base", "devices.base is not configured"}},
    Hostile{"devices_laser_without_map",
            "run --headless --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {laser: {class: CHokuyoURG}, base: {}}\n"}},
            1,
            {"devices.laser.map names none", "projbot slam --out-map"}},
    Hostile{"devices_laser_map_not_a_map",
            "run --headless --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {laser: {class: CHokuyoURG, map: {dir}}, base: {}}\n"}},
            1,
            {"devices.laser.map", "holds no map.simplemap.gz"}},
    Hostile{"devices_base_topic_with_space",
            "run --headless --config {dir}/bad.yaml",
            {{"bad.yaml", kTour + "devices: {base: {odom: 'my odom'}}\n"}},
            1,
            {"devices.base.odom", "not a ROS 2 topic name"}},
    Hostile{"tour_seed_text", "tour --seed abc --report {dir}/prev.json", {}, 2, {"--seed"}},
    Hostile{"tour_dwell_negative", "tour --dwell -1 --report {dir}/prev.json", {}, 2, {"--dwell"}},
    Hostile{"tour_depth_model_unknown",
            "tour --depth-model kinect2 --report {dir}/prev.json",
            {},
            2,
            {"--depth-model must be kinect or fitted, not 'kinect2'"}},
    Hostile{"tour_visits_huge", "tour --visits 1e12 --report {dir}/prev.json", {}, 2, {"--visits"}},
    Hostile{"tour_frames_is_file", "tour --frames {dir}/prev.txt --report {dir}/prev.json", {}, 2, {"--frames", "prev.txt"}},
    Hostile{"tour_report_is_folder", "tour --report {dir}/goodmap", {}, 2, {"--report", "is a folder"}},
    Hostile{"tour_unknown_flag", "tour --fast", {}, 2, {"--fast"}},
    Hostile{"align_voxel_zero", "align --model {duck} --scan {data}/bunny/bun4.pcd --voxel 0", {}, 2, {"--voxel"}},
    Hostile{"align_voxel_nan", "align --model {duck} --scan {data}/bunny/bun4.pcd --voxel nan", {}, 2, {"--voxel"}},
    Hostile{"align_depth_scale_zero", "align --model {duck} --scan " + kGood16 + " --depth-scale 0", {}, 2, {"--depth-scale"}},
    Hostile{"align_intrinsics_three", "align --model {duck} --scan " + kGood16 + " --intrinsics 1,2,3", {}, 1, {"--intrinsics"}},
    Hostile{"align_init_matrix_not_rigid",
            "align --model {duck} --scan {data}/bunny/bun4.pcd --init-matrix 2,0,0,0,0,2,0,0,0,0,2,0,0,0,0,1",
            {},
            1,
            {"--init-matrix"}},
    Hostile{"align_init_three", "align --model {duck} --scan {data}/bunny/bun4.pcd --init \"1 2 3\"", {}, 1, {"--init"}},
    Hostile{"slam_out_map_is_file",
            "slam --rawlog {rawlog} --out-map {dir}/prev.txt --out-trajectory {dir}/t.txt",
            {},
            2,
            {"--out-map", "prev.txt"}},
    Hostile{"slam_out_trajectory_in_proc",
            "slam --rawlog {rawlog} --out-map {dir}/m --out-trajectory /proc/t.txt",
            {},
            2,
            {"--out-trajectory", "/proc/t.txt"}},
    Hostile{"localize_initial_nan",
            "localize --map {dir}/goodmap --rawlog {rawlog} --out-trajectory {dir}/prev.txt --initial \"nan 0 0\"",
            {},
            1,
            {"--initial"}},
    Hostile{"localize_no_out", "localize --map {dir}/goodmap --rawlog {rawlog}", {}, 2, {"--out-trajectory"}},
    Hostile{"bench_render_frames_zero", "bench render --frames 0 --offscreen-only", {}, 2, {"--frames"}},
    Hostile{"bench_render_sizes_bad", "bench render --sizes 64x,x48 --offscreen-only", {}, 2, {"--sizes"}},
    Hostile{"bench_render_lens_bad", "bench render --lens 0.1 --offscreen-only", {}, 2, {"--lens must be K1,K2", "'0.1'"}},
    Hostile{"bench_render_lens_folds",
            "bench render --lens -3,0 --sizes 64x48 --offscreen-only",
            {},
            2,
            {"--lens -3,0 at 64x48: distortion folds the image over at panel pixel"}},
    Hostile{"bench_render_both_only",
            "bench render --offscreen-only --windowed-only",
            {},
            2,
            {"--offscreen-only", "--windowed-only"}},
    Hostile{"bench_track_frames_negative", "bench track --frames -5", {}, 2, {"--frames"}},
    Hostile{"bench_track_distance_nan", "bench track --distance nan", {}, 2, {"--distance"}},
    Hostile{"bench_localize_seed_text", "bench localize --seed x", {}, 2, {"--seed"}},
    Hostile{"bench_localize_truth_without_rawlog", "bench localize --stops 3 --ground-truth {dir}/prev.txt", {}, 2, {"--rawlog"}},
    Hostile{"bench_unknown", "bench paint", {}, 2, {"paint"}},
    Hostile{"version_extra", "--version now", {}, 2, {"now"}},
};

std::vector<Hostile> all_cases() {
  std::vector<Hostile> cases{
      Hostile{"no_command", "", "", 2, {"Usage"}}, Hostile{"unknown_command", "paint", "", 2, {"unknown command 'paint'"}},
      Hostile{"unknown_flag", "render --out x.png --colour red", "", 2, {"unknown option --colour", "render --help"}},
      Hostile{"missing_out", "render", "", 2, {"--out FILE is required"}},
      Hostile{"missing_value", "render --out", "", 2, {"--out needs a value"}},
      Hostile{"bad_frames", "render --out {dir}/a.png --frames -3", "", 2, {"--frames"}},
      Hostile{"bad_size", "render --out {dir}/a.png --size 640by480", "", 2, {"--size", "1920x1080"}},
      Hostile{"bad_intrinsics", "render --out {dir}/a.png --intrinsics 1,2,3", "", 1, {"--intrinsics", "4"}},
      Hostile{"negative_fx", "render --out {dir}/a.png --intrinsics -1,2,3,4", "", 1, {"fx and fy"}},
      Hostile{"near_far", "render --out {dir}/a.png --near 5 --far 1", "", 1, {"near < far"}},
      Hostile{"pose_not_rigid",
              "render --out {dir}/a.png --model {duck} --pose-matrix 2,0,0,0,0,2,0,0,0,0,2,1,0,0,0,1",
              "",
              1,
              {"--pose-matrix", "rotation"}},
      Hostile{"pose_with_two_targets",
              "render --out {dir}/a.png --pose-matrix 1,0,0,0,0,1,0,0,0,0,1,1,0,0,0,1",
              "",
              2,
              {"single target", "2"}},
      Hostile{
          "missing_scene", "render --out {dir}/a.png --scene {dir}/none.yaml", "", 1, {"none.yaml", "none.yaml: does not exist"}},
      Hostile{"scene_unknown_key",
              "render --out {dir}/a.png --scene {dir}/bad.yaml",
              kProj + "targets: []\nextra: 1\n",
              1,
              {"bad.yaml:3:", "extra", "unknown key"}},
      Hostile{"scene_missing_model",
              "render --out {dir}/a.png --scene {dir}/bad.yaml",
              kProj + "targets:\n  - {name: a, model: nothere.glb, pose: {translation: [0, 0, 1]}}\n",
              1,
              {"nothere.glb", "no such model file"}},
      Hostile{"scene_bad_model",
              "render --out {dir}/a.png --scene {dir}/bad.yaml",
              kProj + "targets:\n  - {name: a, model: bad.yaml, pose: {translation: [0, 0, 1]}}\n",
              1,
              {"bad.yaml"}},
      Hostile{"unwritable_png",
              "render --out /nonexistent-dir/a.png --size 64x48",
              "",
              2,
              {"--out /nonexistent-dir/a.png", "does not exist"}},
      Hostile{"render_out_is_a_folder", "render --out {dir} --size 64x48", "", 2, {"--out", "is a folder"}},
      Hostile{"render_profile_missing_folder",
              "render --out {dir}/a.png --profile {dir}/no/p.csv",
              "",
              2,
              {"--profile", "no/p.csv", "does not exist"}},
      Hostile{"tour_report_missing_folder", "tour --report {dir}/no/r.json", "", 2, {"--report", "does not exist"}},
      Hostile{"tour_frames_parent_missing", "tour --frames {dir}/no/frames", "", 2, {"--frames", "parent folder"}},
      Hostile{"run_profile_missing_folder", "run --headless --profile {dir}/no/p.csv", "", 2, {"--profile", "does not exist"}},
      Hostile{"run_bad_present_mode_headless",
              "run --headless --present-mode bogus",
              "",
              2,
              {"--present-mode must be fifo, mailbox or immediate", "bogus"}},
      Hostile{"run_bad_seconds", "run --headless --seconds -1", "", 2, {"--seconds"}},
      Hostile{"slam_out_map_parent_missing",
              "slam --rawlog {rawlog} --out-map {dir}/a/b/m --out-trajectory {dir}/t.txt",
              "",
              2,
              {"--out-map", "parent folder", "does not exist"}},
      Hostile{"slam_trajectory_missing_folder",
              "slam --rawlog {rawlog} --out-map {dir}/m --out-trajectory {dir}/no/t.txt",
              "",
              2,
              {"--out-trajectory", "does not exist"}},
      Hostile{"localize_trajectory_is_a_folder",
              "localize --map {dir} --rawlog {rawlog} --out-trajectory {dir}",
              "",
              2,
              {"--out-trajectory", "is a folder"}},
      Hostile{"bench_without_target", "bench", "", 2, {"bench render"}},
      Hostile{"align_no_model", "align --scan x.pcd", "", 2, {"--model FILE is required"}},
      Hostile{"align_missing_scan", "align --model {duck} --scan {dir}/none.pcd", "", 1, {"none.pcd", "no such point cloud"}},
      Hostile{"align_bad_scan_type", "align --model {duck} --scan {dir}/bad.yaml", "a: 1\n", 2, {"--scan must be"}},
      Hostile{"align_nan_init", "align --model {duck} --scan {dir}/a.pcd --init \"0 0 nan 0 0 0\"", "", 1, {"--init", "finite"}},
      Hostile{"align_both_inits",
              "align --model {duck} --scan {dir}/a.pcd --init \"0 0 1 0 0 0\" --init-matrix 1",
              "",
              2,
              {"not both"}},
      Hostile{"align_empty_cloud", "align --model {duck} --scan {dir}/bad.pcd", "", 1, {"bad.pcd"}},
      Hostile{
          "align_missing_model", "align --model {dir}/none.glb --scan {dir}/a.pcd", "", 1, {"none.glb", "no such model file"}},
      // Meshes (Assimp, isolated) and BOP datasets (issue 41).
      Hostile{"align_mesh_without_faces",
              "align --model {dir}/points.ply --scan {dir}/a.pcd",
              Files{{"points.ply",
                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"},
                    {"a.pcd", "@head:100000:{data}/bunny/bun4.pcd"}},
              1,
              {"points.ply: "}},
      Hostile{"align_obj_garbage",
              "align --model {dir}/m.obj --scan {dir}/a.pcd",
              Files{{"m.obj", "@random:4000"}, {"a.pcd", "@head:100000:{data}/bunny/bun4.pcd"}},
              1,
              {"m.obj: "}},
      Hostile{"align_stl_truncated",
              "align --model {dir}/m.stl --scan {dir}/a.pcd",
              Files{{"m.stl", "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0"},
                    {"a.pcd", "@head:100000:{data}/bunny/bun4.pcd"}},
              1,
              {"m.stl: "}},
      Hostile{
          "align_bad_model_scale", "align --model {duck} --scan {data}/bunny/bun4.pcd --model-scale 0", "", 2, {"--model-scale"}},
      Hostile{"align_bad_guess_error",
              "align --model {duck} --scan {data}/bunny/bun4.pcd --guess-error 20",
              "",
              2,
              {"--guess-error must be MM,DEG"}},
      Hostile{"align_init_matrix_not_rotation",
              "align --model {duck} --scan {data}/bunny/bun4.pcd --init-matrix 1,0,0,0,0,1,0.01,0,0,0,1,0,0,0,0,1",
              "",
              1,
              {"--init-matrix: pose's rotation is not a proper rotation (orthonormality error 0.01"}},
      Hostile{"bench_dataset_missing", "bench dataset {dir}/none", "", 1, {"none: no such folder"}},
      Hostile{"bench_dataset_no_folder", "bench dataset", "", 2, {"give the BOP dataset's folder"}},
      Hostile{"bench_sensor_missing", "bench sensor {dir}/none", "", 1, {"none: no such folder"}},
      Hostile{"bench_sensor_no_folder", "bench sensor", "", 2, {"give the BOP dataset's folder: projbot bench sensor DIR"}},
      Hostile{"bench_dataset_broken_info",
              "bench dataset {dir}/bop",
              Files{{"bop/models/models_info.json", "{\"1\": {\"diameter\": 10"}, {"bop/test/000000/scene_camera.json", "{}"}},
              1,
              {"models_info.json: malformed JSON"}},
      Hostile{"bench_dataset_report_inside",
              "bench dataset {dir}/bop --report {dir}/bop/r.json",
              Files{{"bop/models/models_info.json", "{}"}},
              2,
              {"lies inside the dataset"}},
      Hostile{"bench_dataset_bad_perturb", "bench dataset {dir} --perturb 20", "", 2, {"--perturb must be MM,DEG"}},
      Hostile{"slam_no_rawlog", "slam --out-map {dir}/m --out-trajectory {dir}/t.txt", "", 2, {"--rawlog is required"}},
      Hostile{"slam_missing_rawlog",
              "slam --rawlog {dir}/none.rawlog --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "",
              1,
              {"none.rawlog", "no such rawlog"}},
      Hostile{"slam_corrupt_rawlog",
              "slam --rawlog {dir}/bad.yaml --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "not: a rawlog\n",
              1,
              {"bad.yaml", "not a readable MRPT rawlog"}},
      Hostile{"slam_bad_config",
              "slam --rawlog {rawlog} --config {dir}/bad.yaml --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "a: 1\n",
              1,
              {"bad.yaml:1:", "expected 'key = value'"}},
      Hostile{"slam_bad_start",
              "slam --rawlog {rawlog} --start \"1 2 x\" --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "",
              1,
              {"--start"}},
      Hostile{"sim_base_laser_without_config", "sim-base --laser {dir}/urg --seconds 1", "", 2, {"--laser needs --config"}},
      Hostile{"localize_missing_map",
              "localize --map {dir}/nomap --rawlog {rawlog} --out-trajectory {dir}/t.txt",
              "",
              1,
              {"nomap", "no such map"}},
      Hostile{"localize_bad_initial",
              "localize --map {dir} --rawlog {rawlog} --out-trajectory {dir}/t.txt --initial \"1 2\"",
              "",
              1,
              {"--initial"}},
      Hostile{"bench_localize_bad_stops", "bench localize --stops 3,x", "", 2, {"--stops"}},
      Hostile{"tour_bad_mode", "tour --mode paper", "", 2, {"--mode must be odometry, localized or tracking"}},
      Hostile{"tour_missing_scene", "tour --scene {dir}/nope.yaml", "", 1, {"nope.yaml: does not exist"}},
      Hostile{"tour_without_tour_section", "tour --scene {dir}/bad.yaml", kProj + "targets: []\n", 1, {"needs a 'tour"}},
      Hostile{"tour_bad_visits", "tour --visits 0", "", 2, {"--visits"}},
      Hostile{"run_without_tour_section",
              "run --headless --config {dir}/bad.yaml",
              kProj + "targets: []\n",
              1,
              {"needs a 'tour: {visits: [...]}' section"}},
      Hostile{"run_bad_dwell", "run --headless --dwell 0", "", 2, {"--dwell"}},
      // The calibration: a capture folder that is not one, bad boards and sizes, outputs that cannot be written.
      Hostile{"calibrate_no_step", "calibrate", "", 2, {"say which step: projbot calibrate capture | simulate | solve"}},
      Hostile{"calibrate_solve_missing_folder",
              "calibrate solve {dir}/nothing --out {dir}/c.yaml",
              "",
              1,
              {"nothing' is not a folder"}},
      Hostile{"calibrate_solve_empty_folder",
              "calibrate solve {dir}/goodmap --out {dir}/c.yaml --projector 1280x800 --board checkerboard:9x6:0.05",
              "",
              1,
              {"holds no pose folders with images"}},
      Hostile{"calibrate_solve_no_manifest", "calibrate solve {dir}/goodmap --out {dir}/c.yaml", "", 1, {"has no capture.yaml"}},
      Hostile{"calibrate_solve_garbage_manifest",
              "calibrate solve {dir}/cap --out {dir}/c.yaml",
              Files{{"cap/capture.yaml", "@random:300"}},
              1,
              {"capture.yaml"}},
      Hostile{"calibrate_solve_truncated_image",
              "calibrate solve {dir}/cap --out {dir}/c.yaml --projector 8x8 --board checkerboard:9x6:0.05",
              Files{{"cap/p0/00.png", "@head:40:{src}/assets/scenes/../../README.md"}},
              1,
              {"cap/p0': 1 images, expected 14"}},
      Hostile{"calibrate_solve_png_cut_before_iend",
              "calibrate solve {dir}/cap --out {dir}/c.yaml --projector 8x8 --board checkerboard:9x6:0.05",
              truncated_captures(),
              1,
              {"cap/p0/00.png: corrupt PNG: the file ends after 78 bytes without its IEND chunk"}},
      Hostile{"calibrate_solve_bad_board",
              "calibrate solve {dir}/goodmap --out {dir}/c.yaml --board chess:9x6:0.05",
              "",
              2,
              {"--board 'chess:9x6:0.05': unknown kind 'chess'"}},
      Hostile{"calibrate_simulate_bad_board",
              "calibrate simulate --out {dir}/cap --board charuco:10x7",
              "",
              2,
              {"--board 'charuco:10x7': too few fields"}},
      Hostile{"calibrate_solve_bad_projector",
              "calibrate solve {dir}/goodmap --out {dir}/c.yaml --projector 0x800",
              "",
              2,
              {"--projector '0x800'"}},
      Hostile{"calibrate_solve_out_in_missing_folder", "calibrate solve {dir}/goodmap --out {dir}/no/c.yaml", "", 2, {"--out"}},
      Hostile{"calibrate_simulate_over_a_file", "calibrate simulate --out {dir}/prev.txt --poses 1", "", 2, {"--out"}},
      Hostile{"calibrate_simulate_bad_poses", "calibrate simulate --out {dir}/cap --poses 0", "", 2, {"--poses"}},
      Hostile{"calibrate_simulate_board_too_big",
              "calibrate simulate --out {dir}/cap --poses 1 --board charuco:30x20:0.1:0.08:DICT_4X4_1000",
              "",
              1,
              {"does not fit the camera's and the projector's views together"}},
      Hostile{"calibrate_simulate_too_few_markers",
              "calibrate simulate --out {dir}/cap --board charuco:30x20:0.1:0.08",
              "",
              2,
              {"--board 'charuco:30x20:0.1:0.08': 300 markers, DICT_4X4_50 has 50"}},
      Hostile{"tour_missing_calibration", "tour --calibration {dir}/none.yaml", "", 1, {"none.yaml: does not exist"}}};
  const auto clashes = clash_cases();
  cases.insert(cases.end(), clashes.begin(), clashes.end());
  const auto clouds = cloud_cases();
  cases.insert(cases.end(), clouds.begin(), clouds.end());
  cases.insert(cases.end(), kFileCases.begin(), kFileCases.end());
  cases.insert(cases.end(), kArgumentCases.begin(), kArgumentCases.end());
  return cases;
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Cases, HostileTest, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Hostile>& param_info) { return param_info.param.name; });

TEST(HostileSuite, HasAtLeast120Cases) { EXPECT_GE(all_cases().size(), 120u); }
