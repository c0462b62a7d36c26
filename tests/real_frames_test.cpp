// Pose estimation on real frames (the shared YCB-V frames in BOP format): bench dataset's report through
// the executable, and `projbot align` giving the benchmark's estimate from the same start.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

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

// The report holds one row per estimate and method with the fields; `align` from a row's start,
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
  }
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
