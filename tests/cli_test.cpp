// The projbot executable as a user meets it: rendering, alignment, mapping and localisation, exit codes
// and the one line it prints on bad input.

#include "cli_fixture.hpp"

using namespace cli_fixture;

TEST_F(CliTest, HelpNamesTheCommands) {
  const CliRun r = run_projbot("--help");
  EXPECT_EQ(r.code, 0);
  for (const char* word : {"render", "show", "bench"}) EXPECT_NE(r.output.find(word), std::string::npos) << word;
  const CliRun sub = run_projbot("render --help");
  EXPECT_EQ(sub.code, 0);
  EXPECT_NE(sub.output.find("--pose-matrix"), std::string::npos);
  // A group's help lists its commands with what each does.
  const CliRun group = run_projbot("calibrate --help");
  EXPECT_EQ(group.code, 0) << group.output;
  EXPECT_NE(group.output.find("Usage: projbot calibrate WHAT"), std::string::npos) << group.output;
  EXPECT_NE(group.output.find("  photometric  the projector's response per channel"), std::string::npos) << group.output;
  // Every command's help names the guide's page that explains it, and the page is there.
  std::istringstream listed(r.output.substr(r.output.find("Commands:")));
  int commands = 0;
  for (std::string line; std::getline(listed, line) && line.rfind("Examples:", 0) != 0;) {
    if (line.size() < 26 || line.rfind("  ", 0) != 0) continue;
    std::string name = line.substr(2, 23);
    name.erase(name.find_last_not_of(' ') + 1);
    const CliRun help = run_projbot(name + " --help");
    const auto at = help.output.find("Guide: docs/");
    ASSERT_NE(at, std::string::npos) << name << ": " << help.output;
    const std::string page = help.output.substr(at + 7, help.output.find(' ', at + 7) - at - 7);
    EXPECT_TRUE(fs::exists(fs::path(PROJBOT_SOURCE_DIR) / page)) << name << ": " << page;
    ++commands;
  }
  EXPECT_GE(commands, 24);
  const CliRun bench = run_projbot("bench -h");
  EXPECT_EQ(bench.code, 0) << bench.output;
  EXPECT_NE(bench.output.find("  dataset      pose estimation on a BOP dataset's real frames"), std::string::npos)
      << bench.output;
}

TEST_F(CliTest, RendersTheDemoSceneToAPng) {
  const fs::path out = dir_ / "demo.png";
  const CliRun r = run_projbot("render --out " + out.string() + " --frames 3 --validation");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("p99"), std::string::npos) << "prints the frame-time summary";
  EXPECT_NE(r.output.find("validation: 0 errors, 0 warnings"), std::string::npos) << r.output;
  const auto img = projbot::assets::read_image(out);
  EXPECT_EQ(img.width, 1280);
  EXPECT_EQ(img.height, 800);
  std::size_t lit = 0;
  for (std::size_t i = 0; i < img.rgba.size(); i += 4) lit += img.rgba[i] > 0 ? 1 : 0;
  EXPECT_GT(lit, 50000U);
}

// A projector with a lens (`projector.distortion`): the frame is drawn pre-distorted, validation-clean, the
// Duck where the lens's forward model moves the pinhole frame's Duck; a lens that folds the image over
// is refused naming the file, the key and where.
TEST_F(CliTest, RendersThroughTheProjectorsLens) {
  const auto scene = [&](const std::string& name, const std::string& lens) {
    return write(name, "projector: {width: 320, height: 200, fx: 300, fy: 300, cx: 159.5, cy: 99.5" + lens +
                           "}\ntargets:\n  - {name: duck, model: " + kDuck +
                           ", scale: 0.25, recenter: true, pose: {translation: [0.25, 0.12, 1.0], rpy_deg: [180, 0, 0]}}\n")
        .string();
  };
  const fs::path pin = dir_ / "pin.png", lens = dir_ / "lens.png";
  ASSERT_EQ(run_projbot("render --scene " + scene("pin.yaml", "") + " --out " + pin.string()).code, 0);
  const CliRun r =
      run_projbot("render --validation --scene " + scene("lens.yaml", ", distortion: [-0.3, 0.08]") + " --out " + lens.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("validation: 0 errors, 0 warnings"), std::string::npos) << r.output;
  // Where the lens frame's lit pixels should be: every lit pixel of the pinhole frame moved to the panel
  // position that lights its ray (x -> x (1 + k1 r^2 + k2 r^4), normalised), weighted by the area it then
  // covers; against the centroid of the lens frame's lit pixels.
  const auto panel = [](const Eigen::Vector2d& px) {
    const Eigen::Vector2d x = (px - Eigen::Vector2d(159.5, 99.5)) / 300.0;
    const double r2 = x.squaredNorm();
    return Eigen::Vector2d(Eigen::Vector2d(159.5, 99.5) + 300.0 * x * (1.0 - 0.3 * r2 + 0.08 * r2 * r2));
  };
  const auto pin_img = projbot::assets::read_image(pin), lens_img = projbot::assets::read_image(lens);
  Eigen::Vector3d expected = Eigen::Vector3d::Zero(), measured = Eigen::Vector3d::Zero();
  double moved = 0.0;
  for (int y = 0; y < pin_img.height; ++y)
    for (int x = 0; x < pin_img.width; ++x) {
      if (lens_img.pixel(x, y)[0] > 0) measured += Eigen::Vector3d(x, y, 1);
      if (pin_img.pixel(x, y)[0] == 0) continue;
      const Eigen::Vector2d p(x, y), q = panel(p), dx = panel(p + Eigen::Vector2d(0.5, 0)) - panel(p - Eigen::Vector2d(0.5, 0)),
                                     dy = panel(p + Eigen::Vector2d(0, 0.5)) - panel(p - Eigen::Vector2d(0, 0.5));
      const double area = dx.x() * dy.y() - dx.y() * dy.x();
      expected += area * Eigen::Vector3d(q.x(), q.y(), 1.0);
      moved = std::max(moved, (q - p).norm());
    }
  ASSERT_GT(measured.z(), 300.0);
  EXPECT_GT(moved, 10.0) << "px: the lens must move the duck enough to tell";
  EXPECT_LT((measured.head<2>() / measured.z() - expected.head<2>() / expected.z()).norm(), 0.5);
  // The canvas is resampled bilinearly: the silhouette's edge pixels catch some light (3.3 % more lit here).
  EXPECT_NEAR(measured.z() / expected.z(), 1.0, 0.05) << "lit area";
  const CliRun fold = run_projbot("render --scene " + scene("fold.yaml", ", distortion: [-0.9]") + " --out " + lens.string());
  EXPECT_EQ(fold.code, 1);
  EXPECT_NE(fold.output.find("fold.yaml:1: projector: distortion folds the image over at panel pixel"), std::string::npos)
      << fold.output;
}

// bench render --lens: every run made through the pinhole and through the lens, a row each.
TEST_F(CliTest, BenchRenderMeasuresTheLensPassBesideThePinhole) {
  const CliRun r = run_projbot("bench render --offscreen-only --sizes 64x48 --frames 5 --lens -0.12,0.05");
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream lines(r.output);
  std::map<std::string, int> rows;  // lens column -> rows
  for (std::string line; std::getline(lines, line);) {
    std::istringstream cells(line);
    std::string model, tris, size, target, lens;
    double fps = 0.0, p50 = 0.0, p95 = 0.0, p99 = 0.0, max = 0.0, gpu = 0.0;
    if (!(cells >> model >> tris >> size >> target >> fps >> p50 >> p95 >> p99 >> max >> gpu >> lens) || size != "64x48")
      continue;
    EXPECT_GT(fps, 0.0) << line;
    EXPECT_GT(p50, 0.0) << line;
    ++rows[lens];
  }
  EXPECT_EQ(rows["pinhole"], 2) << r.output;  // duck and sphere
  EXPECT_EQ(rows["k1=-0.12,k2=0.05"], 2) << r.output;
}

TEST_F(CliTest, OverridesAndProfile) {
  const fs::path out = dir_ / "duck.png";
  const fs::path csv = dir_ / "p.csv";
  const CliRun r = run_projbot("render --model " + kDuck + " --size 320x240 --intrinsics 300,280,150,130 --out " + out.string() +
                               " --frames 4 --profile " + csv.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(projbot::assets::read_image(out).width, 320);
  std::ifstream in(csv);
  int lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  EXPECT_EQ(lines, 5);  // header + 4 frames
  // --pose-matrix puts the single target exactly where asked: behind the projector, nothing shows; the
  // black frame is written all the same, and the exit status (3) says it is empty.
  const CliRun behind = run_projbot("render --model " + kDuck + " --size 64x48 --out " + out.string() +
                                    " --pose-matrix 1,0,0,0,0,1,0,0,0,0,1,-3,0,0,0,1");
  ASSERT_EQ(behind.code, 3) << behind.output;
  const auto img = projbot::assets::read_image(out);
  for (std::size_t i = 0; i < img.rgba.size(); i += 4) ASSERT_EQ(img.rgba[i], 0);
  // A scene without targets is an empty frame too (it once exited 0).
  const fs::path none = write("none.yaml", "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\n");
  const CliRun nothing = run_projbot("render --scene " + none.string() + " --out " + out.string());
  EXPECT_EQ(nothing.code, 3) << nothing.output;
  EXPECT_NE(nothing.output.find("the frame is empty: the scene has no targets"), std::string::npos) << nothing.output;
}

TEST_F(CliTest, SlamThenLocalize) {
  const std::string rawlog = std::string(PROJBOT_SHARED_DATA) + "/mrpt/2006-01ENE-21-SENA_Telecom_Faculty_one_loop_only.rawlog";
  const CliRun slam = run_projbot("slam --rawlog " + rawlog + " --out-map " + (dir_ / "map").string() + " --out-trajectory " +
                                  (dir_ / "slam.txt").string());
  ASSERT_EQ(slam.code, 0) << slam.output;
  EXPECT_NE(slam.output.find("225 scans"), std::string::npos) << slam.output;
  for (const char* f : {"map/map.simplemap.gz", "map/grid.png", "map/grid.yaml", "slam.txt"})
    EXPECT_TRUE(fs::exists(dir_ / f)) << f;
  const CliRun loc = run_projbot("localize --map " + (dir_ / "map").string() + " --rawlog " + rawlog + " --out-trajectory " +
                                 (dir_ / "loc.txt").string() + " --ground-truth " + (dir_ / "slam.txt").string());
  ASSERT_EQ(loc.code, 0) << loc.output;
  EXPECT_NE(loc.output.find("localisation vs ground truth"), std::string::npos) << loc.output;
  EXPECT_EQ(trajectory_lines(dir_ / "loc.txt"), 225);
}

// Long commands show a line per step with elapsed and expected time on a terminal (a pseudo-terminal
// from `script` here), and nothing of it when their output is a pipe.
TEST_F(CliTest, LongCommandsShowProgressOnATerminalOnly) {
  const std::string tour =
      std::string(PROJBOT_EXE) + " tour --scene " + PROJBOT_ASSET_DIR + "/scenes/tour.yaml --visits 2 --dwell 0.3";
  FILE* pipe = popen(("script -qec '" + tour + "' /dev/null 2>&1").c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 512> buf{};
  while (fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
  ASSERT_EQ(pclose(pipe), 0) << out;
  EXPECT_NE(out.find("  visit 1/2 done, "), std::string::npos) << out;
  EXPECT_NE(out.find(" elapsed, about "), std::string::npos) << out;  // the time left, after the first visit
  EXPECT_NE(out.find("  visit 2/2 done, "), std::string::npos) << out;
  const std::string rawlog = std::string(PROJBOT_SHARED_DATA) + "/mrpt/2006-01ENE-21-SENA_Telecom_Faculty_one_loop_only.rawlog";
  pipe = popen(("script -qec '" + std::string(PROJBOT_EXE) + " slam --rawlog " + rawlog + " --out-map " +
                (dir_ / "map").string() + " --out-trajectory " + (dir_ / "slam.txt").string() + "' /dev/null 2>&1")
                   .c_str(),
               "r");
  ASSERT_NE(pipe, nullptr);
  out.clear();
  while (fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
  ASSERT_EQ(pclose(pipe), 0) << out;
  EXPECT_NE(out.find("  scan 12/225 done, "), std::string::npos) << out;  // every 12th of 225: at most 20 lines
  EXPECT_EQ(out.find("  scan 13/225 done, "), std::string::npos) << out;
  const CliRun piped = run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml --visits 1 --dwell 0.3");
  ASSERT_EQ(piped.code, 0) << piped.output;
  EXPECT_EQ(piped.output.find(" done, "), std::string::npos) << piped.output;
}

TEST_F(CliTest, AlignPrintsJson) {
  const std::string bunny = std::string(PROJBOT_SHARED_DATA) + "/bunny/";
  const CliRun r = run_projbot("align --model " + bunny + "bun0.pcd --scan " + bunny +
                               "bun4.pcd --no-crop --init \"0.03 0 0.03 0 -30 0\" --json");
  ASSERT_EQ(r.code, 0) << r.output;
  // One JSON object: T row-major with the reference's -34 degree turn about y, and the gate's numbers.
  EXPECT_EQ(r.output.rfind("{\"T\":[[", 0), 0U) << r.output;
  for (const char* key : {"\"converged\":true", "\"inlier_ratio\"", "\"rmse_mm\"", "\"iterations\"", "\"time_ms\"",
                          "\"accepted\":true", "\"free_space\":null"})  // a cloud has no viewpoint to check from
    EXPECT_NE(r.output.find(key), std::string::npos) << key;
  const double m00 = std::stod(r.output.substr(8));
  EXPECT_NEAR(m00, 0.825, 0.02);  // cos(34.4 degrees)
}

// Standard output on a full device is an error, not a silent exit 0 (`--json >/dev/full`).
TEST_F(CliTest, FullStandardOutputIsAnError) {
  const std::string bunny = std::string(PROJBOT_SHARED_DATA) + "/bunny/";
  // slam flushes its first line at once: that write fails mid-run, and the reason is not guessed from a
  // stale errno ("No such file or directory" once).
  // The message names the command as typed: "projbot bench localize:", not "projbot bench:".
  struct Case {
    std::string args, reason, named;
  };
  const std::vector<Case> cases{
      {"align --model " + bunny + "bun0.pcd --scan " + bunny + "bun4.pcd --no-crop --json", "No space left on device",
       "projbot align: "},
      {"--help", "", "projbot: "},  // either reason: the help is about the size of stdout's buffer (4 KiB)
      {"slam --rawlog " + kRawlog + " --out-map " + (dir_ / "m").string() + " --out-trajectory " + (dir_ / "t.txt").string(),
       "a write to it failed during the run", "projbot slam: "},
      {"bench localize --stops 1", "a write to it failed during the run", "projbot bench localize: "}};
  for (const auto& c : cases) {
    const std::string cmd = std::string(PROJBOT_EXE) + " " + c.args + " 2>&1 >/dev/full";
    FILE* pipe = popen(cmd.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string out;
    std::array<char, 512> buf{};
    while (fgets(buf.data(), buf.size(), pipe) != nullptr) out += buf.data();
    const int status = pclose(pipe);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << c.args << ": " << out;
    if (c.reason.empty())
      EXPECT_EQ(out.rfind(c.named + "cannot write to standard output: ", 0), 0U) << out;
    else
      EXPECT_EQ(out, c.named + "cannot write to standard output: " + c.reason + "\n");
  }
}

// A 16-bit depth PNG read by the executable itself: libraries projbot links (MRPT's nanogui, draco)
// export older stb functions that once took the place of ours and refused every 16-bit PNG.
TEST_F(CliTest, AlignReadsA16BitDepthPng) {
  const std::string png = std::string(PROJBOT_SHARED_DATA) + "/rgbd/open3d_rgbd_sequence/depth/00000.png";
  const auto depth = projbot::assets::read_png_gray16(png);
  ASSERT_EQ(depth.width, 640);
  ASSERT_EQ(depth.height, 480);
  std::size_t expected = 0;  // what depth_to_cloud keeps: 0.3 m to 8 m at 1000 units per metre
  for (const auto v : depth.values) {
    const float z = static_cast<float>(v / 1000.0);
    expected += (z > 0.0F && z >= 0.3 && z <= 8.0) ? 1 : 0;
  }
  ASSERT_GT(expected, 100000U);
  // The duck is not in this room scan: the read must succeed, the gate must refuse (exit 3).
  const CliRun r = run_projbot("align --model " + kDuck + " --scan " + png +
                               " --intrinsics 525,525,319.5,239.5 --depth-scale 1000 --voxel 0.02 --json 2>/dev/null");
  ASSERT_EQ(r.code, 3) << r.output;
  const auto at = r.output.find("\"scan_valid_points\":");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_EQ(std::stoul(r.output.substr(at + 20)), expected) << r.output;
  // A depth image is checked for free space too; at the identity the model is out of view: nothing to
  // check, not accepted.
  EXPECT_NE(r.output.find("\"accepted\":false"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"free_space\":{\"behind_px\":0,"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"passed\":false,\"predicted_px\":0}"), std::string::npos) << r.output;
}

namespace {

// The peak resident KiB of one projbot run, its own (RUSAGE_CHILDREN would give the largest of every
// child this test binary ever ran), or -1 when it could not be run.
long peak_rss_kib(const std::vector<std::string>& args) {
  std::vector<char*> argv{const_cast<char*>(PROJBOT_EXE)};
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t quiet;
  posix_spawn_file_actions_init(&quiet);
  posix_spawn_file_actions_addopen(&quiet, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&quiet, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int spawned = posix_spawn(&pid, PROJBOT_EXE, &quiet, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&quiet);
  int status = 0;
  rusage usage{};
  if (spawned != 0 || wait4(pid, &status, 0, &usage) != pid) return -1;
  return usage.ru_maxrss;
}

}  // namespace

// Hostile point clouds through the executable: one line naming the file, exit 1, never a signal; the
// one claiming 2e9 points is refused within a second and in little memory.
TEST_F(CliTest, HostilePcdFilesAreRefused) {
  const std::string header = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2000000000\nHEIGHT 1\nPOINTS 2000000000\nDATA binary\n";
  const std::vector<std::pair<std::string, std::string>> files{
      {"empty.pcd", ""},
      {"header_only.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 5\nHEIGHT 1\n"},
      {"random.pcd", std::string("\x89\x01\xfe\x00garbage\x7f\x10", 14) + std::string(3000, '\x9c')},
      {"huge.pcd", header + std::string(4800, '\x01')}};
  for (const auto& [name, bytes] : files) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    for (const std::string role : {"--model", "--scan"}) {
      const std::string other = role == "--model" ? " --scan " + (dir_ / "empty.pcd").string() : " --model " + kDuck;
      const CliRun r = run_projbot("align " + role + " " + (dir_ / name).string() + other);
      EXPECT_EQ(r.code, 1) << name << ' ' << role << ": " << r.output;
      EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
      EXPECT_NE(r.output.find("malformed PCD file"), std::string::npos) << r.output;
    }
  }
  // The 2e9 points claimed are refused from the header, not read: the run's peak memory says so (a timed
  // comparison with the empty file's refusal failed on a loaded machine).
  const long kib = peak_rss_kib({"align", "--model", (dir_ / "huge.pcd").string(), "--scan", (dir_ / "empty.pcd").string()});
  EXPECT_GT(kib, 0);
  EXPECT_LT(kib, 200 * 1024) << "peak resident KiB of the run refusing a 2e9-point claim";
}

// render --model frames any model whole: a 10 m box (once cut by the 10 m far plane: an all-black PNG
// and exit 0) and a 1 cm one both fill a good part of the frame; an empty frame is exit 3.
TEST_F(CliTest, RenderModelFramesAnySize) {
  const fs::path box = fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF";
  fs::copy(box, dir_ / "box");
  std::ifstream in(dir_ / "box" / "BoxTextured.gltf");
  auto gltf = nlohmann::json::parse(in);
  in.close();
  gltf["nodes"].push_back({{"children", {0}}, {"scale", {1.0, 1.0, 1.0}}});
  gltf["scenes"][0]["nodes"] = {gltf["nodes"].size() - 1};
  for (const double scale : {10.0, 0.01}) {
    gltf["nodes"].back()["scale"] = {scale, scale, scale};
    std::ofstream(dir_ / "box" / "scaled.gltf") << gltf.dump();
    const fs::path png = dir_ / "scaled.png";
    const CliRun r =
        run_projbot("render --model " + (dir_ / "box" / "scaled.gltf").string() + " --size 160x100 --out " + png.string());
    ASSERT_EQ(r.code, 0) << "scale " << scale << ": " << r.output;
    const auto img = projbot::assets::read_image(png);
    EXPECT_GT(img.lit_pixels(), 160U * 100U / 20U) << "scale " << scale << ": the box should fill more than 5 % of the frame";
  }
  const CliRun empty =
      run_projbot("render --model " + kDuck + " --pose-matrix 1,0,0,0,0,1,0,0,0,0,1,-5,0,0,0,1 --size 64x48 --out " +
                  (dir_ / "empty.png").string());
  EXPECT_EQ(empty.code, 3) << empty.output;
  EXPECT_NE(empty.output.find("the frame is empty"), std::string::npos) << empty.output;
}

// The README's main command: with no options, the shop in tracking mode, the other modes named.
TEST_F(CliTest, TourRunsTheShopInTrackingModeByDefault) {
  const CliRun r = run_projbot("tour --visits 1");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("scenes/shop.yaml in tracking mode (--mode localized"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| visit | figure | paper target 1 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| 1 | figure | no | - |"), std::string::npos) << r.output;  // the tracking table
  // Under the fitted depth model by default: how much of the dwell is lit depends on the machine's load (the
  // figure's tracker keeps up or drops frames); TourJudgesEveryLitFrame... checks the counts of what was lit.
  EXPECT_NE(r.output.find("/181 ("), std::string::npos) << r.output;
}

// The honest twin (issue 87): the depth camera fitted to real frames (bench sensor) unless --depth-model
// kinect, and every lit frame judged against the truth: a visit's far-off counts are its lit frames (the
// arrival's and the timeline's) whose mean error passes 10 and 20 mm, the tour's their sum with the
// neighbours'.
TEST_F(CliTest, TourJudgesEveryLitFrameUnderTheFittedDepthModelByDefault) {
  // A fixed processing time: how many frames the figure's tracker confirms does not depend on the load.
  const CliRun r = run_projbot("tour --visits 1 --dwell 1 --processing-ms 20 --report " + (dir_ / "r.json").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("seed 1, depth model fitted;"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("lit frames (> 10 / > 20 mm off)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("Lit far off (the visited targets and their neighbours, fitted depth model): "), std::string::npos)
      << r.output;
  std::ifstream in(dir_ / "r.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report.at("depth_model"), "fitted");
  ASSERT_EQ(report.at("visits").size(), 1U);
  int over10 = 0, over20 = 0, judged = 0;
  for (const auto& v : report.at("visits")) {
    int v10 = 0, v20 = 0;
    const auto judge = [&](bool lit, const nlohmann::json& mean) {
      if (!lit || mean.is_null()) return;
      ++judged;
      v10 += mean.get<double>() > 10.0 ? 1 : 0;
      v20 += mean.get<double>() > 20.0 ? 1 : 0;
    };
    judge(v.at("projected").get<bool>(), v.at("mean_mm"));
    for (const auto& s : v.at("timeline")) judge(s.at("shown").get<bool>(), s.at("mean_mm"));
    EXPECT_EQ(v.at("lit_over_10mm_frames").get<int>(), v10);
    EXPECT_EQ(v.at("lit_over_20mm_frames").get<int>(), v20);
    over10 += v10, over20 += v20;
    for (const auto& n : v.at("neighbours")) {
      EXPECT_LE(n.at("lit_over_20mm_frames").get<int>(), n.at("lit_over_10mm_frames").get<int>());
      EXPECT_LE(n.at("lit_over_10mm_frames").get<int>(), n.at("lit_frames").get<int>());
      over10 += n.at("lit_over_10mm_frames").get<int>(), over20 += n.at("lit_over_20mm_frames").get<int>();
    }
  }
  EXPECT_GT(judged, 10) << "a second's frames at 60 Hz, lit and measured";
  EXPECT_EQ(report.at("lit_far_off").at("over_10mm_frames").get<int>(), over10);
  EXPECT_EQ(report.at("lit_far_off").at("over_20mm_frames").get<int>(), over20);

  // The published model: the figure lit all along, never off by 10 mm.
  const CliRun k = run_projbot("tour --visits 1 --dwell 1 --depth-model kinect --report " + (dir_ / "k.json").string());
  ASSERT_EQ(k.code, 0) << k.output;
  EXPECT_NE(k.output.find("| 61/61 (0 / 0) |"), std::string::npos) << k.output;
  std::ifstream kin(dir_ / "k.json");
  EXPECT_EQ(nlohmann::json::parse(kin).at("depth_model"), "kinect");
}

// Of the frames lit more than 20 mm off, those that drew a pose captured before its target started or
// stopped moving (motion.yaml: the box carried at 0.5 m/s from 0.5 to 1.5 s, the duck from 0.5 to 1.1 s):
// the pipeline's latency, no frame had shown the change yet. Counted per visit and over the tour, as the
// timeline and the scene's motions say; a still visit has none.
TEST_F(CliTest, TourCountsTheFarOffFramesNoCapturedFrameCouldHaveShown) {
  const CliRun r = run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) +
                               "/scenes/motion.yaml --visits 3 --processing-ms 40 --report " + (dir_ / "m.json").string());
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(dir_ / "m.json");
  const auto report = nlohmann::json::parse(in);
  const double changes[3][2] = {{-1.0, -1.0}, {0.5, 1.5}, {0.5, 1.1}};  // start and end of each visit's motion
  int total = 0;
  for (int k = 0; k < 3; ++k) {
    const auto& v = report.at("visits").at(static_cast<std::size_t>(k));
    int unseen = 0;
    for (const auto& f : v.at("timeline")) {
      if (!f.at("shown").get<bool>() || f.at("mean_mm").is_null() || f.at("mean_mm").get<double>() <= 20.0) continue;
      const double t = f.at("t_s").get<double>(), captured = t - 0.001 * f.at("pose_age_ms").get<double>();
      for (const double c : changes[k]) unseen += c >= captured - 1e-6 && c <= t ? 1 : 0;
    }
    EXPECT_EQ(v.at("lit_over_20mm_change_unseen_frames").get<int>(), unseen) << "visit " << k + 1;
    EXPECT_LE(unseen, v.at("lit_over_20mm_frames").get<int>());
    total += unseen;
  }
  EXPECT_EQ(report.at("visits").at(0).at("lit_over_20mm_change_unseen_frames").get<int>(), 0);
  EXPECT_GT(total, 0) << "a sudden start at 0.5 m/s is drawn behind until a frame shows it";
  EXPECT_EQ(report.at("lit_far_off").at("over_20mm_change_unseen_frames").get<int>(), total);
  EXPECT_NE(r.output.find("Of those more than 20 mm off, " + std::to_string(total) + " drew a pose captured before"),
            std::string::npos)
      << r.output;
}

// A command's default scene is an input like a --scene (issue 72): an output naming it is refused before
// any work, and the shipped file stays as it was. Run on a copy of the assets (PROJBOT_ASSETS).
TEST_F(CliTest, NoOutputReplacesACommandsDefaultScene) {
  const fs::path assets = dir_ / "assets";
  fs::create_directories(assets);
  for (const char* part : {"scenes", "models", "videos", "sites"})
    if (fs::exists(fs::path(PROJBOT_ASSET_DIR) / part))
      fs::copy(fs::path(PROJBOT_ASSET_DIR) / part, assets / part, fs::copy_options::recursive);
  ASSERT_EQ(::setenv("PROJBOT_ASSETS", assets.c_str(), 1), 0);
  const std::map<std::string, std::string> cases{
      {"bench content --report ", "content.yaml"},
      {"bench appearance --report ", "shop.yaml"},
      {"calibrate photometric --sim --out ", "shop.yaml"},
  };
  for (const auto& [command, scene] : cases) {
    const fs::path file = assets / "scenes" / scene;
    std::ifstream before_in(file);
    const std::string before((std::istreambuf_iterator<char>(before_in)), std::istreambuf_iterator<char>());
    const CliRun r = run_projbot(command + file.string(), 120);
    EXPECT_EQ(r.code, 2) << command << r.output;
    EXPECT_NE(r.output.find("is also the input the scene " + file.string()), std::string::npos) << command << r.output;
    std::ifstream after_in(file);
    EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after_in)), std::istreambuf_iterator<char>()), before) << command;
  }
  ::unsetenv("PROJBOT_ASSETS");
}
