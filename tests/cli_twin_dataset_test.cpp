// projbot twin-dataset through the executable (issue 68): a BOP dataset that the readers take as they take
// real ones, whose depth agrees with its own ground truth, reproducible for a seed, and its refusals.

#include "cli_fixture.hpp"

using cli_fixture::CliTest;

namespace {

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The median of the measured depth (mm) inside an instance's visible mask; NaN with none.
double median_depth_mm(const fs::path& depth_png, const fs::path& mask_png, double depth_scale, int& mask_px) {
  const auto depth = projbot::assets::read_png_gray16(depth_png);
  const auto mask = projbot::assets::read_image(mask_png);
  std::vector<double> z;
  mask_px = 0;
  for (std::size_t i = 0; i < depth.values.size(); ++i) {
    if (mask.rgba[4 * i] < 128) continue;
    ++mask_px;
    if (depth.values[i] > 0) z.push_back(depth.values[i] * depth_scale);
  }
  if (z.empty()) return std::nan("");
  std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2), z.end());
  return z[z.size() / 2];
}

}  // namespace

TEST_F(CliTest, TwinDatasetIsABopDatasetWhoseDepthAgreesWithItsGroundTruth) {
  const fs::path out = dir_ / "twin";
  const CliRun r = run_projbot("twin-dataset --out " + out.string() + " --scenes 2 --images 2 --seed 3");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("2 scenes, 4 images"), std::string::npos) << r.output;
  const auto models = read_json(out / "models" / "models_info.json");
  EXPECT_EQ(models.size(), 17U + 5U);  // the 12 + 5 shared YCB-Video meshes and the 5 procedural shapes
  EXPECT_TRUE(models.at("101").contains("symmetries_continuous"));   // the bowl turns about its axis
  EXPECT_FALSE(models.at("105").contains("symmetries_continuous"));  // the bent tube does not
  std::map<int, double> diameter;
  for (const auto& [id, m] : models.items()) diameter[std::stoi(id)] = m.at("diameter").get<double>();
  int instances = 0, checked = 0;
  for (const char* scene : {"000000", "000001"}) {
    const fs::path folder = out / "test" / scene;
    const auto cameras = read_json(folder / "scene_camera.json"), gt = read_json(folder / "scene_gt.json"),
               info = read_json(folder / "scene_gt_info.json");
    ASSERT_EQ(gt.size(), 2U);
    for (const auto& [image, list] : gt.items()) {
      ASSERT_EQ(list.size(), info.at(image).size());
      ASSERT_GE(list.size(), 1U);
      char name[32];
      std::snprintf(name, sizeof name, "%06d", std::stoi(image));
      for (std::size_t k = 0; k < list.size(); ++k, ++instances) {
        char mask[96];
        std::snprintf(mask, sizeof mask, "%s_%06d.png", name, static_cast<int>(k));
        int mask_px = 0;
        const double z = median_depth_mm(folder / "depth" / (std::string(name) + ".png"), folder / "mask_visib" / mask,
                                         cameras.at(image).at("depth_scale").get<double>(), mask_px);
        EXPECT_EQ(mask_px, info.at(image)[k].at("px_count_visib").get<int>()) << scene << " " << mask;
        if (mask_px < 500) continue;
        // The measured surface lies within the object's reach of its ground-truth origin, in depth.
        const double t_z = list[k].at("cam_t_m2c")[2].get<double>(), reach = diameter.at(list[k].at("obj_id").get<int>());
        EXPECT_NEAR(z, t_z, reach) << scene << " " << mask;
        EXPECT_GT(t_z, 450.0);
        EXPECT_LT(t_z, 1800.0);  // the camera 0.6 - 1.5 m from the objects' middle
        ++checked;
      }
    }
  }
  EXPECT_GE(instances, 12);  // 3 to 6 objects a scene
  EXPECT_GE(checked, 6);
  // The same seed writes the same dataset; bench dataset reads it as a real one.
  const CliRun again = run_projbot("twin-dataset --out " + (dir_ / "again").string() + " --scenes 1 --images 2 --seed 3");
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_EQ(text_of(out / "test" / "000000" / "scene_gt.json"), text_of(dir_ / "again" / "test" / "000000" / "scene_gt.json"));
  const CliRun bench = run_projbot("bench dataset " + out.string() + " --perturb 20,5 --seed 1");
  ASSERT_EQ(bench.code, 0) << bench.output;
  const double lit = number_after(bench.output, "| all | 20 mm, 5 deg | projbot | ");
  EXPECT_GE(lit, 6.0) << bench.output;  // estimates made: instances with 1500 visible pixels or more
}

TEST_F(CliTest, TwinDatasetRefusesWhatItCannotWrite) {
  fs::create_directories(dir_ / "full");
  write("full/keep.txt", "mine");
  const CliRun full = run_projbot("twin-dataset --out " + (dir_ / "full").string() + " --scenes 1 --images 1");
  EXPECT_EQ(full.code, 2) << full.output;
  EXPECT_NE(full.output.find("not empty"), std::string::npos) << full.output;
  EXPECT_EQ(text_of(dir_ / "full" / "keep.txt"), "mine");
  fs::create_directories(dir_ / "nomodels");
  const CliRun none = run_projbot("twin-dataset --out " + (dir_ / "o").string() + " --models " + (dir_ / "nomodels").string());
  EXPECT_EQ(none.code, 1) << none.output;
  EXPECT_NE(none.output.find((dir_ / "nomodels" / "models_info.json").string()), std::string::npos) << none.output;
  EXPECT_FALSE(fs::exists(dir_ / "o"));  // nothing left behind
  const CliRun sensor = run_projbot("twin-dataset --out " + (dir_ / "o").string() + " --sensor perfect");
  EXPECT_EQ(sensor.code, 2) << sensor.output;
  EXPECT_NE(sensor.output.find("--sensor"), std::string::npos) << sensor.output;
}
