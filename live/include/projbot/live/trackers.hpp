#pragma once
// The tracked targets of a scene: each target with a world or map pose, its model as the estimator knows
// it and a tracker worker for it. The same for a live run, a recording and its replay, so that the same
// frames give the same poses.

#include <memory>
#include <vector>

#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/live/stop_sequence.hpp"

namespace projbot::live {

/// Every tracked target's model cloud and worker, by scene index (null: not tracked).
struct SceneTrackers {
  std::vector<std::unique_ptr<alignment::ModelCloud>> clouds;    ///< by scene index; null: not tracked
  std::vector<std::unique_ptr<alignment::TrackerWorker>> owned;  ///< by scene index
  std::vector<alignment::PoseTracker*> workers;                  ///< by scene index, for StopSequence::visit
  std::vector<Target> targets;                                   ///< for the session
};
/// The trackers' configuration: prediction on or off. In lockstep (record, replay) a search is bounded by
/// its work instead of wall time, so the same frames take the same steps however fast the machine is.
alignment::WorkerConfig worker_config(bool predict, bool lockstep);
/// Loads every target with a world or map pose (its model scaled and recentred, 50k surface samples).
/// Throws assets::AssetError naming a model that cannot be read.
SceneTrackers make_trackers(const config::Scene& scene, const alignment::WorkerConfig& config);

}  // namespace projbot::live
