// projbot calibrate simulate | solve: the projector-camera calibration (issue 13) in the twin and from
// capture folders, checked against the truth when the folder has one.

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "calibrate_devices.hpp"
#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/calibrate/calibrate.hpp"
#include "projbot/calibrate/capture.hpp"
#include "projbot/calibrate/pattern_screen.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/live/devices.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

constexpr const char* kDefaultBoard = "charuco:10x7:0.06:0.045:DICT_4X4_50";

// --board (default kDefaultBoard); a bad one is a usage error naming the option.
calibrate::Board board_option(const cli::Args& args) {
  const std::string spec = args.get_or("board", kDefaultBoard);
  try {
    return calibrate::Board::parse(spec);
  } catch (const calibrate::CalibrationError& e) {
    std::string why = e.what();
    if (const std::string head = "board '" + spec + "': "; why.rfind(head, 0) == 0) why = why.substr(head.size());
    throw cli::UsageError("--board '" + spec + "': " + why);
  }
}

// The twin's session from the command line: poses (spread or scripted), board, seed and noise, with the
// scene's projector and R_cp, T_cp as the truth.
calibrate::SimulationConfig simulation_config(const cli::Args& args, const config::Scene& scene) {
  calibrate::SimulationConfig c;
  c.poses = args.get_int("poses", 10, 1, 100);
  if (const auto file = args.get("poses-file")) {
    if (args.get("poses")) throw cli::UsageError("give --poses or --poses-file, not both");
    try {
      c.scripted = calibrate::read_board_poses(*file);
    } catch (const calibrate::CalibrationError& e) {  // the file's own fault: exit 1, but say which option gave it
      throw calibrate::CalibrationError(std::string("--poses-file: ") + e.what());
    }
    c.poses = static_cast<int>(c.scripted.size());
  }
  c.seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
  c.board = board_option(args);
  c.camera = calibrate::twin_colour_camera(scene.depth_camera);
  c.projector = scene.projector;
  c.T_projector_camera = scene.pan_tilt.T_projector_camera;
  c.noise_sigma = args.get_double("noise", c.noise_sigma);
  if (!(c.noise_sigma >= 0.0 && c.noise_sigma <= 50.0)) throw cli::UsageError("--noise must be 0..50 grey levels");
  return c;
}

int run_simulate(const cli::Args& args) {
  const auto out = args.get("out");
  if (!out) throw cli::UsageError("--out DIR is required");
  cli::check_new_folder(*out, "--out needs a new or empty folder for the capture");
  const std::string scene_path = args.get_or("scene", (asset_dir() / "scenes" / "shop.yaml").string());
  const config::Scene scene = config::load_scene(scene_path);
  check_scene_outputs(args, scene, "the default scene");
  const calibrate::SimulationConfig c = simulation_config(args, scene);
  Progress progress("pose", c.poses);
  catch_interrupts();  // Ctrl-C: the poses rendered so far are written as the capture
  const int written = calibrate::simulate(
      c, *out, [&](int done, int) { progress.step(done); }, [] { return interrupted(); });
  if (written == 0) {
    std::cerr << "projbot calibrate simulate: interrupted before the first pose; nothing written\n";
    return interrupt_exit_code();
  }
  std::cout << "wrote " << written << " board poses (" << calibrate::images_per_pose(c.projector.width_px, c.projector.height_px)
            << " images each, " << c.camera.width_px << "x" << c.camera.height_px << ") and the truth to " << *out
            << "\nnext: projbot calibrate solve " << *out << " --out calib.yaml\n";
  if (written < c.poses) std::cout << "interrupted after " << written << " of " << c.poses << " poses\n";
  return interrupted() ? interrupt_exit_code() : 0;
}

std::pair<int, int> parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 8 || h < 8 || w > 16384 || h > 16384)
    throw cli::UsageError("--projector '" + text + "': expected WIDTHxHEIGHT in pixels, e.g. 1280x800");
  return {w, h};
}

void print_result(const calibrate::Calibration& c) {
  std::cout << std::fixed << std::setprecision(3);
  for (const auto& v : c.views) {
    std::cout << "  " << std::left << std::setw(12) << v.folder << std::right << std::setw(4) << v.corners << " corners, "
              << std::setw(3) << v.projector_corners << " in the projector";
    if (v.refused.empty())
      std::cout << ", RMS camera " << v.camera_rms_px << " px, projector " << v.projector_rms_px << " px\n";
    else
      std::cout << ", refused: " << v.refused << '\n';
  }
  const config::Pinhole& p = c.projector;
  const config::Pinhole& k = c.camera;
  std::cout << "projector " << p.width_px << "x" << p.height_px << ": fx " << p.fx_px << " fy " << p.fy_px << " cx " << p.cx_px
            << " cy " << p.cy_px;
  if (config::has_distortion(c.projector.distortion))
    std::cout << ", k1 " << c.projector.distortion[0] << " k2 " << c.projector.distortion[1];
  std::cout << "\ncamera " << k.width_px << "x" << k.height_px << ": fx " << k.fx_px << " fy " << k.fy_px << " cx " << k.cx_px
            << " cy " << k.cy_px << ", k1 " << c.camera.distortion[0] << " k2 " << c.camera.distortion[1]
            << "\nT_cp (mm, in the board's unit: its square taken as " << std::setprecision(1) << 1000 * c.board_square_m
            << " mm): " << std::setprecision(2) << 1000 * c.T_projector_camera(0, 3) << ", " << 1000 * c.T_projector_camera(1, 3)
            << ", " << 1000 * c.T_projector_camera(2, 3) << std::setprecision(3) << "\nreprojection RMS: camera "
            << c.camera_rms_px << " px, projector " << c.projector_rms_px << " px; corners cover " << std::setprecision(0)
            << 100 * c.projector_coverage << " % of the projector's image\n";
  for (const auto& n : c.notes) std::cout << "note: " << n << '\n';
  for (const auto& w : c.warnings) std::cout << "warning: " << w << '\n';
}

// The solve beside the truth a simulated capture carries.
void print_truth(const calibrate::Calibration& c, const calibrate::Calibration& t) {
  const calibrate::TruthComparison d = calibrate::compare(c, t);
  std::cout << std::fixed << std::setprecision(3) << "against the truth:\n  projector fx " << d.projector_fx_pct << " %, fy "
            << d.projector_fy_pct << " %, principal point " << d.projector_principal_px << " px\n  camera fx " << d.camera_fx_pct
            << " %, fy " << d.camera_fy_pct << " %, principal point " << d.camera_principal_px << " px\n  T_cp "
            << d.translation_mm << " mm, R_cp " << d.rotation_deg << " deg\n";
  if (d.projector_lens)
    std::cout << "  projector lens k1 " << c.projector.distortion[0] << " (truth " << t.projector.distortion[0] << "), k2 "
              << c.projector.distortion[1] << " (truth " << t.projector.distortion[1] << "): the two lenses place a ray "
              << d.projector_lens_px << " px apart at most over the image\n";
}

int run_solve(const cli::Args& args) {
  if (args.positional().size() != 1)
    throw cli::UsageError("give one capture folder: projbot calibrate solve DIR --out calib.yaml");
  const std::filesystem::path dir = args.positional().front();
  const auto out = args.get("out");
  if (!out) throw cli::UsageError("--out FILE is required");
  calibrate::SolveOptions o;
  if (const auto s = args.get("projector")) o.projector_size = parse_size(*s);
  if (args.get("board")) o.board = board_option(args);
  o.projector_distortion = args.flag("projector-distortion");
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<Progress> progress;
  const calibrate::Calibration c = calibrate::solve(dir, o, [&](int done, int total, const calibrate::ViewResult&) {
    if (!progress) progress = std::make_unique<Progress>("view", total);
    progress->step(done);
  });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  calibrate::write_calibration(c, *out, "solved from " + dir.string());
  print_result(c);
  const std::filesystem::path truth = args.get_or("truth", (dir / "truth.yaml").string());
  std::error_code ec;
  if (std::filesystem::exists(truth, ec))
    print_truth(c, calibrate::read_calibration(truth));
  else if (args.get("truth"))
    throw cli::UsageError("--truth '" + truth.string() + "': no such file");
  std::cout << std::setprecision(1) << "solved in " << seconds << " s; wrote " << *out
            << " (a scene takes it as `calibration: " << std::filesystem::path(*out).filename().string() << "`)\n";
  return 0;
}

// The session on the configured projector and colour camera (the projector's window, the camera's
// colour frames after each pattern settles).
calibrate::CaptureSummary capture_on_devices(const cli::Args& args, const config::Scene& scene,
                                             const calibrate::CaptureOptions& o, const std::filesystem::path& out) {
  CalibrationDevices d = open_calibration_devices(args, scene, "projbot calibrate capture");
  calibrate::PatternScreen screen(*d.renderer, scene.projector);
  auto rig = calibrate::make_device_rig(screen, *d.renderer, *d.window, *d.devices.camera, settle_ms_option(args),
                                        scene.projector.input_lag_ms, std::cin, std::cout);
  return calibrate::capture(
      *rig, o, out, [](const std::string& line) { std::cout << line << std::endl; }, interrupted);
}

int run_capture(const cli::Args& args) {
  const auto out = args.get("out");
  if (!out) throw cli::UsageError("--out DIR is required");
  cli::check_new_folder(*out, "--out needs a new or empty folder for the capture");
  const std::string scene_path = args.get_or("config", (asset_dir() / "scenes" / "shop.yaml").string());
  const config::Scene scene = config::load_scene(scene_path);
  check_scene_outputs(args, scene, "the default scene");
  const bool sim = args.flag("sim");
  if (!sim && !scene.devices.camera)
    throw cli::UsageError(scene_path +
                          " configures no camera (devices.camera): the session needs the projector and a colour "
                          "camera; --sim runs it in the twin");
  calibrate::CaptureOptions o;
  o.projector_width = scene.projector.width_px;
  o.projector_height = scene.projector.height_px;
  o.board = board_option(args);
  o.poses = args.get_int("poses", 10, 1, 100);
  catch_interrupts();  // Ctrl-C: the poses kept so far are written as the capture
  calibrate::CaptureSummary s;
  if (sim) {
    engine::Renderer renderer(engine::RendererOptions{});
    calibrate::PatternScreen screen(renderer, scene.projector);
    const calibrate::SimulationConfig c = simulation_config(args, scene);
    o.poses = c.poses;
    // The twin takes what the engine drew, checked pixel for pixel against the pattern it was given.
    auto rig = calibrate::make_twin_rig(c, calibrate::engine_display(screen));
    s = calibrate::capture(
        *rig, o, *out, [](const std::string& line) { std::cout << line << std::endl; }, interrupted);
  } else {
    s = capture_on_devices(args, scene, o, *out);
  }
  if (s.kept == 0) {
    std::cerr << "projbot calibrate capture: no pose kept (" << s.refused << " refused); nothing written\n";
    return interrupted() ? interrupt_exit_code() : 1;
  }
  std::cout << "kept " << s.kept << " board poses (" << s.refused << " refused) in " << *out << "\nnext: projbot calibrate solve "
            << *out << " --out calib.yaml" << std::endl;
  return interrupted() ? interrupt_exit_code() : 0;
}

}  // namespace

CalibrationDevices open_calibration_devices(const cli::Args& args, const config::Scene& scene, const std::string& title) {
  config::DevicesConfig wanted;
  wanted.camera = scene.devices.camera;
  wanted.projector = scene.devices.projector;
  std::vector<live::DeviceCheck> checks;
  CalibrationDevices d;
  d.devices = live::open_devices(wanted, checks, true);  // an absent device: an error naming it, before anything is shown
  for (const auto& c : checks) std::cout << "opened " << c.config << ": " << c.detail << '\n';
  engine::RendererOptions ro;  // after the monitors were checked: that check starts and stops GLFW
  ro.windowing = true;
  d.renderer = std::make_unique<engine::Renderer>(ro);
  engine::WindowOptions wo = window_options(args, scene.projector, title);
  if (scene.devices.projector) {
    wo.fullscreen = args.flag("fullscreen") || scene.devices.projector->fullscreen;
    if (!args.get("monitor")) wo.monitor = scene.devices.projector->monitor;
  }
  d.window = open_window(*d.renderer, wo, scene.projector);
  return d;
}

double settle_ms_option(const cli::Args& args) {
  const double settle_ms = args.get_double("settle-ms", 150.0);
  if (!(settle_ms >= 0.0 && settle_ms <= 5000.0)) throw cli::UsageError("--settle-ms must be 0..5000");
  return settle_ms;
}

const Command kCalibrateCapture{
    "calibrate capture",
    "the calibration session: the projector shows Gray codes on a held board, the colour camera takes them",
    "projbot calibrate capture --out DIR [--config site.yaml | --sim] [--poses N] [--board SPEC] [--settle-ms MS]\n\n"
    "For each pose of a printed board (ChArUco by default; print it flat, measure its squares): the projector\n"
    "shows white while you hold the board in its light, wholly in the camera's view; press Enter and it shows\n"
    "OpenCV's Gray-code patterns of both axes with their inverses, then white and black, taking a colour image\n"
    "of each once the light has settled. A pose with too little board or too few decoded corners is refused on\n"
    "the spot and asked for again; q and Enter finishes with the poses kept. Vary the distance (0.8-1.5 m), the\n"
    "tilt (up to 30 degrees) and the place in the projector's image. Writes the folder `solve` reads:\n"
    "  DIR/capture.yaml   projector size, board, the pose folders\n"
    "  DIR/pose_NN/       the images, in GrayCodePattern::generate() order, then white, then black\n"
    "The projector and camera are the config's `devices.projector` and `devices.camera`; --sim runs the session\n"
    "in the twin (the engine draws each pattern, the twin's board and camera take it; DIR/truth.yaml beside).\n"
    "Ctrl-C writes the poses kept so far as the capture and exits 130.\n",
    {{"out", "DIR", "the capture folder to write (new or empty)", cli::PathRole::output_folder},
     {"config", "FILE", "site or scene file with devices.camera and devices.projector (default: assets/scenes/shop.yaml)",
      cli::PathRole::input_file},
     {"sim", "", "the twin's board, projector and camera"},
     {"poses", "N", "board poses to keep (default 10)"},
     {"poses-file", "FILE", "--sim: the board's poses from a script, as calibrate simulate takes them",
      cli::PathRole::input_file},
     {"board", "SPEC", std::string("board (default ") + kDefaultBoard + "; or checkerboard:9x7:0.05)"},
     {"seed", "K", "--sim: seed of the poses' jitter and the noise (default 1)"},
     {"noise", "LEVELS", "--sim: camera noise sigma, grey levels (default 1.5)"},
     {"settle-ms", "MS", "wait after a pattern is presented before taking the image (default 150; plus projector.input_lag_ms)"},
     {"fullscreen", "", "full screen on the projector (the config's devices.projector says so too)"},
     {"monitor", "N", "the projector's monitor index (default: devices.projector.monitor)"},
     {"present-mode", "MODE", "fifo (default), mailbox or immediate"}},
    run_capture};

const Command kCalibrateSimulate{
    "calibrate simulate",
    "the twin's calibration session: a ChArUco board at N poses under the projector's Gray codes",
    "projbot calibrate simulate --out DIR [--scene FILE] [--poses N | --poses-file FILE] [--board SPEC] [--seed K]\n\n"
    "Holds a printed board at N poses in front of the twin's colour camera and projector (the scene's\n"
    "projector intrinsics and robot.pan_tilt.projector_from_camera are the truth), projects OpenCV's\n"
    "Gray-code patterns of both axes with their inverses, then white and black, and writes what the\n"
    "camera sees (640x480 grey PNGs: its lens distortion, blur, noise, the projector's falloff):\n"
    "  DIR/capture.yaml   projector size, board, the pose folders\n"
    "  DIR/pose_NN/       the images, in GrayCodePattern::generate() order, then white, then black\n"
    "  DIR/truth.yaml     the values the images were made with, in calib.yaml's format\n"
    "Then: projbot calibrate solve DIR --out calib.yaml (it compares itself with truth.yaml).\n"
    "Ctrl-C writes the poses rendered so far as the capture and exits 130.\n",
    {{"out", "DIR", "the capture folder to write (new or empty)", cli::PathRole::output_folder},
     {"scene", "FILE", "scene giving the projector and camera (default: assets/scenes/shop.yaml)", cli::PathRole::input_file},
     {"poses", "N", "board poses (default 10), spread over the projector's image, 0.8-1.3 m, tilted up to 30 degrees"},
     {"poses-file", "FILE",
      "the board's poses from a script: poses: [{centre: [x, y, z], tilt_deg: [a, b, c]}, ...] (camera frame)",
      cli::PathRole::input_file},
     {"board", "SPEC", std::string("board (default ") + kDefaultBoard + "; or checkerboard:9x7:0.05)"},
     {"seed", "K", "seed of the poses' jitter and the noise (default 1)"},
     {"noise", "LEVELS", "camera noise sigma, grey levels (default 1.5)"}},
    run_simulate};

const Command kCalibrateSolve{
    "calibrate solve",
    "projector intrinsics A_p and camera-to-projector R_cp, T_cp from a Gray-code capture folder",
    "projbot calibrate solve DIR --out calib.yaml [--projector WxH --board SPEC] [--projector-distortion]\n\n"
    "DIR holds one folder per board pose, each with the Gray-code images in the order OpenCV's\n"
    "GrayCodePattern::generate() gives them (each bit's pattern then its inverse, columns then rows), then\n"
    "a white and a black image. With a capture.yaml (projbot calibrate simulate writes one) nothing else is\n"
    "needed; captures from other tools give the projector size and the board:\n"
    "  --projector 1024x768 --board checkerboard:9x7:0.025     (9 x 7 inner corners, 25 mm squares)\n"
    "  --board charuco:10x7:0.06:0.045:DICT_4X4_50             (10 x 7 squares of 60 mm, 45 mm markers)\n"
    "Per pose: the board's corners in the white image, each pixel's projector position decoded from the\n"
    "patterns, each corner's projector position from a robust local fit of the decoded pixels around it;\n"
    "then OpenCV's calibrateCamera for camera and projector and a joint stereoCalibrate. Writes A_p,\n"
    "R_cp, T_cp (Eq. 2), the camera's intrinsics and distortion, the reprojection RMS per view and in all,\n"
    "the projector area the corners covered, and warnings. A scene uses it as `calibration: calib.yaml`.\n"
    "The projector is fitted as a pinhole unless --projector-distortion; with it, the renderer pre-distorts its\n"
    "image by the lens found, so that straight content lands straight.\n",
    {{"out", "FILE", "the calibration to write (YAML)", cli::PathRole::output_file},
     {"projector", "WxH", "projector size in pixels (for a folder without capture.yaml)"},
     {"board", "SPEC", "the board (for a folder without capture.yaml)"},
     {"projector-distortion", "",
      "also fit the projector's radial distortion k1, k2 (for a projector lens that bends straight lines)"},
     {"truth", "FILE", "compare with this calibration (default: DIR/truth.yaml when present)", cli::PathRole::input_file}},
    run_solve};

}  // namespace projbot::tools
