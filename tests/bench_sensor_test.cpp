// The sensor benchmark at the library (bench::SensorBench) on one real YCB-V image: the real frame, the
// twin's published Kinect v1 model and the model fitted to real frames, each at the ground truth.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "projbot/bench/sensor.hpp"
#include "projbot/engine/frame_profiler.hpp"

using namespace projbot;
namespace fs = std::filesystem;

namespace {

const fs::path kYcbv = fs::path(PROJBOT_SHARED_DATA) / "ycbv-bop";

// The smallest depth step between neighbours over z^2 (its 10th percentile), mm per m^2.
double step_mm_per_m2(const bench::SensorStats& s) { return 1000.0 * engine::percentile(s.step_per_z2, 0.1); }

TEST(SensorBench, EachSensorAtTheGroundTruthShowsItsOwnDepthSteps) {
  const alignment::BopDataset data = alignment::read_bop_dataset(kYcbv, {"000001"});
  bench::SensorBench bench(data, 0.001);
  bench::SensorComparison c;
  const alignment::BopScene& scene = data.scenes.front();
  bench.image(scene, scene.images.front(), 1500, 1, c);
  EXPECT_EQ(c.images, 1);
  ASSERT_GE(c.instances, 3);
  for (const bench::SensorStats* s : {&c.real, &c.twin, &c.fitted}) {
    ASSERT_GT(s->interior, 1000);  // pixels inside the silhouettes, 2 px from their edges
    ASSERT_FALSE(s->step_per_z2.empty());
    EXPECT_GE(s->offset_mm.size(), 1U);  // one per instance with 100 residuals or more
    EXPECT_LE(s->offset_mm.size(), static_cast<std::size_t>(c.instances));
  }
  // The disparity quantum: the published model's 1000 x 0.125 / (580 x 0.075) = 2.87 mm per m^2, the
  // fitted model's 1.82 (as the command's help says).
  EXPECT_NEAR(step_mm_per_m2(c.twin), 2.87, 0.15);
  EXPECT_NEAR(step_mm_per_m2(c.fitted), 1.82, 0.15);
  // The twin's surfaces are the truth itself: their residual's median is within a step of zero, while
  // both twins miss about as many interior pixels as a real sensor can (a few per cent at most).
  EXPECT_LT(std::abs(engine::percentile(c.twin.residual_mm, 0.5)), 3.0);
  EXPECT_LT(static_cast<double>(c.twin.interior_missing) / static_cast<double>(c.twin.interior), 0.05);
  // Same seed, same image: the same twin.
  bench::SensorComparison again;
  bench.image(scene, scene.images.front(), 1500, 1, again);
  EXPECT_EQ(again.twin.interior_missing, c.twin.interior_missing);
  EXPECT_EQ(again.twin.residual_mm, c.twin.residual_mm);
}

}  // namespace
