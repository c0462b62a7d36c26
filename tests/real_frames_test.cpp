// Pose estimation on real frames (the shared YCB-V frames in BOP format): bench dataset's report through
// the executable, and `projbot align` giving the benchmark's estimate from the same start.

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <vector>

#include "cli_run.hpp"

namespace fs = std::filesystem;

namespace {

const fs::path kYcbv = fs::path(PROJBOT_SHARED_DATA) / "ycbv-bop";

class RealFrames : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_real_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

std::string matrix_arg(const nlohmann::json& m) {
  std::ostringstream out;
  out.precision(17);
  for (std::size_t i = 0; i < m.size(); ++i) out << (i ? "," : "") << m[i].get<double>();
  return out.str();
}

}  // namespace

// The report holds one row per estimate and method with the issue's fields; `align` from a row's start,
// with the image's camera and the model in millimetres, ends where the benchmark's estimate did.
TEST_F(RealFrames, BenchDatasetReportsEachEstimateAndAlignAgreesWithIt) {
  const fs::path report = dir_ / "r.json";
  const CliRun r = run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --max-instances 3 --perturb 20,5 --report " +
                               report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("| all | 20 mm, 5 deg | projbot | 3 |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| all | 20 mm, 5 deg | pcl | 3 |"), std::string::npos) << r.output;
  const auto j = read_json(report);
  EXPECT_FALSE(j.at("interrupted").get<bool>());
  const auto& rows = j.at("instances");
  ASSERT_EQ(rows.size(), 6U);
  for (const auto& row : rows) {
    for (const char* key :
         {"scene", "image", "gt_index", "obj_id", "method", "mode", "perturbation", "T_est", "accepted", "time_ms"})
      EXPECT_TRUE(row.contains(key)) << key;
    EXPECT_EQ(row.at("scene"), "000000");
    EXPECT_EQ(row.at("image"), 1);
    EXPECT_EQ(row.at("mode"), "acquire");
    EXPECT_EQ(row.at("T_est").size(), 16U);
    EXPECT_EQ(row.at("perturbation"), nlohmann::json::array({20.0, 5.0}));
    EXPECT_LE(row.at("adds_mm").get<double>(), row.at("add_mm").get<double>() + 1e-9) << "ADD-S never exceeds ADD";
  }
  // Issue 68: YCB-Video's AUCs over 0-10 cm, printed beside ours; recomputed here from the report's rows.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(
      r.output, m,
      std::regex(R"(\| 20 mm, 5 deg \| projbot \| (\d+) of 3 \| ([0-9.]+) \| ([0-9.]+) \| ([0-9.]+) \| ([0-9.]+) \|)")))
      << r.output;
  double add_lit = 0, adds_lit = 0;
  int lit = 0;
  for (const auto& row : rows)
    if (row.at("method") == "projbot" && row.at("accepted").get<bool>()) {
      ++lit;
      add_lit += 1.0 - std::min(row.at("add_mm").get<double>(), 100.0) / 100.0;
      adds_lit += 1.0 - std::min(row.at("adds_mm").get<double>(), 100.0) / 100.0;
    }
  EXPECT_EQ(std::stoi(m[1].str()), lit);
  if (lit > 0) {
    EXPECT_NEAR(std::stod(m[2].str()), 100.0 * add_lit / lit, 0.051);
    EXPECT_NEAR(std::stod(m[3].str()), 100.0 * adds_lit / lit, 0.051);
  }
  EXPECT_NEAR(std::stod(m[4].str()), 100.0 * add_lit / 3, 0.051) << "a blank counts as a miss";
  EXPECT_NEAR(std::stod(m[5].str()), 100.0 * adds_lit / 3, 0.051);
  // The first row: ours on scene 000000, image 1, instance 0 (the gelatin box, obj 8).
  const auto& first = rows[0];
  ASSERT_EQ(first.at("method"), "projbot");
  ASSERT_EQ(first.at("obj_id"), 8);
  const CliRun a = run_projbot("align --model " + (kYcbv / "models" / "obj_000008.ply").string() +
                               " --model-scale 0.001 --scan " + (kYcbv / "test" / "000000" / "depth" / "000001.png").string() +
                               " --intrinsics 1066.778,1067.487,312.9869,241.3109 --depth-scale 10000 --guess-error 20,5 --json"
                               " --init-matrix " +
                               matrix_arg(first.at("T_start")));
  ASSERT_TRUE(a.code == 0 || a.code == 3) << a.output;
  const auto at = a.output.find('{');
  ASSERT_NE(at, std::string::npos) << a.output;
  const auto out = nlohmann::json::parse(a.output.substr(at));
  EXPECT_EQ(out.at("accepted").get<bool>(), first.at("accepted").get<bool>());
  for (int i = 0; i < 16; ++i)
    EXPECT_NEAR(out.at("T")[static_cast<std::size_t>(i / 4)][static_cast<std::size_t>(i % 4)].get<double>(),
                first.at("T_est")[static_cast<std::size_t>(i)].get<double>(), 1e-9)
        << i;
}

// A start depends on the seed, the instance and the perturbation's values, not on which other
// perturbations run beside it: `--perturb 50,15` alone draws what it draws after 20,5 (it once drew other
// starts, and the README's figure for it alone differed from the table's by 2 points).
TEST_F(RealFrames, BenchDatasetStartsDoNotDependOnTheOtherPerturbations) {
  const auto starts = [&](const std::string& perturb, const std::string& name) {
    const fs::path report = dir_ / name;
    const CliRun r = run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --max-instances 3 " + perturb +
                                 " --report " + report.string());
    EXPECT_EQ(r.code, 0) << r.output;
    std::vector<std::string> out;
    const auto j = read_json(report);
    for (const auto& row : j.at("instances"))
      if (row.at("perturbation") == nlohmann::json::array({50.0, 15.0})) out.push_back(row.at("T_start").dump());
    return out;
  };
  const std::vector<std::string> alone = starts("--perturb 50,15", "alone.json");
  const std::vector<std::string> beside = starts("--perturb 20,5 --perturb 50,15", "beside.json");
  ASSERT_EQ(alone.size(), 6U);  // the first image's 3 instances, ours and PCL's from the same start
  // --max-instances counts instances, not images (issue 88: 1 ran the whole first image).
  {
    const CliRun one = run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --max-instances 1 --perturb 50,15");
    EXPECT_NE(one.output.find("| all | 50 mm, 15 deg | projbot | 1 |"), std::string::npos) << one.output;
    const CliRun track =
        run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --max-instances 1 --track --perturb 20,5");
    EXPECT_NE(track.output.find("| all | 20 mm, 5 deg | projbot | 20 |"), std::string::npos)
        << track.output;  // 1 object, 20 images
  }
  EXPECT_EQ(alone[0], alone[1]);
  EXPECT_EQ(alone, beside);
  EXPECT_NE(alone, starts("--perturb 50,15 --seed 2", "seed2.json"));
}

// The goal's thresholds on a subset of the real frames, in bounded time: from 20 mm / 5 degree starts every
// instance of scene 000001's first four images (master chef can, cracker box, sugar box, mustard bottle,
// 16 estimates) is lit within 10 mm (>= 95 %), none is lit more than 20 mm off, and at most 5 % are
// refused while within 10 mm. (The whole dataset's figures are the README's.)
TEST_F(RealFrames, AcquisitionMeetsTheGoalOnRealFramesOfTheSharedDataset) {
  const fs::path report = dir_ / "r.json";
  const CliRun r =
      run_projbot("bench dataset " + kYcbv.string() + " --scenes 000001 --max-instances 16 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  int n = 0, within = 0, false_accepts = 0, false_rejects = 0, pcl = 0;
  const auto j = read_json(report);  // kept: a range-for over a temporary's member would dangle
  for (const auto& row : j.at("instances")) {
    if (row.at("method").get<std::string>() != "projbot") {
      ++pcl;
      continue;
    }
    ++n;
    const double e = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    within += lit && e <= 10.0 ? 1 : 0;
    false_accepts += lit && e > 20.0 ? 1 : 0;
    false_rejects += !lit && e <= 10.0 ? 1 : 0;
  }
  ASSERT_EQ(n, 16) << r.output;
  EXPECT_EQ(pcl, 16);
  EXPECT_GE(within, 16 * 95 / 100 + 1) << r.output;  // >= 95 % of 16: all 16
  EXPECT_EQ(false_accepts, 0) << r.output;
  EXPECT_LE(false_rejects * 20, n) << r.output;
}

// The red mug of scene 000000 with its handle hidden behind it, from 20 mm / 5 degree starts (its
// first seven images): ICP from two of them was pulled onto the neighbours (refused, 100 mm off), and
// the lit ones were turned 7-12 degrees about the mug's axis, which depth cannot see (6-8 mm by ADD).
// The candidates around a close start where its ICP fails, and the guess's turn about an axis the view
// leaves free: all seven lit within 10 mm, six within 5 mm, none lit wrong.
TEST_F(RealFrames, AMugWithItsHandleHiddenKeepsItsGuessTurn) {
  const fs::path report = dir_ / "mug.json";
  const CliRun r =
      run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --max-instances 21 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  int mugs = 0, within_10 = 0, within_5 = 0, false_accepts = 0;
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    if (row.at("method").get<std::string>() != "projbot") continue;
    const double e = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    false_accepts += lit && e > 20.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() != 14) continue;
    ++mugs;
    within_10 += lit && e <= 10.0 ? 1 : 0;
    within_5 += lit && e <= 5.0 ? 1 : 0;
  }
  ASSERT_EQ(mugs, 7) << r.output;
  EXPECT_EQ(within_10, 7) << r.output;
  EXPECT_GE(within_5, 6) << r.output;
  EXPECT_EQ(false_accepts, 0) << r.output;
}

// The cluttered scene: a banana leaning on a wood block, a gelatin box on top of it, a mustard bottle behind.
// The block, half hidden, scored 0.62-0.68 of its points explained at its own ground truth (the banana
// and the box in front counted against it) and was refused at every pose; ICP was pulled 10-15 mm onto
// them. With occluders neutral in the gate and correspondences far past the median rejected, the block
// of the first image is lit within 10 mm. The banana, within 2 mm, was refused (0.65 of its points
// explained: the block's top beside it, at its depth, counted against it) until a close guess's gate
// left out what lies beside the outline more than two tolerances from the model: now it is lit in both
// images, 11 of the 12 instances are (the pudding box on the block, refused once), none is lit wrong.
TEST_F(RealFrames, AcquisitionHoldsAmongTouchingNeighbours) {
  const fs::path report = dir_ / "clutter.json";
  const CliRun r =
      run_projbot("bench dataset " + kYcbv.string() + " --scenes 000002 --max-instances 12 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  int n = 0, within = 0, false_accepts = 0;
  bool block_lit = false;
  int banana_lit = 0;
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    if (row.at("method").get<std::string>() != "projbot") continue;
    ++n;
    const double e = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    within += lit && e <= 10.0 ? 1 : 0;
    false_accepts += lit && e > 20.0 ? 1 : 0;
    if (row.at("image").get<int>() == 1 && row.at("obj_id").get<int>() == 16) block_lit = lit && e <= 10.0;
    if (row.at("obj_id").get<int>() == 10) banana_lit += lit && e <= 10.0 ? 1 : 0;
  }
  ASSERT_EQ(n, 12) << r.output;
  EXPECT_TRUE(block_lit) << r.output;
  EXPECT_EQ(banana_lit, 2) << r.output;
  EXPECT_GE(within, 10) << r.output;
  EXPECT_EQ(false_accepts, 0) << r.output;
}

// The cluttered scene from 50 mm / 15 degree starts: ICP from there settled on the table and the
// neighbours (5 of these 12 lit within 10 mm; the mustard bottle behind the block, the pudding box on it
// and the banana leaning on it refused in both images, 45-125 mm off). Poses around the start scored
// against the depth first (coarse_candidates), each acquired with the support found under it (the
// block's top for the pudding box; the gross start's wider reach took in the table too, and the box
// stood 24 mm above that): 11 lit within 10 mm, both bottles and both pudding boxes, none lit wrong.
TEST_F(RealFrames, GrossStartsAreFoundAmongTouchingNeighbours) {
  const fs::path report = dir_ / "gross.json";
  const CliRun r = run_projbot("bench dataset " + kYcbv.string() +
                               " --scenes 000002 --max-instances 12 --perturb 50,15 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  int n = 0, within = 0, false_accepts = 0, bottles = 0, puddings = 0;
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    if (row.at("method").get<std::string>() != "projbot") continue;
    ++n;
    const bool right = row.at("accepted").get<bool>() && row.at("error_mm").get<double>() <= 10.0;
    within += right ? 1 : 0;
    false_accepts += row.at("accepted").get<bool>() && row.at("error_mm").get<double>() > 20.0 ? 1 : 0;
    bottles += right && row.at("obj_id").get<int>() == 5 ? 1 : 0;
    puddings += right && row.at("obj_id").get<int>() == 7 ? 1 : 0;
  }
  ASSERT_EQ(n, 12) << r.output;
  EXPECT_GE(within, 10) << r.output;
  EXPECT_EQ(false_accepts, 0) << r.output;
  EXPECT_EQ(bottles, 2) << r.output;
  EXPECT_EQ(puddings, 2) << r.output;
}

// The potted meat can of the cluttered scene from two of bench dataset's 50 mm / 15 degree starts, through
// `align`: the candidate scored first fitted it onto its look-alike neighbour (lit 117-119 mm off, 0.92
// of its points explained); of the candidates that converge, the one nearest the start is kept: within
// 10 mm of the truth.
TEST_F(RealFrames, AGrossStartKeepsTheConvergedCandidateNearestIt) {
  const auto gt = read_json(kYcbv / "test" / "000002" / "scene_gt.json");
  const std::vector<std::pair<int, std::string>> starts{
      // image, T_start (bench dataset --perturb 50,15, seed 1)
      {5,
       "0.63376990267722755,-0.074039771510724772,0.7699700141532374,0.12585964850052223,-0.60390453770817754,"
       "-0.66937161576178639,0.43271347257501447,0.090460450001917436,0.48335806582281171,-0.73922916084736201,"
       "-0.46894053776244926,1.044143233511216,0,0,0,1"},
      {9,
       "0.79776864265791292,0.09254436988839071,0.59581937900148174,0.11156006335361762,-0.23547101058497355,"
       "-0.86186854314514516,0.44915032841016156,0.082541693612644795,0.55508431428553451,-0.4986162391447207,"
       "-0.66578018151288665,1.0915192207105961,0,0,0,1"}};
  for (const auto& [image, start] : starts) {
    char depth[32];
    std::snprintf(depth, sizeof depth, "%06d.png", image);
    const CliRun a = run_projbot("align --model " + (kYcbv / "models" / "obj_000009.ply").string() +
                                 " --model-scale 0.001 --scan " + (kYcbv / "test" / "000002" / "depth" / depth).string() +
                                 " --intrinsics 1066.778,1067.487,312.9869,241.3109 --depth-scale 10000 --guess-error 50,15"
                                 " --json --init-matrix " +
                                 start);
    ASSERT_EQ(a.code, 0) << a.output;
    const auto out = nlohmann::json::parse(a.output.substr(a.output.find('{')));
    const auto& truth = gt.at(std::to_string(image)).at(2);  // the potted meat can, its third instance
    ASSERT_EQ(truth.at("obj_id").get<int>(), 9);
    double d2 = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double e = out.at("T")[i][3].get<double>() - truth.at("cam_t_m2c")[i].get<double>() / 1000.0;
      d2 += e * e;
    }
    EXPECT_LT(std::sqrt(d2), 0.010) << image << ' ' << a.output;
  }
}

// A start from bench dataset on scene 000002, through `align` (the image's camera, the model in mm, a
// 50 mm / 15 degree guess error): refused (exit 3) or lit within 10 mm of the truth, never lit wrong.
namespace {

struct GrossStart {
  int image, gt_index, obj_id;
  std::string T;
};

void expect_blank_or_right(const GrossStart& s) {
  const auto gt = read_json(kYcbv / "test" / "000002" / "scene_gt.json");
  char depth[32], model[32];
  std::snprintf(depth, sizeof depth, "%06d.png", s.image);
  std::snprintf(model, sizeof model, "obj_%06d.ply", s.obj_id);
  const CliRun a = run_projbot("align --model " + (kYcbv / "models" / model).string() + " --model-scale 0.001 --scan " +
                               (kYcbv / "test" / "000002" / "depth" / depth).string() +
                               " --intrinsics 1066.778,1067.487,312.9869,241.3109 --depth-scale 10000 --guess-error 50,15"
                               " --json --init-matrix " +
                               s.T);
  ASSERT_TRUE(a.code == 0 || a.code == 3) << a.output;
  if (a.code == 3) return;  // blank: not lit on the neighbour
  const auto out = nlohmann::json::parse(a.output.substr(a.output.find('{')));
  const auto& truth = gt.at(std::to_string(s.image)).at(s.gt_index);
  ASSERT_EQ(truth.at("obj_id").get<int>(), s.obj_id);
  double d2 = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double e = out.at("T")[i][3].get<double>() - truth.at("cam_t_m2c")[i].get<double>() / 1000.0;
    d2 += e * e;
  }
  EXPECT_LT(std::sqrt(d2), 0.010) << s.image << ' ' << a.output;
}

}  // namespace

// Two starts whose candidates all lay on a neighbour (the potted meat can beside its look-alike, the
// banana on the wood block): the fits converged 82-88 mm from the start's centroid, within the
// silhouette's reach (68-78 mm, the turn included) and its margin, and were lit 116-125 mm off. A turn
// about the centroid does not move it, so the start's error bounds the centroid by the move alone.
TEST_F(RealFrames, AGrossStartRefusesAFitBeyondItsError) {
  expect_blank_or_right({8, 2, 9,
                         "0.42260488262621315,0.1304855167499071,0.896871586738589,0.121671095031957,-0.46601471853191195,"
                         "-0.8174572819492991,0.33851716987427255,0.09241923194580597,0.7773257973926424,-0.5610143688949275,"
                         "-0.2846532673294278,1.0831290162633334,0,0,0,1"});
  expect_blank_or_right({20, 3, 10,
                         "0.5504144002512624,0.7327472861184645,0.4001567226500984,-0.05032060736199118,0.489147619472322,"
                         "-0.6714408275817827,0.5566882623343614,0.02870001408613594,0.6765933744581032,-0.11067352773954334,"
                         "-0.7279922910972898,1.011695187194649,0,0,0,1"});
}

// The marker (a 2 cm thick pen standing upright) from a start 50 mm behind it: every candidate's fit
// sank into the box behind it (lit 90 mm off, 0.76 of its points explained, nothing seen through it),
// its outline flush with the box's face and 0.30 of it behind the marker itself: a fit that hides.
TEST_F(RealFrames, AGrossStartRefusesAFitHiddenBehindTheTarget) {
  expect_blank_or_right({6, 5, 18,
                         "0.9895295766213298,0.0580529573672247,-0.13214034634633987,-0.017279110411197313,0.11779054896808039,"
                         "-0.853902275882134,0.5069282886337179,0.08507228507734607,-0.08340625615269975,-0.5171854187660659,"
                         "-0.8517996472471443,0.9924031046801995,0,0,0,1"});
}

// --track on the scene whose potted meat can was once followed 60-70 mm off on its neighbour (its first
// search was not the acquisition, and it was not told its guess's uncertainty): every object found on
// the first image stays within 10 mm, nothing lit wrong; the banana leaning on the block, refused on the
// first image until the gate of a close guess left its neighbour out, found there and followed; the wood
// block, which the tracker loses where the banana and the box it carries pull it, found again (before the
// support was found afresh for each search, the first image's refused it from the fifth on: 4 of 20).
TEST_F(RealFrames, TrackingFollowsWhatTheFirstImageFinds) {
  const fs::path report = dir_ / "t.json";
  const CliRun r = run_projbot("bench dataset " + kYcbv.string() + " --scenes 000002 --track --report " + report.string(), 600);
  ASSERT_EQ(r.code, 0) << r.output;
  int potted_meat = 0, potted_meat_within = 0, banana_within = 0, block_within = 0, marker_within = 0, false_accepts = 0;
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    EXPECT_EQ(row.at("mode").get<std::string>(), "track");
    const double e = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    false_accepts += lit && e > 20.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() == 10) banana_within += lit && e <= 10.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() == 16) block_within += lit && e <= 10.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() == 18) marker_within += lit && e <= 10.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() != 9) continue;
    ++potted_meat;
    potted_meat_within += lit && e <= 10.0 ? 1 : 0;
  }
  EXPECT_EQ(potted_meat, 20) << r.output;
  EXPECT_GE(potted_meat_within, 19) << r.output;
  EXPECT_GE(banana_within, 19) << r.output;
  EXPECT_GE(block_within, 16) << r.output;
  // The marker standing upright, its cap hardly measured: ICP slid it 6.8 mm up its axis, above the
  // support found around it, which refused it on every image (0 of 20) until such a pose was put down
  // onto the support where the depth agrees as well there (20 of 20).
  EXPECT_GE(marker_within, 18) << r.output;
  EXPECT_EQ(false_accepts, 0) << r.output;
}

// Ours per video, where a run spans several: each video's estimates as the report has them.
TEST_F(RealFrames, BenchDatasetTellsEachVideoApart) {
  const fs::path report = dir_ / "v.json";
  const CliRun r =
      run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000,000001 --track --report " + report.string(), 600);
  ASSERT_EQ(r.code, 0) << r.output;
  std::map<std::string, std::pair<int, int>> by_video;  // estimates, lit within 10 mm
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    auto& [n, within] = by_video[row.at("scene").get<std::string>()];
    ++n;
    within += row.at("accepted").get<bool>() && row.at("error_mm").get<double>() <= 10.0 ? 1 : 0;
  }
  ASSERT_EQ(by_video.size(), 2U);
  for (const auto& [video, counts] : by_video) {
    char row[96];
    std::snprintf(row, sizeof row, "| %s | 20 mm, 5 deg | %d | %.1f %% | 0 |", video.c_str(), counts.first,
                  100.0 * counts.second / counts.first);
    EXPECT_NE(r.output.find(row), std::string::npos) << row << "\n" << r.output;
  }
}

// The mug seen from above, its inside showing (scene 000000): the projective tracker pulled it 17 mm and
// 14 degrees off on every image and the free-space check refused that, so it blanked and was found again
// every third image (14 of 20 lit within 10 mm). A refused track now gets the acquisition's local step on
// the same frame.
TEST_F(RealFrames, TrackingKeepsTheMugWhoseTrackIsSeenThrough) {
  const fs::path report = dir_ / "mug.json";
  const CliRun r = run_projbot("bench dataset " + kYcbv.string() + " --scenes 000000 --track --report " + report.string(), 600);
  ASSERT_EQ(r.code, 0) << r.output;
  int mug = 0, mug_within = 0, false_accepts = 0;
  const auto j = read_json(report);
  for (const auto& row : j.at("instances")) {
    const double e = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    false_accepts += lit && e > 20.0 ? 1 : 0;
    if (row.at("obj_id").get<int>() != 14) continue;
    ++mug;
    mug_within += lit && e <= 10.0 ? 1 : 0;
  }
  EXPECT_EQ(mug, 20) << r.output;
  EXPECT_GE(mug_within, 18) << r.output;
  EXPECT_EQ(false_accepts, 0) << r.output;
}

namespace {

// The cell of a bench sensor row that starts with `what`: its real (column 1) or twin (column 2) value.
std::string sensor_cell(const std::string& output, const std::string& what, int column) {
  const auto at = output.find("| " + what);
  if (at == std::string::npos) return "";
  std::string line = output.substr(at, output.find('\n', at) - at);
  std::stringstream cells(line);
  std::string cell;
  for (int i = 0; i <= column + 1 && std::getline(cells, cell, '|');) ++i;
  return cell;
}

double first_number(const std::string& cell) { return std::stod(cell.substr(cell.find_first_of("+-0123456789"))); }

}  // namespace

// The sensor comparison on one scene's first images, through the executable: the real frames agree with
// the rendered ground truth to a few millimetres (the issue's 2.2 mm median, an estimate's floor), the
// twin's depth steps are its model's 2.87 mm per m^2 (1/8 px of disparity); the real ones are finer, and
// the model fitted to them has their 1.8 mm per m^2 and their smooth noise.
TEST_F(RealFrames, BenchSensorComparesRealAndTwinAtTheGroundTruth) {
  const CliRun r = run_projbot("bench sensor " + kYcbv.string() + " --scenes 000001 --max-images 2", 300);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("The real sensor and the twin's at the ground truth: "), std::string::npos) << r.output;
  const std::string inside = "inside the silhouette: depth - truth";
  const double real_median = first_number(sensor_cell(r.output, inside, 1));
  EXPECT_GT(real_median, 0.1) << r.output;
  EXPECT_LT(real_median, 4.0) << r.output;
  EXPECT_LT(first_number(sensor_cell(r.output, inside, 2)), real_median) << "the twin is kinder inside: " << r.output;
  const std::string steps = "depth step between neighbours / z^2";
  EXPECT_NEAR(first_number(sensor_cell(r.output, steps, 2)), 2.87, 0.2) << r.output;
  EXPECT_NEAR(first_number(sensor_cell(r.output, steps, 3)), 1.82, 0.15) << r.output;
  const std::string alike = "that noise's correlation with the pixel 1 / 3 / 8 px";
  EXPECT_LT(first_number(sensor_cell(r.output, alike, 2)), 0.5) << "the published model's noise is per pixel: " << r.output;
  EXPECT_GT(first_number(sensor_cell(r.output, alike, 3)), 0.8) << "the fitted model's is smooth: " << r.output;
  const double real_steps = first_number(sensor_cell(r.output, steps, 1));  // finer than 1/8 px: about 1 mm per m^2
  EXPECT_GT(real_steps, 0.2) << r.output;
  EXPECT_LT(real_steps, 4.0) << r.output;
  const double missing = first_number(sensor_cell(r.output, "missing inside", 1));
  EXPECT_GE(missing, 0.0);
  EXPECT_LT(missing, 30.0) << r.output;
}
