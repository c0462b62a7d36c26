// projbot align: one acquisition (ICP with quality gate and re-initialisation) of a model against a scan.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands.hpp"
#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/scan_alignment.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/rigid.hpp"
#include "projbot/config/scene.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

// --scan, with --intrinsics and --depth-scale for a depth image: a usage error for what they cannot apply to.
alignment::Scan load_scan(const cli::Args& args) {
  const std::filesystem::path scan = *args.get("scan");
  if (alignment::is_cloud_file(scan)) {
    if (args.get("intrinsics") || args.get("depth-scale"))
      throw cli::UsageError("--intrinsics and --depth-scale apply to depth images, not to " + scan.extension().string() +
                            " clouds");
    return alignment::load_scan(scan, 1.0, std::nullopt);
  }
  if (!alignment::is_depth_image_file(scan))
    throw cli::UsageError("--scan must be a .pcd or .ply cloud or a 16-bit .png / .tiff depth image, got '" + scan.string() +
                          "'");
  const double scale = args.get_double("depth-scale", 1000.0);
  if (!(scale > 0.0)) throw cli::UsageError("--depth-scale must be > 0 depth units per metre");
  std::optional<alignment::CameraIntrinsics> k;
  if (const auto text = args.get("intrinsics")) {
    const auto v = config::parse_number_list(*text, 4, "--intrinsics");
    if (!(v[0] > 0.0) || !(v[1] > 0.0)) throw cli::UsageError("--intrinsics: fx and fy must be > 0");
    k = alignment::CameraIntrinsics::kinect_v1();
    k->fx_px = v[0], k->fy_px = v[1], k->cx_px = v[2], k->cy_px = v[3];
  } else {
    std::cerr << "projbot align: no --intrinsics, using the Kinect v1 defaults (fx = fy = 525, cx = 319.5, cy = 239.5)\n";
  }
  return alignment::load_scan(scan, scale, k);
}

nlohmann::json free_space_json(const std::optional<alignment::FreeSpaceCheck>& c, double limit) {
  if (!c) return nullptr;
  return {{"predicted_px", c->predicted},      {"behind_px", c->behind},    {"in_front_px", c->in_front},
          {"behind_ratio", c->behind_ratio()}, {"max_behind_ratio", limit}, {"passed", c->passes(limit)}};
}

Eigen::Matrix4d initial_guess(const cli::Args& args) {
  const auto matrix = args.get("init-matrix");
  const auto xyz_rpy = args.get("init");
  if (matrix && xyz_rpy) throw cli::UsageError("give --init-matrix or --init, not both");
  if (matrix) {
    const auto v = config::parse_number_list(*matrix, 16, "--init-matrix");
    Eigen::Matrix4d T;
    for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    return config::orthonormalised_rigid(T, "--init-matrix");  // a dataset's float32 rotation is good to ~1e-7
  }
  if (xyz_rpy) {
    const auto v = cli::spaced_numbers(*xyz_rpy, 6, "--init \"x y z roll pitch yaw\"");
    return config::pose_from_xyz_rpy({v[0], v[1], v[2]}, {v[3], v[4], v[5]});
  }
  return Eigen::Matrix4d::Identity();
}

// How far the guess may be off (--guess-error MM,DEG): the depth image is cropped to the guess's
// silhouette grown by how far that can move a model point, and an estimate beyond it is refused.
alignment::GuessError guess_error(const cli::Args& args) {
  const auto [mm, deg] = cli::parse_distance_angle(args.get_or("guess-error", "50,15"), "guess-error", "mm", 500);
  return {mm / 1000.0, deg};
}

}  // namespace

const Command kAlign{
    "align",
    "estimate a target's pose: ICP of its model against a scan, with a quality gate",
    "projbot align --model M --scan S [--init-matrix m00,...,m33 | --init \"x y z roll pitch yaw\"] [--json]\n\n"
    "Refines the initial guess (default: identity) of T_scan_model, the transform mapping model points into\n"
    "the scan's frame, by point-to-plane ICP; when the result fails the quality gate it restarts ICP from the\n"
    "guess turned +-25 degrees about each axis, then re-initialises globally (FPFH features,\n"
    "SampleConsensusPrerejective) and tries again. M is a mesh (glTF, OBJ, STL, PLY with faces) or a\n"
    "PCD / PLY cloud; S is a PCD / PLY cloud or a 16-bit PNG / TIFF depth image (then --intrinsics and\n"
    "--depth-scale). On a depth image the acquisition is the tour's and bench dataset's: the surface the\n"
    "target rests on (a table) is found under the guess and left out, the depth is cropped to the guess's\n"
    "silhouette grown by --guess-error, and projective ICP goes first.\n"
    "A depth image is also checked for free space: the depth the model would give at the estimate against\n"
    "the depth measured inside its silhouette; where the camera sees through the model (more than 10 % of\n"
    "the silhouette), the pose is rejected however well it fits.\n"
    "Exit status: 0 when the pose passed the quality gate, 3 when it did not, 1 or 2 on bad input.\n",
    {{"model", "FILE", "target model: .gltf / .glb / .obj / .stl / .ply mesh (surface-sampled), or .pcd / .ply cloud",
      cli::PathRole::input_file},
     {"scan", "FILE", "scan: .pcd / .ply cloud, or .png / .tiff 16-bit depth image", cli::PathRole::input_file},
     {"intrinsics", "fx,fy,cx,cy", "depth camera intrinsics in pixels (default: Kinect v1)"},
     {"depth-scale", "K", "depth units per metre: 1000 for millimetres (default), 5000 for TUM"},
     {"init-matrix", "m00,...,m33", "initial T_scan_model, 16 numbers, row-major, metres"},
     {"init", "\"x y z r p y\"", "initial pose: metres and degrees, R = Rz(yaw) Ry(pitch) Rx(roll)"},
     {"no-crop", "", "use the whole scan, not only the region around the initial guess (clouds)"},
     {"guess-error", "MM,DEG",
      "how far the initial guess may be off (depth images; default 50,15): the crop, and the bound past which an estimate is "
      "refused"},
     {"model-scale", "S", "model units to metres (default 1; 0.001 for a model in millimetres, as BOP's)"},
     {"voxel", "M", "downsampling voxel size in metres (default 0.004)"},
     {"json", "", "print one JSON object instead of text"}},
    [](const cli::Args& args) {
      if (!args.get("model")) throw cli::UsageError("--model FILE is required");
      if (!args.get("scan")) throw cli::UsageError("--scan FILE is required");
      const Eigen::Matrix4d T_init = initial_guess(args);
      alignment::AcquisitionConfig cfg;
      cfg.crop = !args.flag("no-crop");
      cfg.voxel_m = args.get_double("voxel", cfg.voxel_m);
      if (!(cfg.voxel_m > 0.0) || cfg.voxel_m > 0.1) throw cli::UsageError("--voxel must be in (0, 0.1] metres");
      const double model_scale = model_scale_option(args, 1.0);
      const alignment::ModelCloud model = alignment::load_model_cloud(*args.get("model"), 50000, model_scale);
      const alignment::GuessError error = guess_error(args);
      const alignment::Scan loaded = load_scan(args);
      const alignment::PointCloud& scan = loaded.cloud;
      if (const std::size_t valid = scan.finite_count(); valid < cfg.min_points)
        throw alignment::AlignmentError(*args.get("scan") + ": " + std::to_string(valid) + " valid points; at least " +
                                        std::to_string(cfg.min_points) + " are needed");
      const alignment::ScanAlignment a = alignment::align_scan(model, loaded, T_init, error, cfg);
      if (!a.refused.empty()) std::cerr << "projbot align: " << a.refused << "\n";
      const alignment::AlignmentResult& r = a.result;
      const std::optional<alignment::FreeSpaceCheck>& free_space = a.free_space;
      const double limit = a.max_behind_ratio;
      const bool accepted = a.accepted;
      if (args.flag("json")) {
        nlohmann::json T = nlohmann::json::array();
        for (int i = 0; i < 4; ++i)
          T.push_back({r.T_scan_model(i, 0), r.T_scan_model(i, 1), r.T_scan_model(i, 2), r.T_scan_model(i, 3)});
        const nlohmann::json out = {{"T", T},
                                    {"converged", r.converged},
                                    {"inlier_ratio", r.inlier_ratio},
                                    {"rmse_mm", std::isfinite(r.rmse_mm) ? nlohmann::json(r.rmse_mm) : nlohmann::json(nullptr)},
                                    {"iterations", r.iterations},
                                    {"time_ms", r.time_ms},
                                    {"reinitialised", r.reinitialised},
                                    {"neutral_ratio", r.neutral_ratio},
                                    {"stands", r.stands},
                                    {"support_height_mm", r.footing_height_error_mm},
                                    {"scan_valid_points", scan.finite_count()},
                                    {"scan_points_used", r.scan_points},
                                    {"free_space", free_space_json(free_space, limit)},
                                    {"accepted", accepted}};
        std::cout << out.dump() << '\n';
      } else {
        std::cout << "T_scan_model (row-major, metres):\n";
        for (int i = 0; i < 4; ++i)
          std::printf("  % .6f % .6f % .6f % .6f\n", r.T_scan_model(i, 0), r.T_scan_model(i, 1), r.T_scan_model(i, 2),
                      r.T_scan_model(i, 3));
        std::printf("%s: inlier ratio %.3f, rmse %.2f mm, %d iterations, %.1f ms%s\n",
                    r.converged ? "converged" : "NOT converged", r.inlier_ratio, r.rmse_mm, r.iterations, r.time_ms,
                    r.reinitialised ? " (after global re-initialisation)" : "");
        if (free_space && free_space->predicted < alignment::FreeSpaceCheck::kMinPredicted)
          std::printf("free space: the model at the estimate covers %zu pixels of the image, too few to check: REJECTED\n",
                      free_space->predicted);
        else if (free_space)
          std::printf("free space: the camera sees through the model at %zu of %zu silhouette pixels (%.3f, limit %.2f): %s\n",
                      free_space->behind, free_space->predicted, free_space->behind_ratio(), limit,
                      free_space->behind_ratio() <= limit ? "passed" : "REJECTED, the model is not where it fits");
      }
      return accepted ? 0 : 3;
    }};

}  // namespace projbot::tools
