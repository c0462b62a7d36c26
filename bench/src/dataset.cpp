#include "projbot/bench/dataset.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/pose_error.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::bench {
namespace {

constexpr double kFrameHz = 30.0;  // YCB-Video's frame rate

DatasetEstimate row_for(const std::string& scene, const char* mode, int image, int gt_index, int obj_id, const Perturbation& p) {
  DatasetEstimate r;
  r.scene = scene, r.method = "projbot", r.mode = mode;
  r.image = image, r.gt_index = gt_index, r.obj_id = obj_id, r.perturbation = p;
  return r;
}

// The truth moved `mm` in a random direction and turned `deg` about a random axis through the model's
// centre; the generator is seeded per instance and perturbation, so a start does not depend on which
// scenes or which other perturbations run (`--perturb 50,15` alone gives the starts it gives beside 20,5).
Eigen::Matrix4d perturbed(const Eigen::Matrix4d& T, const Eigen::Vector3d& centre_model, const Perturbation& p,
                          std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
  const Eigen::Vector3d shift = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * p.mm / 1000.0;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(config::radians(p.deg), axis).toRotationMatrix();
  const Eigen::Vector3d c = (T * centre_model.homogeneous()).head<3>();
  Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
  turn.topLeftCorner<3, 3>() = R;
  turn.topRightCorner<3, 1>() = c - R * c + shift;
  return turn * T;
}

std::uint32_t start_seed(std::uint64_t seed, const std::string& scene, int image, int gt_index, const Perturbation& p) {
  const std::size_t h = std::hash<std::string>{}(scene + "/" + std::to_string(image) + "/" + std::to_string(gt_index) + "/" +
                                                 std::to_string(p.mm) + "," + std::to_string(p.deg) + "/" + std::to_string(seed));
  return static_cast<std::uint32_t>(h ^ (h >> 32));
}

// The row's estimate against the truth: ADD and ADD-S both (for the AUCs), and the one its shape calls for.
void score(DatasetEstimate& row, const alignment::BopModel& m, const Eigen::Matrix4d& T_true) {
  row.add_mm = 1000.0 * alignment::add_error_m(m.vertices, row.T_est, T_true);
  row.adds_mm = 1000.0 * alignment::adds_error_m(m.vertices, row.T_est, T_true);
  row.error_mm = m.info->symmetric ? row.adds_mm : row.add_mm;
}

bool same_camera(const alignment::CameraIntrinsics& a, const alignment::CameraIntrinsics& b) {
  return a.fx_px == b.fx_px && a.fy_px == b.fy_px && a.cx_px == b.cx_px && a.cy_px == b.cy_px && a.width_px == b.width_px &&
         a.height_px == b.height_px;
}

template <typename F>
double timed_ms(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return config::ms_since(t0);
}

// The starts' error is known (the perturbation): an estimate beyond it is something else that fits
// (as a GuessError given to acquire() says without --track).
alignment::WorkerConfig bounded_guess() {
  alignment::WorkerConfig c;
  c.guess_bounds_estimate = true;
  return c;
}

nlohmann::json matrix_json(const Eigen::Matrix4d& T) {
  nlohmann::json out = nlohmann::json::array();
  for (int i = 0; i < 16; ++i) out.push_back(T(i / 4, i % 4));
  return out;
}

}  // namespace

DatasetBench::DatasetBench(const alignment::BopDataset& data, double scale, std::vector<Perturbation> perturbations,
                           std::uint64_t seed, std::function<bool()> stop_requested)
    : data_(data),
      scale_(scale),
      perturbations_(std::move(perturbations)),
      seed_(seed),
      stop_requested_(std::move(stop_requested)) {}

void DatasetBench::image(const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible,
                         std::vector<DatasetEstimate>& rows) {
  const alignment::DepthImage depth = alignment::read_bop_depth(image);
  alignment::CameraIntrinsics k = image.k;
  k.width_px = depth.width, k.height_px = depth.height;
  for (const alignment::BopInstance& inst : image.instances) {
    if (inst.visible_px >= 0 && inst.visible_px < min_visible) continue;
    if (!take_instance()) return;
    const alignment::BopModel& m = model(inst.obj_id);
    Estimators& e = estimators(m, k);
    for (std::size_t p = 0; p < perturbations_.size() && !stopped(); ++p) {
      DatasetEstimate row = row_for(scene.name, "acquire", image.id, inst.gt_index, inst.obj_id, perturbations_[p]);
      row.T_start = perturbed(inst.T_camera_model, m.centre, perturbations_[p],
                              start_seed(seed_, scene.name, image.id, inst.gt_index, perturbations_[p]));
      alignment::AlignmentResult r;
      row.time_ms = timed_ms([&] {
        try {
          r = e.ours.acquire(depth, row.T_start, alignment::GuessError{perturbations_[p].mm / 1000.0, perturbations_[p].deg});
        } catch (const alignment::AlignmentError&) {  // too little depth left near the start: blank
          r.T_scan_model = row.T_start;
        }
        const alignment::FreeSpaceCheck check = e.ours.verify(depth, r.T_scan_model, true);
        row.accepted = r.converged && e.ours.passes(check);
        row.behind_ratio = check.behind_ratio();
        row.agree_ratio = check.agree_ratio();
        row.flush_ratio = check.flush_ratio();
      });
      if (stopped()) return;  // the estimate a stop cut short says nothing: dropped, as the rest not made
      row.inlier_ratio = r.inlier_ratio, row.rmse_mm = r.rmse_mm;
      row.T_est = r.T_scan_model;
      score(row, m, inst.T_camera_model);
      rows.push_back(row);
      rows.push_back(pcl_estimate(row, e.pcl, depth, k, m, inst));
    }
  }
}

void DatasetBench::track(const alignment::BopScene& scene, int min_visible, std::vector<DatasetEstimate>& rows) {
  std::vector<alignment::DepthImage> frames;
  for (const auto& image : scene.images) {
    frames.push_back(alignment::read_bop_depth(image));
    alignment::check_same_size(image, frames.back(), scene.images.front().depth, frames.front());
    frames.back().capture_time_s = static_cast<double>(image.id) / kFrameHz;
  }
  alignment::CameraIntrinsics k = scene.images.front().k;
  k.width_px = frames.front().width, k.height_px = frames.front().height;
  for (const alignment::BopInstance& start : scene.images.front().instances) {
    if (start.visible_px >= 0 && start.visible_px < min_visible) continue;
    if (!take_instance()) return;
    const alignment::BopModel& m = model(start.obj_id);
    for (std::size_t p = 0; p < perturbations_.size() && !stopped(); ++p) follow(scene, frames, k, m, start, p, rows);
  }
}

void DatasetBench::follow(const alignment::BopScene& scene, const std::vector<alignment::DepthImage>& frames,
                          const alignment::CameraIntrinsics& k, const alignment::BopModel& m, const alignment::BopInstance& start,
                          std::size_t p, std::vector<DatasetEstimate>& rows) {
  // The follower knows how far its guess may be off, as the acquisition without --track is told.
  alignment::WorkerConfig config = bounded_guess();
  config.guess_uncertainty_m = perturbations_[p].mm / 1000.0;
  config.guess_uncertainty_deg = perturbations_[p].deg;
  alignment::TargetFollower follower(m.cloud, k, config);
  const Eigen::Matrix4d T_start =
      perturbed(start.T_camera_model, m.centre, perturbations_[p],
                start_seed(seed_, scene.name, scene.images.front().id, start.gt_index, perturbations_[p]));
  follower.set_initial_guess(T_start);
  std::optional<alignment::PoseSample> shown;
  for (std::size_t f = 0; f < frames.size() && !stopped(); ++f) {
    DatasetEstimate row = row_for(scene.name, "track", scene.images[f].id, -1, m.info->id, perturbations_[p]);
    row.T_start = T_start;
    row.time_ms = timed_ms([&] {
      if (auto s = follower.step(frames[f])) shown = s;
    });
    if (stopped()) break;  // a frame a stop cut short: dropped
    row.accepted = shown && !shown->lost;
    row.T_est = shown ? shown->T_camera_target : follower.last_pose();
    if (shown) row.inlier_ratio = shown->inlier_ratio, row.rmse_mm = shown->rmse_mm;
    // The checks of the pose shown, as the acquisition's rows give them (outside the timing: tracking
    // itself does not judge the outline).
    const alignment::FreeSpaceCheck check = follower.verify(frames[f], row.T_est, true);
    row.behind_ratio = check.behind_ratio(), row.agree_ratio = check.agree_ratio(), row.flush_ratio = check.flush_ratio();
    for (const alignment::BopInstance& inst : scene.images[f].instances)
      if (inst.obj_id == m.info->id) {
        row.gt_index = inst.gt_index;
        score(row, m, inst.T_camera_model);
      }
    if (row.gt_index >= 0) rows.push_back(row);
  }
}

DatasetEstimate DatasetBench::pcl_estimate(DatasetEstimate row, const alignment::Aligner& pcl, const alignment::DepthImage& depth,
                                           const alignment::CameraIntrinsics& k, const alignment::BopModel& m,
                                           const alignment::BopInstance& inst) {
  row.method = "pcl";
  alignment::AlignmentResult r;
  row.time_ms = timed_ms([&] {
    try {
      r = pcl.align(alignment::depth_to_cloud(depth, k), row.T_start, alignment::SearchStage::icp_only);
    } catch (const alignment::AlignmentError&) {
      r.T_scan_model = row.T_start;
    }
  });
  row.accepted = r.converged;
  row.T_est = r.T_scan_model;
  score(row, m, inst.T_camera_model);
  return row;
}

const alignment::BopModel& DatasetBench::model(int id) {
  auto it = models_.find(id);
  if (it == models_.end()) it = models_.emplace(id, alignment::load_bop_model(*data_.object(id), scale_)).first;
  return it->second;
}

DatasetBench::Estimators& DatasetBench::estimators(const alignment::BopModel& m, const alignment::CameraIntrinsics& k) {
  auto it = estimators_.find(m.info->id);
  if (it != estimators_.end() && !same_camera(it->second.first, k)) estimators_.erase(it), it = estimators_.end();
  if (it == estimators_.end())
    it =
        estimators_
            .emplace(m.info->id, std::make_pair(k, Estimators{alignment::TargetFollower(m.cloud, k, alignment::WorkerConfig{}),
                                                              alignment::Aligner(m.cloud, alignment::pcl_pipeline_config(true))}))
            .first;
  return it->second.second;
}

double auc_10cm(const std::vector<double>& errors_mm) {
  if (errors_mm.empty()) return 0.0;
  double sum = 0.0;
  for (const double e : errors_mm) sum += 1.0 - std::min(e, 100.0) / 100.0;  // the integral of [e < t] over t in 0..10 cm
  return 100.0 * sum / static_cast<double>(errors_mm.size());
}

void write_dataset_report(const std::filesystem::path& file, const std::vector<DatasetEstimate>& rows, bool interrupted_run) {
  nlohmann::json out = {{"instances", nlohmann::json::array()}, {"interrupted", interrupted_run}};
  for (const DatasetEstimate& r : rows)
    out["instances"].push_back({{"scene", r.scene},
                                {"image", r.image},
                                {"gt_index", r.gt_index},
                                {"obj_id", r.obj_id},
                                {"method", r.method},
                                {"mode", r.mode},
                                {"perturbation", {r.perturbation.mm, r.perturbation.deg}},
                                {"T_start", matrix_json(r.T_start)},
                                {"T_est", matrix_json(r.T_est)},
                                {"accepted", r.accepted},
                                {"error_mm", r.error_mm},
                                {"add_mm", r.add_mm},
                                {"adds_mm", r.adds_mm},
                                {"inlier_ratio", r.inlier_ratio},
                                {"rmse_mm", std::isfinite(r.rmse_mm) ? nlohmann::json(r.rmse_mm) : nlohmann::json(nullptr)},
                                {"behind_ratio", r.behind_ratio},
                                {"agree_ratio", r.agree_ratio},
                                {"flush_ratio", r.flush_ratio},
                                {"time_ms", r.time_ms}});
  config::write_file_atomically(file, out.dump(1) + "\n");
}

}  // namespace projbot::bench
