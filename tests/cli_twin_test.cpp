// The twin's commands through the executable: tours, bench appearance, bench motion, bench acquire and
// run, with the figures they print. Those whose thresholds measure compensation, prediction or placement
// name --depth-model kinect: the published model, whose noise those figures were set on; every command's
// default, the model fitted to real frames, is judged by the tour's far-off counts (cli_test).

#include <algorithm>
#include <regex>

#include "cli_fixture.hpp"

using namespace cli_fixture;

// bench appearance (issue 43): the shop's figure, compensation off and on, scored and reported; the
// compensated picture within the issue's colour goals, the one as stored far off them.
TEST_F(CliTest, BenchAppearanceScoresCompensationOffAndOn) {
  const fs::path report = dir_ / "appearance.json";
  const CliRun r = run_projbot("bench appearance --processing-ms 20 --visits 1 --depth-model kinect --frames " +
                               (dir_ / "frames").string() + " --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("| 1 | figure | no |"), std::string::npos) << r.output;
  std::ifstream in(report);
  const auto json = nlohmann::json::parse(in);
  ASSERT_EQ(json.at("visits").size(), 2U) << json.dump(1);
  const auto& off = json.at("visits")[0];
  const auto& on = json.at("visits")[1];
  EXPECT_EQ(off.at("compensation"), "off");
  EXPECT_EQ(on.at("compensation"), "on");
  EXPECT_EQ(on.at("target"), "figure");
  EXPECT_FALSE(on.at("moving").get<bool>());
  EXPECT_LE(on.at("de2000_median").get<double>(), 5.0) << on.dump();
  EXPECT_LE(on.at("de2000_p95").get<double>(), 12.0) << on.dump();
  EXPECT_GE(on.at("ssim").get<double>(), 0.85) << on.dump();
  EXPECT_GE(on.at("psnr_db").get<double>(), off.at("psnr_db").get<double>() + 10.0) << off.dump() << on.dump();
  EXPECT_GT(off.at("de2000_median").get<double>(), 10.0) << off.dump();
  EXPECT_GT(on.at("ms_per_frame").get<double>(), 0.0);
  EXPECT_TRUE(fs::exists(dir_ / "frames" / "visit01_figure_spectator_off.png"));
  EXPECT_TRUE(fs::exists(dir_ / "frames" / "visit01_figure_spectator_on.png"));
}

// bench appearance on the shop's printed box (issue 43): its gain read over its faces' print, so that the
// visitor sees at most 2 % of its lit pixels clipped (the issue's goal; measured 0.4 %) and the colours
// it can reach within the goals.
TEST_F(CliTest, BenchAppearanceKeepsThePrintedBoxUnclipped) {
  const fs::path report = dir_ / "box.json";
  const CliRun r =
      run_projbot("bench appearance --processing-ms 20 --visits 3 --dwell 0.5 --depth-model kinect --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream in(report);
  const auto rows = nlohmann::json::parse(in).at("visits");
  const auto box = std::find_if(rows.begin(), rows.end(), [](const nlohmann::json& row) {
    return row.at("target") == "box" && row.at("compensation") == "on";
  });
  ASSERT_NE(box, rows.end()) << rows.dump(1);
  EXPECT_LE(box->at("clipped_share").get<double>(), 0.02) << box->dump();
  // Every target's gain holds the projector's own pixels at full to about 2 % (measured 1.8-2.0 %).
  for (const auto& row : rows) {
    if (row.at("compensation") == "on")
      EXPECT_LE(row.at("projector_saturated_share").get<double>(), 0.025) << row.dump();
    else
      EXPECT_TRUE(row.at("projector_saturated_share").is_null()) << row.dump();
  }
  EXPECT_GE(box->at("psnr_db").get<double>(), 24.0) << box->dump();
  EXPECT_GE(box->at("ssim").get<double>(), 0.85) << box->dump();
  EXPECT_LE(box->at("de2000_median").get<double>(), 5.0) << box->dump();
  EXPECT_LE(box->at("de2000_p95").get<double>(), 12.0) << box->dump();
}

// bench appearance on targets that move (issue 43): the box carried at 0.5 m/s is scored through its
// motion (a frame every 0.1 s) beside the same frames drawn where it truly is (what they would show
// standing still there). Its first 0.2 s are a row of their own: the light lags the sudden start until the
// camera's frames show it. After that the motion costs little, and the gain has followed the box down as
// it moved away from the projector's axis (chosen again as it goes, dimming no faster than the plan's rate).
TEST_F(CliTest, BenchAppearanceScoresAMovingTargetBesideItselfStandingStill) {
  const fs::path report = dir_ / "moving.json";
  const CliRun r = run_projbot("bench appearance --processing-ms 20 --scene " + std::string(PROJBOT_ASSET_DIR) +
                               "/scenes/motion.yaml --visits 2 --depth-model kinect --report " + report.string() + " --frames " +
                               (dir_ / "frames").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("PSNR still there dB"), std::string::npos) << r.output;
  for (const char* part : {"starting", "moving"}) {  // the visitor's picture of each part's worst frame
    const fs::path picture = dir_ / "frames" / ("visit02_box_spectator_" + std::string(part) + "_worst.png");
    EXPECT_GT(fs::exists(picture) ? fs::file_size(picture) : 0, 1000U) << picture;
  }
  EXPECT_NE(r.output.find("| starting, 2 frames, worst "), std::string::npos) << r.output;
  std::ifstream in(report);
  const auto rows = nlohmann::json::parse(in).at("visits");
  const nlohmann::json *arrival = nullptr, *starting = nullptr, *moving = nullptr;
  for (const auto& row : rows) {
    if (row.at("target") != "box" || row.at("compensation") != "on") continue;
    const bool is_moving = row.at("moving").get<bool>(), is_starting = row.at("starting").get<bool>();
    (is_starting ? starting : is_moving ? moving : arrival) = &row;
    EXPECT_EQ(row.at("still_psnr_db").is_null(), !is_moving) << row.dump();
  }
  ASSERT_TRUE(arrival && starting && moving) << rows.dump(1);
  EXPECT_EQ(arrival->at("frames"), 1) << arrival->dump();
  EXPECT_EQ(starting->at("frames"), 2) << starting->dump();  // at 0.017 and 0.117 s into the motion
  EXPECT_EQ(moving->at("frames"), 8) << moving->dump();      // 0.2 to 1 s
  const double psnr = moving->at("psnr_db").get<double>(), still = moving->at("still_psnr_db").get<double>();
  EXPECT_GT(psnr, still - 1.5) << moving->dump();  // measured 0.7 dB apart
  EXPECT_GT(still, psnr - 0.5) << moving->dump();  // drawn where it is, no worse than where it was tracked
  EXPECT_GE(psnr, 24.0) << moving->dump();
  EXPECT_LE(moving->at("worst_psnr_db").get<double>(), psnr) << moving->dump();
  // The sudden start: the light is left behind for a frame or two (measured 19.3 dB against 32.1 there).
  EXPECT_LT(starting->at("psnr_db").get<double>(), starting->at("still_psnr_db").get<double>() - 3.0) << starting->dump();
  EXPECT_LT(moving->at("gain").get<double>(), arrival->at("gain").get<double>() - 0.03) << rows.dump(1);
}

// bench appearance --reflectance measured (issue 43): the figure's beige measured at its stop from the
// colour camera under the projector's black and grey, within 3 % of the scene's (the twin's truth).
TEST_F(CliTest, BenchAppearanceMeasuresTheFiguresReflectance) {
  const CliRun r = run_projbot("bench appearance --processing-ms 20 --visits 1 --dwell 0.2 --reflectance measured");
  ASSERT_EQ(r.code, 0) << r.output;
  double m[3] = {0, 0, 0}, t[3] = {0, 0, 0};
  const std::size_t at = r.output.find("visit 1 figure: reflectance measured ");
  ASSERT_NE(at, std::string::npos) << r.output;
  ASSERT_EQ(std::sscanf(r.output.c_str() + at, "visit 1 figure: reflectance measured %lf %lf %lf, the scene's %lf %lf %lf", &m[0],
                        &m[1], &m[2], &t[0], &t[1], &t[2]),
            6)
      << r.output;
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(m[ch], t[ch], 0.03 * t[ch]) << "channel " << ch << "\n" << r.output;
  EXPECT_DOUBLE_EQ(t[0], 0.72);  // the shop's beige
}

// tour --compensation (issue 43, default on): the shop's figure is beige, so the compensated frame sends
// it more blue than red to show its grey content grey; off, the content goes out as stored.
TEST_F(CliTest, TourCompensatesTheFiguresBeigeUnlessTurnedOff) {
  const auto blue_over_red = [&](const std::string& extra, const fs::path& frames) {
    const CliRun r = run_projbot("tour --visits 1 --mode localized --frames " + frames.string() + extra);
    EXPECT_EQ(r.code, 0) << r.output;
    const auto image = projbot::assets::read_image(frames / "visit01_figure.png");
    double red = 0.0, blue = 0.0;
    for (std::size_t i = 0; i < image.rgba.size(); i += 4)
      if (image.rgba[i] + image.rgba[i + 1] + image.rgba[i + 2] > 60) red += image.rgba[i], blue += image.rgba[i + 2];
    return red > 0.0 ? blue / red : 0.0;
  };
  EXPECT_GT(blue_over_red("", dir_ / "on"), 1.15);  // beige reflects red 0.72, blue 0.44
  EXPECT_NEAR(blue_over_red(" --compensation off", dir_ / "off"), 1.0, 0.1);
}

// surface.texture (issue 43): the shop's duck printed with red bands over its UVs (the scene's yellow
// between them). As stored, the bands show through the content; compensated against the print, the visitor
// sees the content within the issue's colour goals. A print that is not there, or not a picture, is one
// line naming it.
TEST_F(CliTest, BenchAppearanceCompensatesAPrintedSurface) {
  projbot::assets::Image print;
  print.width = print.height = 64;
  for (int y = 0; y < print.height; ++y)
    for (int x = 0; x < print.width; ++x) {
      const bool band = (y / 8) % 2 == 0;
      print.rgba.insert(print.rgba.end(), {std::uint8_t(band ? 218 : 229), std::uint8_t(band ? 108 : 206),
                                           std::uint8_t(band ? 89 : 80), std::uint8_t(255)});
    }
  projbot::assets::write_png(dir_ / "print.png", print);
  std::ifstream in(std::string(PROJBOT_ASSET_DIR) + "/scenes/shop.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto replace = [&yaml](const std::string& from, const std::string& to) {
    const auto at = yaml.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), to);
  };
  for (std::size_t at = 0; (at = yaml.find("../models/", at)) != std::string::npos;)
    yaml.replace(at, 10, std::string(PROJBOT_ASSET_DIR) + "/models/");
  replace("surface: {albedo: [0.78, 0.62, 0.08]}", "surface: {texture: print.png}");
  replace("visits: [figure, duck, box,", "visits: [duck]  #");
  std::ofstream(dir_ / "printed.yaml") << yaml;
  const CliRun r = run_projbot("bench appearance --processing-ms 20 --scene " + (dir_ / "printed.yaml").string() + " --report " +
                               (dir_ / "r.json").string());
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream report(dir_ / "r.json");
  const auto json = nlohmann::json::parse(report);
  ASSERT_EQ(json.at("visits").size(), 2U) << json.dump(1);
  const auto& off = json.at("visits")[0];
  const auto& on = json.at("visits")[1];
  EXPECT_EQ(on.at("compensation"), "on");
  EXPECT_LE(on.at("de2000_median").get<double>(), 5.0) << on.dump();
  EXPECT_LE(on.at("de2000_p95").get<double>(), 12.0) << on.dump();
  EXPECT_GE(on.at("ssim").get<double>(), 0.85) << on.dump();
  EXPECT_GE(on.at("psnr_db").get<double>(), off.at("psnr_db").get<double>() + 10.0) << off.dump() << on.dump();
  EXPECT_GT(off.at("de2000_median").get<double>(), 20.0) << off.dump();
  // The print learnt at the stop (--reflectance mapped) instead of given: within the goals too (measured:
  // 26.2 dB, SSIM 0.882, dE2000 1.5 / 4.6, against 26.7, 0.914, 1.4 / 3.5 with the print given).
  const CliRun mapped = run_projbot("bench appearance --processing-ms 20 --scene " + (dir_ / "printed.yaml").string() +
                                    " --reflectance mapped --report " + (dir_ / "m.json").string());
  ASSERT_EQ(mapped.code, 0) << mapped.output;
  EXPECT_NE(mapped.output.find("reflectance measured over its texture coordinates"), std::string::npos) << mapped.output;
  std::ifstream mapped_report(dir_ / "m.json");
  const auto learnt = nlohmann::json::parse(mapped_report).at("visits").at(1);
  EXPECT_LE(learnt.at("de2000_median").get<double>(), 5.0) << learnt.dump();
  EXPECT_LE(learnt.at("de2000_p95").get<double>(), 12.0) << learnt.dump();
  EXPECT_GE(learnt.at("ssim").get<double>(), 0.83) << learnt.dump();
  EXPECT_GE(learnt.at("psnr_db").get<double>(), off.at("psnr_db").get<double>() + 10.0) << learnt.dump();
  // The print missing, then not a picture.
  fs::remove(dir_ / "print.png");
  CliRun bad = run_projbot("bench appearance --processing-ms 20 --scene " + (dir_ / "printed.yaml").string());
  EXPECT_EQ(bad.code, 1) << bad.output;
  EXPECT_NE(bad.output.find("print.png"), std::string::npos) << bad.output;
  std::ofstream(dir_ / "print.png") << "not a picture";
  bad = run_projbot("bench appearance --processing-ms 20 --scene " + (dir_ / "printed.yaml").string());
  EXPECT_EQ(bad.code, 1) << bad.output;
  EXPECT_NE(bad.output.find("print.png"), std::string::npos) << bad.output;
}

// Two targets side by side: at the duck's stop the box is lit in the same projector frames, on the
// right of the duck (the box stands 0.6 m east of it).
TEST_F(CliTest, TourLightsANeighbourInTheSameFrame) {
  const CliRun r = run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) + "/scenes/display.yaml --visits 1" +
                               " --dwell 0.5 --processing-ms 20 --report " + (dir_ / "r.json").string() + " --frames " +
                               (dir_ / "frames").string());
  ASSERT_EQ(r.code, 0) << r.output;
  // Lit in most frames: blank in those whose pose broke its motion's prediction (none far off).
  std::smatch lit;
  ASSERT_TRUE(std::regex_search(r.output, lit, std::regex("; neighbour box lit in ([0-9]+)/31 frames, mean ([0-9.]+) mm")))
      << r.output;
  EXPECT_GE(std::stoi(lit[1]), 22) << r.output;
  EXPECT_LT(std::stod(lit[2]), 5.0) << r.output;
  EXPECT_NE(r.output.find("| 1 | duck | box |"), std::string::npos) << r.output;  // the neighbours table
  std::ifstream in(dir_ / "r.json");
  std::ostringstream json;
  json << in.rdbuf();
  EXPECT_NE(json.str().find("\"neighbours\": [\n        {"), std::string::npos) << json.str().substr(0, 400);
  // The projector frame carries both: the yellow duck left of the middle, the box's white and blue right.
  const auto image = projbot::assets::read_image(dir_ / "frames" / "visit01_duck.png");
  std::size_t left = 0, right = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const auto* p = image.pixel(x, y);
      if (p[0] + p[1] + p[2] < 60) continue;
      (x < image.width * 3 / 4 ? left : right) += 1;
    }
  EXPECT_GT(left, 20000U);
  EXPECT_GT(right, 20000U);
}

// tour --processing-ms: each pose is ready a fixed time after its capture, so the timeline does not depend
// on the machine's load: two runs give the same frames, lit and measured alike, and each drawn pose's age
// at display is that time plus the wait for a projector frame and one refresh (the arrival's pose, taken
// at the stop's start, is 2 refreshes old when its first frame is lit).
TEST_F(CliTest, TourWithAFixedProcessingTimeRepeatsItsTimeline) {
  const auto timeline = [this](const std::string& name) {
    const fs::path report = dir_ / name;
    const CliRun r = run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) +
                                 "/scenes/display.yaml --visits 1 --dwell 0.5 --processing-ms 20 --report " + report.string());
    EXPECT_EQ(r.code, 0) << r.output;
    std::ifstream in(report);
    const auto json = nlohmann::json::parse(in);
    EXPECT_EQ(json.at("processing_ms").get<double>(), 20.0);
    return json.at("visits").at(0).at("timeline");
  };
  const auto first = timeline("a.json"), second = timeline("b.json");
  ASSERT_EQ(first.size(), 30U);  // 0.5 s at 60 Hz
  EXPECT_EQ(first, second);
  int shown = 0;
  for (const auto& frame : first) {
    if (!frame.at("shown").get<bool>()) continue;  // a pose that broke its motion's prediction, or the first
    ++shown;
    const double age_ms = frame.at("pose_age_ms").get<double>();
    EXPECT_GE(age_ms, 1000.0 / 30.0 - 1e-6) << frame.dump();                         // 2 refreshes: the arrival's
    EXPECT_LE(age_ms, 20.0 + 1000.0 / 60.0 + 1000.0 / 30.0 + 1e-6) << frame.dump();  // ready, then a camera frame
  }
  EXPECT_GE(shown, 20);  // 22 here (fitted depth model, seed 1)
}

TEST_F(CliTest, TourPrintsTheTableAndWritesReportAndFrames) {
  const CliRun r = run_projbot("tour --scene " + std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml --mode localized" +
                               " --visits 1 --report " + (dir_ / "r.json").string() + " --frames " + (dir_ / "frames").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("| visit | duck | paper target 1 |"), std::string::npos) << r.output;
  std::ifstream in(dir_ / "r.json");
  std::ostringstream json;
  json << in.rdbuf();
  for (const char* key : {"\"T_projector_target_true\"", "\"T_projector_target_estimated\"", "\"error_mm\"", "\"model_m\"",
                          "\"inlier_ratio\"", "\"fx\"", "\"timings_ms\""})
    EXPECT_NE(json.str().find(key), std::string::npos) << key;
  // The projector frame shows the Duck: a good share of lit pixels, the rest black.
  const auto image = projbot::assets::read_image(dir_ / "frames" / "visit01_duck.png");
  ASSERT_EQ(image.width, 1280);
  std::size_t lit = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) lit += image.pixel(x, y)[0] + image.pixel(x, y)[1] > 40 ? 1 : 0;
  const double share = static_cast<double>(lit) / (image.width * image.height);
  EXPECT_GT(share, 0.01);
  EXPECT_LT(share, 0.5);
  // Beside it, the RGB-D camera's colour view at 640 x 480: the yellow Duck in the middle of a lit room.
  const auto camera = projbot::assets::read_image(dir_ / "frames" / "visit01_duck_camera.png");
  ASSERT_EQ(camera.width, 640);
  ASSERT_EQ(camera.height, 480);
  std::size_t yellow = 0, dark = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const auto* p = camera.pixel(x, y);
      yellow += p[0] > 180 && p[1] > 150 && p[2] < 90 ? 1 : 0;
      dark += p[0] + p[1] + p[2] < 30 ? 1 : 0;
    }
  EXPECT_GT(static_cast<double>(yellow) / (640 * 480), 0.02);
  EXPECT_LT(static_cast<double>(dark) / (640 * 480), 0.05);  // walls and floor everywhere else
  // And a visitor's view of the room with the projector's light on it.
  const auto spectator = projbot::assets::read_image(dir_ / "frames" / "visit01_duck_spectator.png");
  EXPECT_EQ(spectator.width, 960);
  EXPECT_EQ(spectator.height, 720);
}

namespace {

// The figures in one table cell "a / b / c", as numbers.
std::vector<double> numbers_in(const std::string& cell) {
  std::vector<double> out;
  std::istringstream in(cell);
  std::string item;
  while (std::getline(in, item, '/')) out.push_back(std::stod(item));
  return out;
}

}  // namespace

// bench motion through the executable: both runs, side by side, and prediction better on the box
// carried at 0.5 m/s (visit 2 of the shipped motion scene). Each pose ready 20 ms after its capture, as
// in the twin's own test: with this machine's measured times the figures moved with the load (p95 12.5 mm
// once, with CI beside it).
TEST_F(CliTest, BenchMotionComparesPredictionOffAndOn) {
  const CliRun r = run_projbot("bench motion --visits 2 --dwell 2 --processing-ms 20 --depth-model kinect");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("prediction off: 1 2 visits done"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("prediction on: 1 2 visits done"), std::string::npos) << r.output;
  const auto row = r.output.find("| 2 | box | moved | ");
  ASSERT_NE(row, std::string::npos) << r.output;
  std::vector<std::string> cells;
  std::istringstream line(r.output.substr(row, r.output.find('\n', row) - row));
  std::string cell;
  while (std::getline(line, cell, '|')) cells.push_back(cell);
  ASSERT_GE(cells.size(), 6U) << r.output;
  const auto off = numbers_in(cells[4]), on = numbers_in(cells[5]);
  ASSERT_EQ(off.size(), 3U);
  ASSERT_EQ(on.size(), 3U);
  EXPECT_GT(off[0], 8.0);  // 0.5 m/s and a pose about 50 ms old at display: about 25 mm behind
  EXPECT_LT(on[0], 5.0);   // the issue's goal for the mean while moving
  EXPECT_LT(on[1], 10.0);  // and for its 95th percentile
  EXPECT_NE(r.output.find("projector 60 Hz, input lag 0 ms; camera 30 Hz"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("a pose ready 20.0 ms after its capture (fixed)"), std::string::npos) << r.output;
  EXPECT_EQ(run_projbot("bench motion --dwell 0").code, 2);
  EXPECT_EQ(run_projbot("bench motion --processing-ms -1").code, 2);
}

// run lights the neighbour in view with the visited target (assets/scenes/display.yaml: the box beside
// the duck), each from its own tracker worker.
TEST_F(CliTest, RunLightsANeighbourInTheSameFrames) {
  const CliRun r = run_projbot("run --headless --config " + std::string(PROJBOT_ASSET_DIR) +
                               "/scenes/display.yaml --visits 1 --dwell 3 --depth-model kinect");
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string key = " frames lit a neighbour too";
  const auto at = r.output.find(key);
  ASSERT_NE(at, std::string::npos) << r.output;
  const auto from = r.output.rfind("; ", at);
  ASSERT_NE(from, std::string::npos);
  // Of about 180 frames in the 3 s dwell, those after both acquisitions (wall time: 66-102 of 120 in a 2 s
  // dwell, fewer with a build running beside it).
  EXPECT_GT(std::stoi(r.output.substr(from + 2)), 60) << r.output;
  EXPECT_LT(number_after(r.output, "still mean "), 2.5) << r.output;  // both targets' frames
}

// run in the shop: each worker starts a stop with the target's footing and the colour taken on arrival,
// as the tour does; the face-on box slid 2.9 mm along its face on depth alone (all frames: 1.1 mm).
TEST_F(CliTest, RunPlacesTheShopTargetsWithFootingAndColour) {
  const CliRun r = run_projbot("run --headless --config " + std::string(PROJBOT_ASSET_DIR) +
                               "/scenes/shop.yaml --visits 3 --dwell 2 --depth-model kinect");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto still = r.output.find("still mean ");
  // Measured 0.4 on a quiet machine, 0.8 beside a build: the live loop runs in real time, so its figures
  // follow the load; the tour's tests, at a fixed processing time, hold the accuracy itself.
  EXPECT_LT(number_after(r.output, "still mean "), 1.5) << r.output;
  EXPECT_GT(number_after(r.output, " mm over ", still), 200.0) << r.output;  // of about 360 frames: all three lit
}

// run --learn-reflectance (issue 43, item 3): at each stop, once the pose is accepted, the projector shows
// black and then grey while the twin's colour camera sees the target under them; the reflectance read at the
// tracked pose is the scene's surface within 3 % (measured within 0.6 %), learnt as a map over the duck's and
// the box's texture coordinates, and the frames shown black or grey are counted apart. Tracking is as good.
TEST_F(CliTest, RunLearnsEachTargetsReflectanceAtItsStop) {
  const CliRun r =
      run_projbot("run --headless --config " + std::string(PROJBOT_ASSET_DIR) +
                  "/scenes/shop.yaml --visits 3 --dwell 2 --depth-model kinect --learn-reflectance --reflectance-out " +
                  (dir_ / "learnt").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const std::map<std::string, Eigen::Vector3d> scene{
      {"figure", {0.72, 0.58, 0.44}}, {"duck", {0.78, 0.62, 0.08}}, {"box", {0.55, 0.42, 0.30}}};
  for (const auto& [name, truth] : scene) {
    const std::string said = "reflectance of " + name + " measured: ";
    const std::size_t at = r.output.find(said);
    ASSERT_NE(at, std::string::npos) << name << '\n' << r.output;
    double points = 0.0, m[3] = {0, 0, 0};
    ASSERT_EQ(std::sscanf(r.output.c_str() + at + said.size(), "%lf points, median %lf %lf %lf", &points, &m[0], &m[1], &m[2]), 4)
        << r.output;
    EXPECT_GT(points, 100.0) << name;
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(m[ch], truth[ch], 0.03 * truth[ch]) << name << " channel " << ch;
    const bool mapped = r.output.find("(a map over its texture coordinates)", at) < r.output.find('\n', at);
    EXPECT_EQ(mapped, name != "figure") << name << '\n' << r.output;  // the figure's model has no UVs
  }
  EXPECT_NE(r.output.find(" frames black or grey while 3 target reflectance(s) were measured"), std::string::npos) << r.output;
  EXPECT_LT(number_after(r.output, "still mean "), 1.5) << r.output;  // as in the test above: 0.4 quiet, 0.8 loaded
  // Saved as learnt: a surface: line per target for the scene, the maps as PNGs beside it.
  std::ifstream in(dir_ / "learnt" / "surfaces.yaml");
  const std::string saved{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_NE(saved.find("- name: figure\n  surface: {albedo: [0.72"), std::string::npos) << saved;
  for (const char* mapped : {"duck", "box"}) {
    const std::size_t at = saved.find(std::string("- name: ") + mapped + "\n  surface: {texture: ");
    ASSERT_NE(at, std::string::npos) << saved;
    const std::size_t from = saved.find("texture: ", at) + 9;
    const fs::path png = saved.substr(from, saved.find('}', from) - from);
    EXPECT_GT(fs::exists(png) ? fs::file_size(png) : 0, 100U) << png;
  }
  EXPECT_EQ(run_projbot("run --headless --learn-reflectance --replay " + dir_.string()).code, 2);
}

// bench acquire through the executable, one trial per target on the demo tour: a row per target, kind
// of guess and method, and the duck acquired from a 5 cm / 10 degree guess without a false accept.
TEST_F(CliTest, BenchAcquireReportsEveryTargetAndMethod) {
  const CliRun r = run_projbot("bench acquire --scene " + std::string(PROJBOT_ASSET_DIR) + "/scenes/tour.yaml --trials 1");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* row : {"| duck | 5 cm, 10 deg | ours | 1 |", "| duck | 5 cm, 10 deg | PCL | 1 |",
                          "| duck | 30 cm, 40 deg | ours | 1 |", "| box | 30 cm, 40 deg | PCL | 1 |"})
    EXPECT_NE(r.output.find(row), std::string::npos) << row << '\n' << r.output;
  EXPECT_NE(r.output.find("| duck | 5 cm, 10 deg | ours | 1 | 100.0 % | 0 (0) | 0 |"), std::string::npos) << r.output;
  EXPECT_EQ(run_projbot("bench acquire --guess-error 5").code, 2);
  EXPECT_EQ(run_projbot("bench acquire --trials 0").code, 2);
}
