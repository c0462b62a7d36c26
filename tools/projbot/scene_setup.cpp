#include "scene_setup.hpp"

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <set>
#include <thread>

#include "projbot/assets/model.hpp"
#include "projbot/assets/video.hpp"
#include "projbot/robot/localization.hpp"

namespace projbot::tools {

std::vector<cli::OptionSpec> with_scene_options(std::vector<cli::OptionSpec> own) {
  own.insert(own.end(),
             {
                 {"scene", "FILE", "scene YAML (default: the shipped demo scene)", cli::PathRole::input_file},
                 {"model", "FILE", "glTF model for the scene's single target (without --scene: framed in view)",
                  cli::PathRole::input_file},
                 {"size", "WxH", "projector image size in pixels, e.g. 1920x1080"},
                 {"intrinsics", "fx,fy,cx,cy", "projector intrinsics in pixels (OpenCV pinhole)"},
                 {"near", "M", "near clipping distance, metres"},
                 {"far", "M", "far clipping distance, metres"},
                 {"pose-matrix", "m00,...,m33", "T_projector_target of the single target: 16 numbers, row-major, metres"},
                 {"device", "N", "Vulkan physical device index (default: best available)"},
                 {"validation", "", "enable the Vulkan validation layer and report its messages"},
             });
  return own;
}

std::filesystem::path asset_dir() {
  if (const char* env = std::getenv("PROJBOT_ASSETS"); env != nullptr && *env != '\0') return env;
  return PROJBOT_ASSET_DIR;
}

void check_content_videos(const config::Scene& scene) {
  std::set<std::filesystem::path> opened;
  for (const auto& t : scene.targets)
    if (t.content && !t.content->video.empty() && opened.insert(t.content->video).second)
      assets::VideoDecoder probe(t.content->video);
}

TourFamilyArgs tour_family_args(const cli::Args& args, double default_dwell_s, int default_visits) {
  TourFamilyArgs t;
  t.visits = args.get_int("visits", default_visits, 1, 1000);
  t.dwell_s = args.get_double("dwell", default_dwell_s);
  if (!(t.dwell_s >= 0.1 && t.dwell_s <= 3600.0)) throw cli::UsageError("--dwell must be 0.1..3600 seconds");
  t.seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  t.depth_model = args.get_or("depth-model", "fitted");
  t.depth_noise = depth_model_named(t.depth_model);
  if (args.get("processing-ms")) {
    t.processing_ms = args.get_double("processing-ms", 0.0);
    if (!(*t.processing_ms >= 0.0 && *t.processing_ms <= 1000.0)) throw cli::UsageError("--processing-ms must be 0..1000");
  }
  return t;
}

cli::OptionSpec processing_ms_option() {
  return {"processing-ms", "MS",
          "a pose is ready this long after its capture (default: as measured on this machine); fixed, the figures do "
          "not depend on the machine's load"};
}

cli::OptionSpec depth_model_option() {
  return {"depth-model", "M",
          "the twin's depth camera: fitted (to the real sensor's frames, default) or kinect (the published model)"};
}

alignment::KinectNoiseConfig depth_model_named(const std::string& name, const std::string& option) {
  if (name == "fitted") return alignment::KinectNoiseConfig::fitted();
  if (name == "kinect") return {};
  throw cli::UsageError(option + " must be kinect or fitted, not '" + name + "'");
}

void check_made_video(const config::Scene& scene) {
  for (const auto& t : scene.targets)
    if (t.content && !t.content->video.empty() && !std::filesystem::exists(t.content->video))
      throw config::ConfigError(t.content->video.string() +
                                ": does not exist; the build makes it, into " PROJBOT_GENERATED_ASSET_DIR
                                "/videos (cmake --build --preset release --target projbot_sample_video)");
}

void note_twin_on_odometry(std::ostream& out) {
  if (!robot::built_with_mrpt())
    out << "note: this portable build has no MRPT: the twin's robot closes its loop on odometry alone\n";
}

double model_scale_option(const cli::Args& args, double fallback) {
  const double scale = args.get_double("model-scale", fallback);
  if (!(scale >= 1e-6 && scale <= 1e6)) throw cli::UsageError("--model-scale must be in [1e-6, 1e6]");
  return scale;
}

Eigen::Matrix4d framing_pose(const config::ProjectorConfig& p, double radius_m) {
  const double half_fov = std::atan(std::min(p.width_px / (2.0 * p.fx_px), p.height_px / (2.0 * p.fy_px)));
  const double distance = radius_m / std::sin(half_fov * 0.8);
  Eigen::Matrix4d T = config::pose_from_xyz_rpy({0.0, 0.0, distance}, {180.0, 0.0, 0.0});
  // Aim at the principal point's ray for the image centre.
  T.block<2, 1>(0, 3) = p.back_project((p.width_px - 1) / 2.0, (p.height_px - 1) / 2.0, distance).head<2>();
  return T;
}

namespace {

void add_model_inputs(const std::filesystem::path& model, const std::string& whose, std::vector<config::NamedPath>& out) {
  if (model.empty()) return;
  const auto files = assets::model_files(model);
  out.push_back({"the model of " + whose, files.front(), false});
  for (std::size_t i = 1; i < files.size(); ++i) out.push_back({"part of the model of " + whose, files[i], false});
}

}  // namespace

std::vector<config::NamedPath> scene_inputs(const config::Scene& scene, const std::string& scene_name) {
  std::vector<config::NamedPath> out;
  if (!scene.source.empty()) out.push_back({scene_name, scene.source, false});
  if (!scene.calibration.empty()) out.push_back({"the calibration of " + scene_name, scene.calibration, false});
  if (scene.console && !scene.console->token_file.empty())
    out.push_back({"the console's token file of " + scene_name, scene.console->token_file, false});
  for (const auto& t : scene.targets) {
    const std::string whose = "target '" + t.name + "'";
    add_model_inputs(t.model, whose, out);
    if (!t.surface.texture.empty()) out.push_back({"the surface texture of " + whose, t.surface.texture, false});
    if (t.content && !t.content->video.empty()) out.push_back({"the video of " + whose, t.content->video, false});
  }
  for (const auto& p : scene.props) add_model_inputs(p.model, "prop '" + p.name + "'", out);
  if (scene.devices.laser && !scene.devices.laser->map.empty())
    out.push_back({"the laser's map", scene.devices.laser->map, true});
  return out;
}

void check_scene_outputs(const cli::Args& args, const config::Scene& scene, const std::string& scene_name) {
  args.check_clashes(scene_inputs(scene, scene_name));
}

config::Scene scene_from_args(const cli::Args& args) {
  const auto scene_path = args.get("scene");
  config::Scene scene;
  bool frame_model = false;
  if (scene_path) {
    scene = config::load_scene(*scene_path);
  } else if (args.get("model")) {
    config::TargetConfig target;
    target.name = "model";
    target.recenter = true;
    scene.targets.push_back(target);
    frame_model = !args.get("pose-matrix");
  } else {
    scene = config::load_scene(asset_dir() / "scenes" / "demo.yaml");
  }

  if (const auto model = args.get("model")) {
    if (scene.targets.size() != 1)
      throw cli::UsageError("--model replaces the model of a scene's single target, but the scene has " +
                            std::to_string(scene.targets.size()));
    scene.targets[0].model = *model;
  }
  check_scene_outputs(args, scene, scene_path ? "the scene" : "the default scene");
  auto& p = scene.projector;
  if (const auto size = args.get("size")) {
    const auto x = size->find('x');
    if (x == std::string::npos) throw cli::UsageError("--size must look like 1920x1080, got '" + *size + "'");
    const auto wh = config::parse_number_list(size->substr(0, x) + "," + size->substr(x + 1), 2, "--size");
    if (wh[0] != std::floor(wh[0]) || wh[1] != std::floor(wh[1])) throw cli::UsageError("--size needs whole pixels");
    if (wh[0] < 1 || wh[1] < 1 || wh[0] > 16384 || wh[1] > 16384)
      throw cli::UsageError("--size must be 1..16384 pixels each way, got '" + *size + "'");
    p.width_px = static_cast<int>(wh[0]);
    p.height_px = static_cast<int>(wh[1]);
  }
  if (const auto k = args.get("intrinsics")) {
    const auto v = config::parse_number_list(*k, 4, "--intrinsics");
    p.fx_px = v[0], p.fy_px = v[1], p.cx_px = v[2], p.cy_px = v[3];
  }
  p.near_m = args.get_double("near", p.near_m);
  p.far_m = args.get_double("far", p.far_m);
  config::validate_projector(p, "projector (after command-line overrides)");

  if (const auto m = args.get("pose-matrix")) {
    if (scene.targets.size() != 1)
      throw cli::UsageError("--pose-matrix sets the pose of a single target, but the scene has " +
                            std::to_string(scene.targets.size()));
    const auto v = config::parse_number_list(*m, 16, "--pose-matrix");
    Eigen::Matrix4d T;
    for (int i = 0; i < 16; ++i) T(i / 4, i % 4) = v[static_cast<std::size_t>(i)];
    config::validate_rigid(T, "--pose-matrix");
    scene.targets[0].T_projector_target = T;
  }
  if (frame_model) {
    // Framing needs the model's size: load it once here (upload_scene loads it again, cheaply).
    auto model = assets::load_model(scene.targets[0].model);
    assets::scale_and_recenter(model, 1.0, true);
    const double radius = 0.5 * model.bounds().diagonal().norm();
    if (!(radius > 0.0) || !std::isfinite(radius))
      throw config::ConfigError(*args.get("model") + ": the model has no extent to frame (size " + std::to_string(2 * radius) +
                                " m)");
    scene.targets[0].T_projector_target = framing_pose(p, radius);
    // Whatever its size, the whole bounding sphere lies between the clip planes (a 10 m far plane once
    // cut models wider than about 3.4 m out of the frame), unless the user set them.
    const double distance = scene.targets[0].T_projector_target(2, 3);
    if (!args.get("near")) p.near_m = std::max(1e-4, 0.5 * (distance - radius));
    if (!args.get("far")) p.far_m = std::max(p.near_m * 2.0, 1.5 * (distance + radius));
  }
  return scene;
}

bool on_off(const cli::Args& args, const std::string& name, bool fallback) {
  const auto value = args.get(name);
  if (!value) return fallback;
  if (*value == "on") return true;
  if (*value == "off") return false;
  throw cli::UsageError("--" + name + " must be on or off, not '" + *value + "'");
}

engine::PresentMode present_mode(const std::string& name) {
  if (name == "fifo") return engine::PresentMode::kFifo;
  if (name == "mailbox") return engine::PresentMode::kMailbox;
  if (name == "immediate") return engine::PresentMode::kImmediate;
  throw cli::UsageError("--present-mode must be fifo, mailbox or immediate, got '" + name + "'");
}

engine::WindowOptions window_options(const cli::Args& args, const config::ProjectorConfig& projector, std::string title) {
  engine::WindowOptions w;
  w.title = std::move(title);
  w.width_px = projector.width_px;
  w.height_px = projector.height_px;
  w.fullscreen = args.flag("fullscreen");
  w.monitor = args.get_int("monitor", 0, 0, 64);
  w.present_mode = present_mode(args.get_or("present-mode", "fifo"));
  return w;
}

std::unique_ptr<engine::RenderTarget> open_window(engine::Renderer& renderer, const engine::WindowOptions& options,
                                                  const config::ProjectorConfig& projector) {
  auto window = renderer.make_window(options);
  if (options.fullscreen && (window->width() != projector.width_px || window->height() != projector.height_px))
    std::cerr << "projbot: warning: monitor is " << window->width() << "x" << window->height() << " but the projector model is "
              << projector.width_px << "x" << projector.height_px << "; the image is stretched\n";
  return window;
}

}  // namespace projbot::tools
