// projbot twin-dataset --out DIR: a BOP dataset rendered by the twin with the sensor model fitted to real
// frames (issue 68), for `bench dataset` and `bench sensor` to measure on beyond the shared real frames.

#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/twin/dataset.hpp"

namespace projbot::tools {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> model_folders(const cli::Args& args) {
  std::vector<fs::path> out;
  for (const auto& m : args.get_all("models")) out.emplace_back(m);
  if (!out.empty()) return out;
  const fs::path shared(PROJBOT_SHARED_DATA);
  for (const char* sub : {"ycbv-bop/models", "ycbv-extra-models/models"}) {
    std::error_code ec;
    if (!fs::is_directory(shared / sub, ec))
      throw cli::UsageError((shared / sub).string() +
                            ": the default models folder is missing; name the models with --models DIR");
    out.push_back(shared / sub);
  }
  return out;
}

// --depth-model (the name every command that simulates depth takes) or --sensor (this command's older name).
std::string sensor_name(const cli::Args& args) {
  if (args.get("sensor") && args.get("depth-model")) throw cli::UsageError("give --depth-model or --sensor, not both");
  return args.get_or("depth-model", args.get_or("sensor", "fitted"));
}

alignment::KinectNoiseConfig sensor_model(const cli::Args& args) {
  const std::string name = sensor_name(args);
  if (name == "fitted") return alignment::KinectNoiseConfig::fitted();
  if (name == "kinect") return {};
  if (name == "none") return alignment::KinectNoiseConfig::none();
  throw cli::UsageError(std::string(args.get("sensor") ? "--sensor" : "--depth-model") +
                        " must be fitted, kinect or none, got '" + name + "'");
}

int run_twin_dataset(const cli::Args& args) {
  const auto out = args.get("out");
  if (!out) throw cli::UsageError("give the folder to write: --out DIR");
  twin::DatasetOptions options;
  options.model_folders = model_folders(args);
  options.procedural = !args.flag("no-procedural");
  options.scenes = args.get_int("scenes", 10, 1, 10000);
  options.images = args.get_int("images", 10, 1, 10000);
  options.seed = static_cast<std::uint32_t>(args.get_int("seed", 1, 0, 1 << 30));
  options.sensor = sensor_model(args);
  std::vector<config::NamedPath> inputs;
  for (const auto& m : options.model_folders) inputs.push_back({"the models folder", m, true});
  args.check_clashes(inputs);
  cli::check_new_folder(*out, "twin-dataset writes a new dataset into a new or empty folder");
  std::error_code ec;
  const bool made = !fs::exists(*out, ec);
  fs::create_directories(*out);
  catch_interrupts();
  Progress progress("image", options.scenes * options.images);
  options.stop_requested = interrupted;
  options.image_done = [&](int done) { progress.step(done); };
  twin::DatasetSummary s;
  try {
    engine::Renderer renderer{engine::RendererOptions{}};
    s = twin::write_twin_dataset(*out, options, renderer);
  } catch (...) {
    if (made) fs::remove_all(*out, ec);  // only what this command made
    throw;
  }
  if (s.scenes == 0) {
    if (made) fs::remove_all(*out, ec);
    return nothing_written("before the first image");
  }
  std::cout << "twin-dataset: " << s.scenes << " scenes, " << s.images << " images, " << s.instances << " instances of "
            << s.objects << " objects in " << *out << " (sensor: " << sensor_name(args) << ")\n"
            << "measure on it: projbot bench dataset " << *out << "\n";
  if (s.interrupted) {
    std::cout << "interrupted: the last scene holds the images written before the stop; every scene's files are complete\n";
    return interrupt_exit_code();
  }
  return 0;
}

}  // namespace

const Command kTwinDataset{
    "twin-dataset",
    "a BOP dataset rendered by the twin, its depth under the sensor model fitted to real frames",
    "projbot twin-dataset --out DIR [--models DIR]... [--scenes N] [--images M] [--seed K]\n"
    "                     [--depth-model fitted|kinect|none] [--no-procedural]\n\n"
    "Writes a BOP dataset (the layout bench dataset and bench sensor read) into DIR, a new or empty folder:\n"
    "N scenes (default 10) of 3 to 6 objects resting on a table, touching and hiding each other, with a wall or\n"
    "a shelf behind, each a video of M images (default 10) from a camera 0.6 to 1.5 m away, looking down 20 to\n"
    "60 degrees and moving slowly round. The objects: every model of each --models folder (a BOP models folder:\n"
    "models_info.json beside obj_ID.ply in millimetres; default the shared YCB-Video meshes, ycbv-bop/models and\n"
    "ycbv-extra-models/models), and five procedural shapes the real frames lack (ids 101-105: a bowl and a cup\n"
    "with thin walls, a plate, a cylinder, a bent tube). Each rests on a stable face of its bounding box, turned\n"
    "at random. Depth is the exact render under MODEL: fitted (default: fitted to YCB-Video's real PrimeSense\n"
    "frames, see bench sensor), kinect (the published Kinect v1 model) or none; colour is each object's flat\n"
    "albedo, shaded, with the colour camera's noise. The camera is YCB-Video's (640x480, fx 1066.8). mask_visib,\n"
    "scene_gt_info.json (px_count_visib ...) and cam_R_w2c / cam_t_w2c come from the exact render. Symmetries in\n"
    "models_info.json: each procedural body of revolution's axis; a folder's symmetric object (YCB-V's list)\n"
    "the half turn about its most distinct principal axis. The same seed writes the same dataset. Ctrl-C\n"
    "stops after the image being written: the last scene keeps the images written so far, its files complete\n"
    "(each scene is written beside its place and renamed into it when done: an error leaves no half scene).\n",
    {{"out", "DIR", "the dataset's folder (new or empty)", cli::PathRole::output_folder},
     {"models", "DIR", "a BOP models folder to take objects from (repeatable; default: the shared YCB-Video meshes)",
      cli::PathRole::input_folder},
     {"scenes", "N", "scenes to write (default 10)"},
     {"images", "M", "images per scene (default 10)"},
     {"seed", "K", "seed of the scenes, the cameras and the sensor's noise (default 1)"},
     {"depth-model", "MODEL", "the twin's depth camera: fitted (to the real sensor's frames, default), kinect or none"},
     {"sensor", "MODEL", "the same as --depth-model (its older name)"},
     {"no-procedural", "", "leave out the procedural shapes"}},
    run_twin_dataset};

}  // namespace projbot::tools
