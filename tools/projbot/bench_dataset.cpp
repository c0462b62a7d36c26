// projbot bench dataset DIR: pose estimation on the real frames of a BOP dataset (issue 41), ours beside
// PCL's pipeline from the same perturbed starts, scored by ADD / ADD-S against the dataset's ground truth.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/alignment/bop.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/pose_error.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

namespace fs = std::filesystem;

struct Perturbation {
  double mm = 20.0, deg = 5.0;
};

using ObjectModel = alignment::BopModel;  // points for estimation, vertices for scoring

// One estimate, as the report's row holds it.
struct Row {
  std::string scene, method, mode = "acquire";
  int image = 0, gt_index = 0, obj_id = 0;
  Perturbation perturbation;
  Eigen::Matrix4d T_start = Eigen::Matrix4d::Identity(), T_est = Eigen::Matrix4d::Identity();
  bool accepted = false;
  double time_ms = 0.0, error_mm = 0.0;
  double inlier_ratio = 0.0, rmse_mm = 0.0, behind_ratio = 0.0, agree_ratio = 0.0;  // what the gate and the free-space check saw
  double flush_ratio = 0.0;
};

Row row_for(const std::string& scene, const char* mode, int image, int gt_index, int obj_id, const Perturbation& p) {
  Row r;
  r.scene = scene, r.method = "projbot", r.mode = mode;
  r.image = image, r.gt_index = gt_index, r.obj_id = obj_id, r.perturbation = p;
  return r;
}

std::vector<Perturbation> parse_perturbations(const std::vector<std::string>& texts) {
  std::vector<Perturbation> out;
  for (const std::string& t : texts) {
    const auto [mm, deg] = cli::parse_distance_angle(t, "perturb", "mm", 500);
    out.push_back({mm, deg});
  }
  if (out.empty()) out.push_back(Perturbation{});
  return out;
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
  const Eigen::Matrix3d R = Eigen::AngleAxisd(p.deg * M_PI / 180.0, axis).toRotationMatrix();
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

double error_mm(const ObjectModel& m, const Eigen::Matrix4d& T_est, const Eigen::Matrix4d& T_true) {
  return 1000.0 * (m.info->symmetric ? alignment::adds_error_m(m.vertices, T_est, T_true)
                                     : alignment::add_error_m(m.vertices, T_est, T_true));
}

bool same_camera(const alignment::CameraIntrinsics& a, const alignment::CameraIntrinsics& b) {
  return a.fx_px == b.fx_px && a.fy_px == b.fy_px && a.cx_px == b.cx_px && a.cy_px == b.cy_px && a.width_px == b.width_px &&
         a.height_px == b.height_px;
}

template <typename F>
double timed_ms(F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The starts' error is known (the perturbation): an estimate beyond it is something else that fits
// (as a GuessError given to acquire() says without --track).
alignment::WorkerConfig bounded_guess() {
  alignment::WorkerConfig c;
  c.guess_bounds_estimate = true;
  return c;
}

// The estimators of one object for one camera, made when first needed.
struct Estimators {
  alignment::TargetFollower ours;
  alignment::Aligner pcl;
};

class Bench {
 public:
  Bench(const alignment::BopDataset& data, double scale, std::vector<Perturbation> perturbations, std::uint64_t seed)
      : data_(data), scale_(scale), perturbations_(std::move(perturbations)), seed_(seed) {}

  // Every instance of one image with enough visible pixels, from every perturbation, both methods.
  void image(const alignment::BopScene& scene, const alignment::BopImage& image, int min_visible, std::vector<Row>& rows) {
    const alignment::DepthImage depth = alignment::read_bop_depth(image);
    alignment::CameraIntrinsics k = image.k;
    k.width_px = depth.width, k.height_px = depth.height;
    for (const alignment::BopInstance& inst : image.instances) {
      if (inst.visible_px >= 0 && inst.visible_px < min_visible) continue;
      const ObjectModel& m = model(inst.obj_id);
      Estimators& e = estimators(m, k);
      for (std::size_t p = 0; p < perturbations_.size() && !interrupted(); ++p) {
        Row row = row_for(scene.name, "acquire", image.id, inst.gt_index, inst.obj_id, perturbations_[p]);
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
        row.inlier_ratio = r.inlier_ratio, row.rmse_mm = r.rmse_mm;
        row.T_est = r.T_scan_model;
        row.error_mm = error_mm(m, row.T_est, inst.T_camera_model);
        rows.push_back(row);
        rows.push_back(pcl_row(row, e.pcl, depth, k, m, inst));
      }
    }
  }

  // --track: each object of the scene's first image started once from its perturbed truth, then followed
  // image by image as `run` follows a target (TargetFollower::step: track, refine, search when lost). A
  // frame's estimate is what the renderer would show: the newest published pose unless it was lost.
  void track(const alignment::BopScene& scene, int min_visible, std::vector<Row>& rows) {
    std::vector<alignment::DepthImage> frames;
    for (const auto& image : scene.images) {
      frames.push_back(alignment::read_bop_depth(image));
      frames.back().capture_time_s = static_cast<double>(image.id) / kFrameHz;
    }
    alignment::CameraIntrinsics k = scene.images.front().k;
    k.width_px = frames.front().width, k.height_px = frames.front().height;
    for (const alignment::BopInstance& start : scene.images.front().instances) {
      if (start.visible_px >= 0 && start.visible_px < min_visible) continue;
      const ObjectModel& m = model(start.obj_id);
      for (std::size_t p = 0; p < perturbations_.size() && !interrupted(); ++p) follow(scene, frames, k, m, start, p, rows);
    }
  }

 private:
  static constexpr double kFrameHz = 30.0;  // YCB-Video's frame rate

  void follow(const alignment::BopScene& scene, const std::vector<alignment::DepthImage>& frames,
              const alignment::CameraIntrinsics& k, const ObjectModel& m, const alignment::BopInstance& start, std::size_t p,
              std::vector<Row>& rows) {
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
    for (std::size_t f = 0; f < frames.size() && !interrupted(); ++f) {
      Row row = row_for(scene.name, "track", scene.images[f].id, -1, m.info->id, perturbations_[p]);
      row.T_start = T_start;
      row.time_ms = timed_ms([&] {
        if (auto s = follower.step(frames[f])) shown = s;
      });
      row.accepted = shown && !shown->lost;
      row.T_est = shown ? shown->T_camera_target : follower.last_pose();
      for (const alignment::BopInstance& inst : scene.images[f].instances)
        if (inst.obj_id == m.info->id) {
          row.gt_index = inst.gt_index;
          row.error_mm = error_mm(m, row.T_est, inst.T_camera_model);
        }
      if (row.gt_index >= 0) rows.push_back(row);
    }
  }

  Row pcl_row(Row row, const alignment::Aligner& pcl, const alignment::DepthImage& depth, const alignment::CameraIntrinsics& k,
              const ObjectModel& m, const alignment::BopInstance& inst) {
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
    row.error_mm = error_mm(m, row.T_est, inst.T_camera_model);
    return row;
  }

  const ObjectModel& model(int id) {
    auto it = models_.find(id);
    if (it == models_.end()) it = models_.emplace(id, alignment::load_bop_model(*data_.object(id), scale_)).first;
    return it->second;
  }

  Estimators& estimators(const ObjectModel& m, const alignment::CameraIntrinsics& k) {
    auto it = estimators_.find(m.info->id);
    if (it != estimators_.end() && !same_camera(it->second.first, k)) estimators_.erase(it), it = estimators_.end();
    if (it == estimators_.end())
      it = estimators_
               .emplace(m.info->id,
                        std::make_pair(k, Estimators{alignment::TargetFollower(m.cloud, k, alignment::WorkerConfig{}),
                                                     alignment::Aligner(m.cloud, alignment::pcl_pipeline_config(true))}))
               .first;
    return it->second.second;
  }

  const alignment::BopDataset& data_;
  double scale_;
  std::vector<Perturbation> perturbations_;
  std::uint64_t seed_;
  std::map<int, ObjectModel> models_;
  std::map<int, std::pair<alignment::CameraIntrinsics, Estimators>> estimators_;
};

struct Tally {
  int n = 0, within5 = 0, within10 = 0, false_accepts = 0, false_rejects = 0;
  std::vector<double> ms;
  void add(const Row& r) {
    ++n;
    within5 += r.accepted && r.error_mm <= 5.0 ? 1 : 0;
    within10 += r.accepted && r.error_mm <= 10.0 ? 1 : 0;
    false_accepts += r.accepted && r.error_mm > 20.0 ? 1 : 0;
    false_rejects += !r.accepted && r.error_mm <= 10.0 ? 1 : 0;
    ms.push_back(r.time_ms);
  }
  void print(const std::string& what, const Perturbation& p, const std::string& method) const {
    const auto pct = [&](int k) { return n > 0 ? 100.0 * k / n : 0.0; };
    std::printf("| %s | %.0f mm, %.0f deg | %s | %d | %.1f %% | %.1f %% | %d | %d (%.1f %%) | %.0f / %.0f / %.0f |\n",
                what.c_str(), p.mm, p.deg, method.c_str(), n, pct(within5), pct(within10), false_accepts, false_rejects,
                pct(false_rejects), engine::percentile(ms, 0.5), engine::percentile(ms, 0.95), engine::percentile(ms, 1.0));
  }
};

void print_tables(const std::vector<Row>& rows, const std::vector<Perturbation>& perturbations,
                  const std::vector<std::string>& methods) {
  std::printf(
      "| object | start | method | estimates | lit within 5 mm | lit within 10 mm | false accepts (> 20 mm) | false rejects "
      "(<= 10 mm) | time median / p95 / max ms |\n|---|---|---|---|---|---|---|---|---|\n");
  std::set<int> ids;
  for (const Row& r : rows) ids.insert(r.obj_id);
  for (const Perturbation& p : perturbations)
    for (const std::string& method : methods) {
      Tally all;
      for (const int id : ids) {
        Tally t;
        for (const Row& r : rows)
          if (r.obj_id == id && r.method == method && r.perturbation.mm == p.mm && r.perturbation.deg == p.deg)
            t.add(r), all.add(r);
        if (t.n > 0) t.print("obj " + std::to_string(id), p, method);
      }
      all.print("all", p, method);
    }
}

nlohmann::json matrix_json(const Eigen::Matrix4d& T) {
  nlohmann::json out = nlohmann::json::array();
  for (int i = 0; i < 16; ++i) out.push_back(T(i / 4, i % 4));
  return out;
}

void write_report(const fs::path& file, const std::vector<Row>& rows, bool interrupted_run) {
  nlohmann::json out = {{"instances", nlohmann::json::array()}, {"interrupted", interrupted_run}};
  for (const Row& r : rows)
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
                                {"inlier_ratio", r.inlier_ratio},
                                {"rmse_mm", std::isfinite(r.rmse_mm) ? nlohmann::json(r.rmse_mm) : nlohmann::json(nullptr)},
                                {"behind_ratio", r.behind_ratio},
                                {"agree_ratio", r.agree_ratio},
                                {"flush_ratio", r.flush_ratio},
                                {"time_ms", r.time_ms}});
  config::write_file_atomically(file, out.dump(1) + "\n");
}

// --report may not name a file inside the dataset it reads.
void check_report_apart(const cli::Args& args, const fs::path& dir) {
  const auto report = args.get("report");
  if (!report) return;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(*report), ec), in = fs::weakly_canonical(fs::absolute(dir), ec);
  const auto rel = out.lexically_relative(in);
  if (!rel.empty() && *rel.begin() != "..")
    throw cli::UsageError("--report " + *report + " lies inside the dataset " + dir.string() + " (an input): write it elsewhere");
}

int run_bench_dataset(const cli::Args& args) {
  if (args.positional().size() != 1) throw cli::UsageError("give the BOP dataset's folder: projbot bench dataset DIR");
  const fs::path dir = args.positional().front();
  const auto perturbations = parse_perturbations(args.get_all("perturb"));
  const int min_visible = args.get_int("min-visible", 1500, 0, 100000000);
  const auto seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  const int max_instances = args.get_int("max-instances", 1 << 30, 1, 1 << 30);
  const double scale = model_scale_option(args, 0.001);
  check_report_apart(args, dir);
  const alignment::BopDataset data = alignment::read_bop_dataset(dir, args.get_list("scenes"));
  catch_interrupts();
  Bench bench(data, scale, perturbations, seed);
  std::vector<Row> rows;
  int instances = 0, total = 0;
  for (const auto& s : data.scenes)
    for (const auto& im : s.images)
      for (const auto& inst : im.instances) total += inst.visible_px < 0 || inst.visible_px >= min_visible ? 1 : 0;
  total = std::min(total, max_instances);
  if (args.flag("track")) {
    Progress progress("scene", static_cast<int>(data.scenes.size()));
    int done = 0;
    for (const auto& scene : data.scenes) {
      if (interrupted()) break;
      bench.track(scene, min_visible, rows);
      progress.step(++done);
    }
    print_tables(rows, perturbations, {"projbot"});
    if (const auto report = args.get("report")) write_report(*report, rows, interrupted());
    if (interrupted()) return benchmark_interrupted("after " + std::to_string(done) + " scenes");
    return 0;
  }
  Progress progress("instance", total);
  for (const auto& scene : data.scenes)
    for (const auto& image : scene.images) {
      if (interrupted() || instances >= max_instances) break;
      const std::size_t before = rows.size();
      bench.image(scene, image, min_visible, rows);
      instances += static_cast<int>((rows.size() - before) / (2 * perturbations.size()));
      progress.step(std::min(instances, total));
    }
  print_tables(rows, perturbations, {"projbot", "pcl"});
  if (const auto report = args.get("report")) write_report(*report, rows, interrupted());
  if (interrupted()) return benchmark_interrupted("after " + std::to_string(instances) + " instances");
  return 0;
}

}  // namespace

const Command kBenchDataset{
    "bench dataset",
    "pose estimation on a BOP dataset's real frames, ours beside PCL's pipeline",
    "projbot bench dataset DIR [--perturb MM,DEG]... [--seed K] [--min-visible PX] [--scenes A,B] [--max-instances N]\n"
    "                          [--model-scale S] [--track] [--report FILE.json]\n\n"
    "DIR is a BOP dataset (models/ with models_info.json, test/SCENE/ with depth/, mask_visib/,\n"
    "scene_camera.json, scene_gt.json, scene_gt_info.json). Each object instance with at least PX visible pixels\n"
    "is estimated from its ground truth moved MM in a random direction and turned DEG about a random axis through\n"
    "the model's centre (seeded per instance and perturbation), by ours (the acquisition `align`, the tour and\n"
    "the tracker run: the support under the start found in the frame and left out, the depth cropped to the\n"
    "start's silhouette, projective and point-to-plane ICP, the quality gate and the free-space check; from a\n"
    "start off by more than half the model's size, poses around it scored against the depth first and the best\n"
    "three acquired in turn) and by PCL's pipeline from the same start (crop around the start, normals, ICP; lit\n"
    "whenever it converges). Error: ADD, the mean distance of the model's vertices under the estimate and under\n"
    "the truth; ADD-S (to the nearest vertex) for symmetric shapes (models_info.json's symmetries; for YCB-V\n"
    "without them, ids 1 4 6 13 16 18 19 20 21). Per object and overall: lit within 5 and 10 mm, false accepts\n"
    "(lit, more than 20 mm off), false rejects (blank, within 10 mm), time. The ground truth itself agrees with\n"
    "real depth to about 2 mm: within 3 mm is as good as the data can tell. With --track, each object of a\n"
    "scene's first image is started once from its perturbed truth and followed through the scene's images in\n"
    "order by the tracker as `run` uses it (track, refine, search when lost); each image's row is the pose the\n"
    "renderer would show then (blank when lost). Ctrl-C prints and reports the estimates done (\"interrupted\":\n"
    "true).\n",
    {{"perturb", "MM,DEG", "the start's error; repeat for several (default 20,5)"},
     {"seed", "K", "seed of the starts (default 1)"},
     {"min-visible", "PX", "skip instances with fewer visible pixels (default 1500)"},
     {"scenes", "A,B", "only these scene folders (default: all of test/)"},
     {"max-instances", "N", "stop after N instances (default: all)"},
     {"model-scale", "S", "model units to metres (default 0.001: BOP's millimetres)"},
     {"track", "", "follow each scene's objects frame by frame from one perturbed start on its first image"},
     {"report", "FILE", "JSON report, one row per estimate", cli::PathRole::output_file}},
    run_bench_dataset};

}  // namespace projbot::tools
