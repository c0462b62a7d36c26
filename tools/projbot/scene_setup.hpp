#pragma once
// From a command line to a scene on the GPU: the scene file (or the built-in demo), the overrides the
// render-type subcommands share, and the upload of every target's model.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/content.hpp"
#include "projbot/engine/renderer.hpp"

namespace projbot::tools {

/// A subcommand's own options followed by those every subcommand that draws a scene accepts.
std::vector<cli::OptionSpec> with_scene_options(std::vector<cli::OptionSpec> own);

/// The folder holding the shipped demo assets (PROJBOT_ASSETS overrides the built-in path).
std::filesystem::path asset_dir();

/// Opens every target's content video once (its header and first frame), before a command that only plays
/// it later (record: the replay would fail): throws assets::AssetError naming the file.
void check_content_videos(const config::Scene& scene);

/// The tour family's shared options (tour, run, record, bench motion, bench appearance), one range each:
/// --visits 1..1000 (default `default_visits`: 0 is the scene's list once), --dwell 0.1..3600 s, --seed
/// 0..2^30 (default 1), --depth-model fitted (default) or kinect, --processing-ms 0..1000 where the command takes
/// it. Throws cli::UsageError naming the option.
struct TourFamilyArgs {
  int visits = 0;
  double dwell_s = 0.0;
  std::uint64_t seed = 1;
  std::string depth_model = "fitted";                                                 ///< the twin's depth camera, by name
  alignment::KinectNoiseConfig depth_noise = alignment::KinectNoiseConfig::fitted();  ///< ...and its model
  std::optional<double> processing_ms;  ///< a pose ready this long after its capture; none: as measured here
};
TourFamilyArgs tour_family_args(const cli::Args& args, double default_dwell_s, int default_visits = 0);

/// `--depth-model fitted|kinect`: the twin's depth camera as fitted to the real sensor's frames (the default:
/// a twin no kinder than the real sensor) or the published Kinect v1 model. Every command that simulates depth
/// takes it.
cli::OptionSpec depth_model_option();
/// `--processing-ms MS`: the twin's tracker takes this long per frame instead of its measured time, so a
/// figure does not follow the machine's load.
cli::OptionSpec processing_ms_option();
/// The named model; cli::UsageError naming `option` for another name.
alignment::KinectNoiseConfig depth_model_named(const std::string& name, const std::string& option = "--depth-model");

/// For a shipped scene, whose video the build makes into the build tree: a missing one is refused saying how
/// to make it (config::ConfigError).
void check_made_video(const config::Scene& scene);

/// In a portable build (no MRPT), a line saying the twin's robot drives on odometry alone; nothing otherwise.
void note_twin_on_odometry(std::ostream& out);

/// --model-scale (model units to metres), `fallback` when not given; a usage error outside [1e-6, 1e6].
double model_scale_option(const cli::Args& args, double fallback);

/// Loads --scene (or the demo scene) and applies --model, --size, --intrinsics, --near, --far and
/// --pose-matrix; no output option may be any file it reads (check_scene_outputs). Throws
/// config::ConfigError or cli::UsageError.
config::Scene scene_from_args(const cli::Args& args);

/// The files a scene makes a command read, named for messages: the scene file (as `scene_name`: "the
/// default scene" where the command chose it), each target's and prop's model with the files it reads
/// (assets::model_files), surface textures, content videos, the laser's map.
std::vector<config::NamedPath> scene_inputs(const config::Scene& scene, const std::string& scene_name = "the scene");

/// Before any work: no output option of `args` is one of scene_inputs(scene, scene_name), or holds one
/// (UsageError naming both).
void check_scene_outputs(const cli::Args& args, const config::Scene& scene, const std::string& scene_name = "the scene");

/// A pose that frames a model of bounding radius r in the projector's view: model +y up in the image,
/// model front (+z) towards the projector.
Eigen::Matrix4d framing_pose(const config::ProjectorConfig& projector, double radius_m);

/// An `--NAME on|off` option: `fallback` when not given; anything else is a usage error naming it.
bool on_off(const cli::Args& args, const std::string& name, bool fallback);

/// fifo, mailbox or immediate. Throws cli::UsageError listing them for anything else.
engine::PresentMode present_mode(const std::string& name);

/// The projector window from --fullscreen, --monitor and --present-mode (fifo, mailbox or immediate), the
/// projector's size when windowed. Throws cli::UsageError.
engine::WindowOptions window_options(const cli::Args& args, const config::ProjectorConfig& projector, std::string title);
/// Opens it, warning on stderr when a fullscreen monitor's mode differs from the projector model's size.
std::unique_ptr<engine::RenderTarget> open_window(engine::Renderer& renderer, const engine::WindowOptions& options,
                                                  const config::ProjectorConfig& projector);

}  // namespace projbot::tools
