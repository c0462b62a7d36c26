#include "projbot/live/trackers.hpp"

#include <limits>

#include "projbot/assets/model.hpp"

namespace projbot::live {

alignment::WorkerConfig worker_config(bool predict, bool lockstep) {
  alignment::WorkerConfig c;
  c.predict = predict;
  if (lockstep) c.acquisition.attempt_budget_ms = std::numeric_limits<double>::infinity();
  return c;
}

SceneTrackers make_trackers(const config::Scene& scene, const alignment::WorkerConfig& config) {
  SceneTrackers t;
  const std::size_t n = scene.targets.size();
  t.clouds.resize(n);
  t.owned.resize(n);
  t.workers.assign(n, nullptr);
  const alignment::CameraIntrinsics& k = scene.depth_camera;
  for (std::size_t i = 0; i < n; ++i) {
    const config::TargetConfig& c = scene.targets[i];
    if (!c.T_world_target && !c.T_map_target) continue;
    auto model = assets::load_model(c.model);
    assets::scale_and_recenter(model, c.scale, c.recenter);
    t.clouds[i] = std::make_unique<alignment::ModelCloud>(alignment::model_cloud_from(model, 50000));
    t.owned[i] = std::make_unique<alignment::TrackerWorker>(*t.clouds[i], k, config);
    t.workers[i] = t.owned[i].get();
    t.targets.push_back({static_cast<int>(i), t.clouds[i].get(), model.bounds().center()});
  }
  return t;
}

}  // namespace projbot::live
