// projbot record: the projection session at every stop of the tour, written so that `projbot run
// --replay` runs it again with no device and no twin (issue 12, item 4): each stop's camera stream as a
// fakenect dump (it also replays through the real Kinect driver), what the base and pan-tilt answered
// there, and the pose every lit target's tracker gave for every frame, tracked in lockstep.

#include <cmath>
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/live/record.hpp"
#include "projbot/twin/twin_rig.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {

namespace fs = std::filesystem;

const Command kRecord{
    "record",
    "run the session through the tour and record it (camera, base, pan-tilt, poses) to replay with run --replay",
    "projbot record --out DIR [--config site.yaml] [--sim] [--visits N] [--dwell S] [--seed K]\n"
    "               [--depth-model fitted|kinect]\n\n"
    "Runs the projection session at every stop of the config's tour, as run does, with every camera frame\n"
    "tracked in lockstep (each frame tracked before the next is read; a search bounded by its work, not by\n"
    "wall time), and writes into DIR:\n"
    "  stopNN/         each stop's depth + colour frames, in libfreenect's fakenect format (INDEX.txt, raw\n"
    "                  11-bit depth PGMs, RGB PPMs, the capture times kept)\n"
    "  recording.yaml  the scene, and per stop what the session asked and the devices answered: the stop\n"
    "                  driven to, where the robot then believed it stood, the pan-tilt's angles\n"
    "  poses.csv       the pose each lit target's tracker gave for every frame (the session's decisions)\n"
    "  laser.rawlog    the robot's laser scans and wheel odometry while driving and settling (the twin's, or\n"
    "                  a configured laser's with the base's odometry), as an MRPT rawlog (projbot slam and\n"
    "                  MRPT's own tools read it)\n"
    "  reflectance/    with the twin's camera: each target's reflectance, measured at the end of every stop\n"
    "                  where its pose was accepted (the colour camera under the projector's black and mid grey,\n"
    "                  divided by the light's distance and angle), refined over the visits, as a PNG over its\n"
    "                  model's texture coordinates (a model without them: one albedo in recording.yaml);\n"
    "                  run --replay compensates with it (a configured camera's recording has none: nothing\n"
    "                  is projected while recording)\n"
    "`projbot run --replay DIR` runs the same session from them with no device and no twin, and compares\n"
    "its poses with poses.csv frame for frame. A stop's dump also replays through the real Kinect driver:\n"
    "  fakenect DIR/stop01 projbot run --config site.yaml   (camera: {driver: freenect, registered: false})\n"
    "The devices are the config's, as for run: a base, pan-tilt and camera together drive the robot with no\n"
    "twin, localised on a configured laser against devices.laser.map; a laser without a map is only\n"
    "recorded (a mapping run: projbot slam --rawlog DIR/laser.rawlog --start \"robot.start\" makes the site's\n"
    "map, in the scene's frame; record prints the command). A\n"
    "camera alone is read with the twin's robot; none, or --sim, is the twin's. Depth is kept to\n"
    "the Kinect's disparity steps, for the trackers too. Ctrl-C ends the stop in progress and keeps every\n"
    "stop recorded.\n",
    {{"out", "DIR", "the recording's folder (new or empty)", cli::PathRole::output_folder},
     {"config", "FILE", "scene (default: assets/scenes/tour.yaml)", cli::PathRole::input_file},
     {"sim", "", "record the twin's camera whatever `devices:` configures"},
     {"visits", "N", "visits, cycling through the tour (default: the list once)"},
     {"dwell", "S", "seconds at each stop (default 2)"},
     {"seed", "K", "seed of the twin's drive and noise (default 1, as run's)"},
     depth_model_option()},
    [](const cli::Args& args) {
      const auto out = args.get("out");
      if (!out) throw cli::UsageError("--out DIR is required");
      const TourFamilyArgs family = tour_family_args(args, 2.0);
      const double dwell_s = family.dwell_s;
      const std::uint64_t seed = family.seed;
      const config::Scene scene = config::load_scene(args.get_or("config", (asset_dir() / "scenes" / "tour.yaml").string()));
      check_scene_outputs(args, scene, "the default scene");
      if (scene.visits.empty())
        throw config::ConfigError(scene.source.string() + ": `projbot record` needs a 'tour: {visits: [...]}' section");
      const int visits = family.visits > 0 ? family.visits : static_cast<int>(scene.visits.size());
      check_content_videos(scene);  // the recording's replay plays them: a broken one is refused before the drive
      cli::check_new_folder(*out, "a recording needs a new folder");
      catch_interrupts();  // Ctrl-C: during set-up nothing is written; later, end the stop in progress, keep every stop

      Progress progress("frame", static_cast<int>(std::ceil(visits * dwell_s * 30.0)));
      live::RecordHooks hooks{[] { return interrupted(); }, [&progress](int frames) { progress.step(frames); }, &std::cout,
                              twin::rig_opener({.seed = seed, .depth_model = family.depth_noise})};
      const live::Recorded r = live::record(scene, {visits, dwell_s, seed, args.flag("sim")}, *out, hooks);
      if (!r.started) return nothing_written("while setting up");  // no folder made
      std::cout << "recorded " << r.recording.stops.size() << " stop(s), " << r.frames << " frames from " << r.recording.camera
                << " to " << *out << "\nreplay: projbot run --replay " << *out << "\n";
      if (!r.recording.laser.empty())  // the rawlog's odometry starts at robot.start: the map goes in the scene's frame
        std::cout << "map: projbot slam --rawlog " << (fs::path(*out) / r.recording.laser).string() << " --start \""
                  << scene.robot_start.x() << " " << scene.robot_start.y() << " " << scene.robot_start.z()
                  << "\" --out-map MAP --out-trajectory MAP.txt\n";
      return interrupt_exit_code();
    }};

}  // namespace projbot::tools
