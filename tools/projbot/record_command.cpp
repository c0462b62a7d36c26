// projbot record: the RGB-D camera's stream (a configured camera, or the twin's at the tour's first
// stop) as a libfreenect fakenect dump, so a scene seen in the field replays on a desk through the real
// Kinect driver (issue 12, item 4, for the camera stream).

#include <chrono>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "devices.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/twin/world.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

// Frames from the configured camera for `seconds` of its own time (or until Ctrl-C).
int record_camera(alignment::RgbdCamera& camera, double seconds, alignment::FakenectDumpWriter& out, Progress& progress) {
  double first_s = -1.0;
  while (!interrupted()) {
    const alignment::RgbdFrame f = camera.next();
    if (f.colour.rgba.empty())
      throw DeviceError("the configured camera delivers no colour, and a fakenect dump holds depth and colour together");
    if (first_s < 0.0) first_s = f.depth.capture_time_s;
    if (f.depth.capture_time_s - first_s >= seconds) break;
    out.add({&f.depth, &f.colour, f.depth.capture_time_s});
    progress.step(out.frames());
  }
  return out.frames();
}

// The twin's camera at the first stop of the tour, 30 frames per simulated second, its noise seeded per frame.
int record_twin(const config::Scene& scene, std::uint64_t seed, double seconds, alignment::FakenectDumpWriter& out,
                Progress& progress, std::string& where) {
  if (scene.visits.empty())
    throw config::ConfigError(scene.source.string() + ": recording the twin needs a 'tour: {visits: [...]}' section");
  engine::Renderer renderer(engine::RendererOptions{});
  twin::TwinOptions options;
  options.seed = seed;
  twin::Twin twin(scene, options, renderer);
  const std::size_t i = twin.target_index(scene.visits.front());
  const twin::Arrival arrival = twin.arrive(i, 0);
  const Eigen::Matrix4d T_world_camera = arrival.truth.T_world_camera.matrix();
  where = "the twin's camera at the stop for '" + scene.visits.front() + "' (its first visit, seed " + std::to_string(seed) + ")";
  for (int k = 0; k / 30.0 < seconds && !interrupted(); ++k) {
    const auto noise = static_cast<std::uint32_t>(seed * 7919 + static_cast<std::uint64_t>(k));
    const alignment::DepthImage depth = twin.capture(T_world_camera, noise);
    const assets::Image colour = twin.capture_colour(T_world_camera, noise);
    out.add({&depth, &colour, k / 30.0});
    progress.step(out.frames());
  }
  return out.frames();
}

}  // namespace

const Command kRecord{
    "record",
    "record the RGB-D camera's stream (the configured camera, or the twin's) as a fakenect dump to replay",
    "projbot record --out DIR [--config site.yaml] [--sim] [--seconds S] [--seed K]\n\n"
    "Writes S seconds of depth + colour frames from the config's `devices.camera` (or, with none or with\n"
    "--sim, from the twin's camera at the tour's first stop) into DIR in libfreenect's fakenect format\n"
    "(INDEX.txt, raw 11-bit depth PGMs, RGB PPMs) with recording.yaml beside them. They replay on a desk\n"
    "through the real Kinect driver, with `devices.camera: {driver: freenect, registered: false}`:\n"
    "  fakenect DIR projbot run --config site.yaml      (libfreenect-bin's wrapper: FAKENECT_PATH=DIR and its\n"
    "                                                  libfreenect.so first on LD_LIBRARY_PATH)\n"
    "Depth is kept to the Kinect's disparity steps. Ctrl-C keeps the frames recorded so far (INDEX.txt is\n"
    "rewritten after each). Only the camera is recorded yet: not the pan-tilt, laser, odometry or the\n"
    "session's decisions.\n",
    {{"out", "DIR", "the dump folder (new or empty)"},
     {"config", "FILE", "scene (default: assets/scenes/tour.yaml)"},
     {"sim", "", "record the twin's camera whatever `devices:` configures"},
     {"seconds", "S", "how long to record (default 5)"},
     {"seed", "K", "seed of the twin's drive and noise (default 1, as run's)"}},
    [](const cli::Args& args) {
      const auto out = args.get("out");
      if (!out) throw cli::UsageError("--out DIR is required");
      const double seconds = args.get_double("seconds", 5.0);
      if (!(seconds > 0.0 && seconds <= 3600.0)) throw cli::UsageError("--seconds must be in (0, 3600]");
      const auto seed = static_cast<std::uint64_t>(args.get_int("seed", 1, 0, 1 << 30));
      args.check_output_folders({"out"});
      const config::Scene scene = config::load_scene(args.get_or("config", (asset_dir() / "scenes" / "tour.yaml").string()));
      catch_interrupts();  // Ctrl-C: keep the frames recorded so far
      alignment::FakenectDumpWriter writer(*out);
      Progress progress("frame", static_cast<int>(std::ceil(seconds * 30.0)));
      std::string where;
      int frames = 0;
      if (scene.devices.camera && !args.flag("sim")) {
        config::DevicesConfig camera_only;
        camera_only.camera = scene.devices.camera;
        std::vector<DeviceCheck> checks;
        Devices devices = open_devices(camera_only, checks, true);
        where = checks.front().config;
        frames = record_camera(*devices.camera, seconds, writer, progress);
      } else {
        frames = record_twin(scene, seed, seconds, writer, progress, where);
      }
      const auto& k = scene.depth_camera;
      std::ostringstream manifest;
      manifest << "# projbot record: a libfreenect fakenect dump (INDEX.txt lists the frames)\n"
               << "source: \"" << where << "\"\nscene: \"" << scene.source.string() << "\"\nframes: " << frames
               << "\ncamera: {width: " << k.width_px << ", height: " << k.height_px << ", fx: " << k.fx_px << ", fy: " << k.fy_px
               << ", cx: " << k.cx_px << ", cy: " << k.cy_px << "}\ndepth: raw 11-bit Kinect disparity\n"
               << "interrupted: " << (interrupted() ? "true" : "false") << "\n";
      config::write_file_atomically(std::filesystem::path(*out) / "recording.yaml", manifest.str());
      std::cout << "recorded " << frames << " frames from " << where << " to " << *out
                << "\nreplay through the Kinect driver: fakenect " << *out
                << " projbot run --config SITE.yaml (with devices.camera: {driver: freenect, registered: false})\n";
      return interrupt_exit_code();
    }};

}  // namespace projbot::tools
