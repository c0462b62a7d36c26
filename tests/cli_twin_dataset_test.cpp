// projbot twin-dataset through the executable (issue 68): a BOP dataset that the readers take as they take
// real ones, whose depth agrees with its own ground truth, reproducible for a seed, and its refusals.

#include <Eigen/Geometry>

#include "cli_fixture.hpp"
#include "projbot/assets/model.hpp"

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

// The lowest point (mm, world z: the table top is 0) of `mesh` placed by an instance's ground truth and
// its image's camera pose.
double lowest_in_world_mm(const projbot::assets::Model& mesh, const nlohmann::json& gt, const nlohmann::json& camera) {
  Eigen::Matrix3d R_m2c, R_w2c;
  for (int i = 0; i < 9; ++i) {
    R_m2c(i / 3, i % 3) = gt.at("cam_R_m2c")[i].get<double>();
    R_w2c(i / 3, i % 3) = camera.at("cam_R_w2c")[i].get<double>();
  }
  Eigen::Vector3d t_m2c, t_w2c;
  for (int i = 0; i < 3; ++i) t_m2c[i] = gt.at("cam_t_m2c")[i].get<double>(), t_w2c[i] = camera.at("cam_t_w2c")[i].get<double>();
  double lowest = 1e9;
  for (const auto& p : mesh.primitives)
    for (const auto& v : p.vertices) {
      const Eigen::Vector3d camera_point = R_m2c * Eigen::Vector3d(v.position[0], v.position[1], v.position[2]) + t_m2c;
      lowest = std::min(lowest, (R_w2c.transpose() * (camera_point - t_w2c)).z());
    }
  return lowest;
}

// The enclosed volume (mm^3) of a closed mesh: positive when its faces point outward.
double signed_volume(const projbot::assets::Model& mesh) {
  double v = 0.0;
  for (const auto& p : mesh.primitives)
    for (std::size_t i = 0; i + 2 < p.indices.size(); i += 3) {
      const auto at = [&](std::size_t k) {
        const auto& q = p.vertices[p.indices[i + k]].position;
        return Eigen::Vector3d(q[0], q[1], q[2]);
      };
      v += at(0).dot(at(1).cross(at(2))) / 6.0;
    }
  return v;
}

}  // namespace

// Every object of a scene rests on the table (its lowest point at the table top, z = 0 in the world the
// cameras' cam_R_w2c / cam_t_w2c give), and the procedural shapes are closed with their faces outward:
// the cup holds its walls' volume, not its hollow's.
TEST_F(CliTest, TwinDatasetObjectsRestOnTheTableAndTheShapesAreSolid) {
  const fs::path out = dir_ / "twin";
  const CliRun r = run_projbot("twin-dataset --out " + out.string() + " --scenes 1 --images 1 --seed 4");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto gt = read_json(out / "test" / "000000" / "scene_gt.json").at("0");
  const auto camera = read_json(out / "test" / "000000" / "scene_camera.json").at("0");
  ASSERT_GE(gt.size(), 1U);
  for (const auto& instance : gt) {
    char name[32];
    std::snprintf(name, sizeof name, "obj_%06d.ply", instance.at("obj_id").get<int>());
    EXPECT_NEAR(lowest_in_world_mm(projbot::assets::load_mesh(out / "models" / name), instance, camera), 0.0, 0.5) << name;
  }
  const double cup = signed_volume(projbot::assets::load_mesh(out / "models" / "obj_000102.ply"));
  const double walls = M_PI * (40.0 * 40.0 * 95.0 - 37.0 * 37.0 * 89.0);  // outer cylinder less the hollow
  EXPECT_NEAR(cup, walls, 0.01 * walls);
  for (const int id : {101, 103, 104, 105}) {
    char name[32];
    std::snprintf(name, sizeof name, "obj_%06d.ply", id);
    EXPECT_GT(signed_volume(projbot::assets::load_mesh(out / "models" / name)), 1000.0) << name;
  }
}

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

// The twin's scene 1 (seed 1) holds a flat box and flat scissors lying on the table, the camera all but
// still: tracked from 20 mm / 5 deg, both once ran away along the table (to 469 and 478 mm off, lit on
// every image, the free-space check passed: thin parts lying in the table's depth). Nothing lit may lie
// 50 mm from a still target (the scissors slip up to about 20 mm: depth barely sees them on the table).
TEST_F(CliTest, TrackingDoesNotRunAwayAlongTheTableWithFlatObjects) {
  const fs::path out = dir_ / "twin", report = dir_ / "track.json";
  const CliRun made = run_projbot("twin-dataset --out " + out.string() + " --scenes 2 --seed 1");
  ASSERT_EQ(made.code, 0) << made.output;
  const CliRun r = run_projbot("bench dataset " + out.string() +
                               " --scenes 000001 --track --perturb 20,5 --min-visible 1500 --seed 5 --report " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  int rows = 0, lit_within_10 = 0, flat = 0;
  const nlohmann::json estimates = read_json(report);
  for (const auto& row : estimates.at("instances")) {
    if (row.at("method") != "projbot") continue;
    ++rows;
    const double error = row.at("error_mm").get<double>();
    const bool lit = row.at("accepted").get<bool>();
    if (lit) {
      EXPECT_LT(error, 50.0) << "obj " << row.at("obj_id") << " image " << row.at("image");
    }
    lit_within_10 += lit && error <= 10.0;
    const int obj = row.at("obj_id").get<int>();
    flat += obj == 8 || obj == 17;
    // Tracking's rows carry the checks of the pose shown, as the acquisition's do.
    if (lit) {
      EXPECT_GT(row.at("agree_ratio").get<double>(), 0.5);
    }
  }
  EXPECT_EQ(rows, 50);  // 5 objects over 10 images
  EXPECT_EQ(flat, 20);
  EXPECT_GE(lit_within_10, 45);  // 39 when they ran away
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
