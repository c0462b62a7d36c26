#pragma once
// Pose estimation on a BOP dataset's real frames (`projbot bench dataset`, issue 41): ours (the
// acquisition, or with tracking the follower as `run` uses it) beside PCL's pipeline from the same
// perturbed starts, each estimate scored by ADD / ADD-S against the dataset's ground truth.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "projbot/alignment/bop.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker_worker.hpp"

namespace projbot::bench {

/// A start's error: the truth moved `mm` in a random direction and turned `deg` about a random axis
/// through the model's centre.
struct Perturbation {
  double mm = 20.0, deg = 5.0;
};

/// One estimate, as the report's row holds it.
struct DatasetEstimate {
  std::string scene, method;     ///< method: "projbot" or "pcl"
  std::string mode = "acquire";  ///< "acquire", or "track" (followed image by image)
  int image = 0, gt_index = 0, obj_id = 0;
  Perturbation perturbation;
  Eigen::Matrix4d T_start = Eigen::Matrix4d::Identity(), T_est = Eigen::Matrix4d::Identity();
  bool accepted = false;               ///< lit: converged and through the gate and the free-space check
  double time_ms = 0.0;                ///< wall time of the estimate
  double error_mm = 0.0;               ///< ADD (ADD-S for symmetric objects) against the ground truth
  double add_mm = 0.0, adds_mm = 0.0;  ///< ADD and ADD-S whatever the shape (YCB-Video's AUCs take each for all)
  double inlier_ratio = 0.0;           ///< what the gate saw
  double rmse_mm = 0.0;                ///< likewise (may be infinite)
  double behind_ratio = 0.0, agree_ratio = 0.0, flush_ratio = 0.0;  ///< what the free-space check saw
};

/// YCB-Video's area under the accuracy-threshold curve over 0-10 cm, in percent: 100 x the mean of
/// 1 - min(e, 10 cm) / 10 cm over `errors_mm` (an infinite error, a miss, adds 0). 0 for none.
double auc_10cm(const std::vector<double>& errors_mm);

/// The benchmark over one dataset: estimators and models made when first needed and kept.
/// Not thread-safe.
class DatasetBench {
 public:
  /// `scale`: model units to metres. `stop_requested`, asked before each estimate (Ctrl-C), ends the work
  /// there; what was estimated stays in the rows.
  DatasetBench(const alignment::BopDataset& data, double scale, std::vector<Perturbation> perturbations, std::uint64_t seed,
               std::function<bool()> stop_requested = {});
  /// Every instance of one image with at least `min_visible` visible pixels, from every perturbation, by
  /// both methods (ours first): appended to `rows`.
  void image(const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible,
             std::vector<DatasetEstimate>& rows);
  /// Each object of the scene's first image started once from its perturbed truth, then followed image by
  /// image as `run` follows a target; a frame's estimate is what the renderer would show (the newest
  /// published pose unless lost).
  void track(const alignment::BopScene& scene, int min_visible, std::vector<DatasetEstimate>& rows);
  /// At most `n` instances over all calls: estimated (image) or followed from the first image (track).
  void limit_instances(int n) { instances_left_ = n; }

 private:
  struct Estimators {
    alignment::TargetFollower ours;
    alignment::Aligner pcl;
  };
  void follow(const alignment::BopScene& scene, const std::vector<alignment::DepthImage>& frames,
              const alignment::CameraIntrinsics& k, const alignment::BopModel& m, const alignment::BopInstance& start,
              std::size_t p, std::vector<DatasetEstimate>& rows);
  DatasetEstimate pcl_estimate(DatasetEstimate row, const alignment::Aligner& pcl, const alignment::DepthImage& depth,
                               const alignment::CameraIntrinsics& k, const alignment::BopModel& m,
                               const alignment::BopInstance& inst);
  const alignment::BopModel& model(int id);
  Estimators& estimators(const alignment::BopModel& m, const alignment::CameraIntrinsics& k);
  bool stopped() const { return stop_requested_ && stop_requested_(); }
  bool take_instance() { return instances_left_ > 0 ? (--instances_left_, true) : false; }

  const alignment::BopDataset& data_;
  double scale_;
  std::vector<Perturbation> perturbations_;
  std::uint64_t seed_;
  std::function<bool()> stop_requested_;
  std::map<int, alignment::BopModel> models_;
  std::map<int, std::pair<alignment::CameraIntrinsics, Estimators>> estimators_;
  int instances_left_ = std::numeric_limits<int>::max();
};

/// The report: {"instances": [one object per estimate], "interrupted": b}, written atomically. Throws
/// config::ConfigError naming the file when it cannot be written.
void write_dataset_report(const std::filesystem::path& file, const std::vector<DatasetEstimate>& rows, bool interrupted);

}  // namespace projbot::bench
