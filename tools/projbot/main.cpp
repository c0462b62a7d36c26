// projbot: one executable, one subcommand per job. Exceptions end here as one clear line.

#include <malloc.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <new>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/stop_request.hpp"
#include "projbot/robot/error.hpp"
#include "scene_setup.hpp"

namespace {

using projbot::tools::Command;

#ifdef PROJBOT_PORTABLE
constexpr const char* kBuild = " (portable build: without MRPT, OpenCV, FFmpeg and PCL's io; tools/bundle.sh)";
#else
constexpr const char* kBuild = "";
#endif

const std::vector<const Command*>& commands() {
  static const std::vector<const Command*> all{&projbot::tools::kRender,
                                               &projbot::tools::kShow,
                                               &projbot::tools::kBenchRender,
                                               &projbot::tools::kAlign,
                                               &projbot::tools::kBenchTrack,
                                               &projbot::tools::kBenchMotion,
                                               &projbot::tools::kBenchAppearance,
                                               &projbot::tools::kBenchContent,
                                               &projbot::tools::kBenchAcquire,
                                               &projbot::tools::kBenchDataset,
                                               &projbot::tools::kBenchSensor,
                                               &projbot::tools::kTwinDataset,
                                               &projbot::tools::kSlam,
                                               &projbot::tools::kLocalize,
                                               &projbot::tools::kBenchLocalize,
                                               &projbot::tools::kTour,
                                               &projbot::tools::kRun,
                                               &projbot::tools::kDevices,
                                               &projbot::tools::kSimBase,
                                               &projbot::tools::kRecord,
                                               &projbot::tools::kFleet,
                                               &projbot::tools::kCalibrateCapture,
                                               &projbot::tools::kCalibrateSimulate,
                                               &projbot::tools::kCalibrateSolve,
                                               &projbot::tools::kCalibratePhotometric};
  return all;
}

// The guide's page (docs/ in the source tree) that explains each command, by the command's first word
// or its whole name.
std::string guide_page(const std::string& name) {
  static const std::map<std::string, std::string> pages{{"render", "using.md"},
                                                        {"show", "using.md"},
                                                        {"bench render", "profiling.md"},
                                                        {"align", "pose-estimation.md"},
                                                        {"bench track", "pose-estimation.md"},
                                                        {"bench acquire", "pose-estimation.md"},
                                                        {"bench dataset", "pose-estimation.md"},
                                                        {"bench sensor", "pose-estimation.md"},
                                                        {"twin-dataset", "pose-estimation.md"},
                                                        {"bench motion", "twin-and-tour.md"},
                                                        {"bench appearance", "visitor.md"},
                                                        {"bench content", "content.md"},
                                                        {"slam", "robot.md"},
                                                        {"localize", "robot.md"},
                                                        {"bench localize", "robot.md"},
                                                        {"tour", "twin-and-tour.md"},
                                                        {"run", "using.md"},
                                                        {"record", "using.md"},
                                                        {"fleet", "fleet.md"},
                                                        {"devices", "hardware.md"},
                                                        {"sim-base", "hardware.md"},
                                                        {"calibrate photometric", "visitor.md"},
                                                        {"calibrate", "calibration.md"}};
  if (const auto at = pages.find(name); at != pages.end()) return at->second;
  const auto at = pages.find(name.substr(0, name.find(' ')));
  return at != pages.end() ? at->second : "using.md";
}

void print_help() {
  std::cout << "projbot: projection mapping for a projector robot.\n\n"
               "Renders textured 3-D models of target objects through a calibrated projector so the\n"
               "content lands on the real objects.\n\n"
               "Usage: projbot COMMAND [options]     (projbot COMMAND --help for its options)\n"
               "       projbot --version\n\nCommands:\n";
  for (const auto* c : commands()) {
    std::string name = "  " + c->name;
    name.resize(std::max<std::size_t>(25, name.size() + 2), ' ');  // the longest, "calibrate photometric", and two
    std::cout << name << (c->left_out.empty() ? c->summary : "(not in this build: " + c->left_out + ")") << '\n';
  }
  std::cout
      << "\nExamples:\n"
         "  projbot render --out frame.png                    the demo scene, headless\n"
         "  projbot render --model duck.glb --out duck.png    one model, framed in view\n"
         "  projbot show --scene my.yaml --fullscreen --monitor 1\n"
         "  projbot align --model bun0.pcd --scan bun4.pcd --init \"0 0 0 0 -30 0\" --json\n"
         "  projbot bench dataset ../shared/data/ycbv-bop     pose estimation on real frames (BOP)\n"
         "  projbot slam --rawlog run.rawlog --out-map map --out-trajectory slam.txt\n"
         "  projbot localize --map map --rawlog run2.rawlog --out-trajectory loc.txt\n"
         "  projbot tour                                      the demo tour in the digital twin (Table 1)\n"
         "  projbot tour --mode odometry --report r.json      the paper's set-up, with a JSON report\n"
         "  projbot run --sim --fullscreen                    the live engine against the twin\n"
         "  projbot devices --config site.yaml                what this machine has; do the scene's devices work?\n"
         "  projbot record --out rec/ --config site.yaml      the session through the tour, recorded\n"
         "  projbot run --replay rec/ --headless              the same session again from the recording\n"
         "  projbot calibrate capture --out cap/                 the projector-camera calibration session (--sim: the twin's)\n"
         "  projbot calibrate simulate --out cap/                the twin's session, rendered without the engine\n"
         "  projbot calibrate solve cap/ --out calib.yaml        A_p, R_cp, T_cp from Gray-code captures\n"
         "  projbot bench render\n";
}

// A group of commands ("bench render", "calibrate solve", ...): the table's commands named "GROUP WHAT",
// and what to say when WHAT is missing or unknown.
struct Group {
  const char* name;
  const char* missing;
  const char* unknown;
};
constexpr Group kGroups[] = {{"bench", "say what to benchmark", "no benchmark"}, {"calibrate", "say which step", "no step"}};

// `projbot bench --help`, `projbot calibrate -h`: the group's commands with what each does; false for
// anything else.
bool print_group_help(int argc, char** argv) {
  if (argc != 3 || (std::string(argv[2]) != "--help" && std::string(argv[2]) != "-h")) return false;
  const std::string prefix = std::string(argv[1]) + " ";
  if (std::none_of(std::begin(kGroups), std::end(kGroups), [&](const Group& g) { return argv[1] == std::string(g.name); }))
    return false;
  std::cout << "Usage: projbot " << argv[1] << " WHAT [options] (projbot " << argv[1] << " WHAT --help for each)\n\n";
  for (const Command* c : commands())
    if (c->name.rfind(prefix, 0) == 0) {
      std::string what = "  " + c->name.substr(prefix.size());
      what.resize(std::max<std::size_t>(15, what.size() + 2), ' ');
      std::cout << what << (c->left_out.empty() ? c->summary : "(not in this build: " + c->left_out + ")") << '\n';
    }
  return true;
}

// The command argv names (`name` gets it as typed, "align", "bench motion"; `first` the index of its first
// option); null, said on stderr, when there is none.
const Command* find_command(int argc, char** argv, std::string& name, int& first) {
  name = argv[1];
  first = 2;
  for (const Group& g : kGroups) {
    if (name != g.name) continue;
    const std::string what = argc < 3 ? std::string() : argv[2], prefix = name + " ";
    std::string known;  // the group's commands, from the table: "render | track | ..."
    bool found = false;
    for (const Command* c : commands())
      if (c->name.rfind(prefix, 0) == 0) {
        known += (known.empty() ? "" : " | ") + c->name.substr(prefix.size());
        found = found || c->name.substr(prefix.size()) == what;
      }
    if (!found) {
      std::cerr << "projbot " << name << ": " << (argc < 3 ? std::string(g.missing) : std::string(g.unknown) + " '" + what + "'")
                << ": projbot " << name << " " << known << "\n";
      return nullptr;
    }
    name = prefix + what;
    first = 3;
  }
  for (const auto* c : commands())
    if (c->name == name) return c;
  std::cerr << "projbot: unknown command '" << name << "' (projbot --help lists them)\n";
  return nullptr;
}

// Runs `cmd` on its options (argv from `first`); every exception ends here as one clear line.
int run_command(const Command& cmd, int argc, char** argv, int first, const std::string& name) {
  try {
    const projbot::cli::Args args(cmd.options, argc, argv, first);
    // Only `calibrate solve DIR`, `bench dataset DIR` and `bench sensor DIR` take an argument that is not an option.
    const bool takes_folder = &cmd == &projbot::tools::kCalibrateSolve || &cmd == &projbot::tools::kBenchDataset ||
                              &cmd == &projbot::tools::kBenchSensor;
    if (args.positional().size() > (takes_folder ? 1U : 0U))
      throw projbot::cli::UsageError("unexpected argument '" + args.positional().back() + "'");
    // Every command's paths, before any work: inputs that are files, outputs that clash with nothing.
    std::vector<projbot::config::NamedPath> folder;
    if (takes_folder && !args.positional().empty()) folder.push_back({"the folder", args.positional().front(), true});
    args.check_paths(folder);
    return cmd.run(args);
  } catch (const projbot::robot::SetupInterrupted& e) {  // SIGTERM while the twin was built: nothing made
    return projbot::tools::nothing_written(std::string("while building the twin (") + e.what() + ")");
  } catch (const projbot::config::StopRequested& e) {  // a signal while a big model was read or prepared
    return projbot::tools::nothing_written(std::string("(") + e.what() + ")");
  } catch (const std::bad_alloc&) {
    std::cerr << "projbot " << name << ": out of memory: an input is larger than this machine can hold\n";
    return 1;
  } catch (const projbot::cli::UsageError& e) {
    std::cerr << "projbot " << name << ": " << e.what() << " (see projbot " << name << " --help)\n";
    return 2;
  } catch (const std::exception& e) {  // ConfigError, AssetError, AlignmentError, EngineError: one clear line
    // A third-party text that slipped through (a banner, a call stack): its first line that says something.
    std::istringstream text(e.what());
    std::string line, said;
    while (said.empty() && std::getline(text, line))
      if (line.find_first_not_of(" \t=") != std::string::npos) said = line;
    std::cerr << "projbot " << name << ": " << said << '\n';
    return 1;
  }
}

}  // namespace

// Runs the command argv names; its exit status. `name` gets it as typed ("align", "bench motion"), empty
// for --help and --version.
static int dispatch(int argc, char** argv, std::string& name) {
  // Lavapipe allocates its per-frame binning memory anew each frame. By default glibc returns such large
  // blocks to the kernel on free and the next frame faults them in again, zeroed; keeping them in the
  // heap took the 100k-triangle 1080p benchmark from p99 23 ms to 18 ms (tools/bench-vs-vkcube.sh,
  // projbot bench render). Process-wide, hence here in the application and not in the engine library.
  mallopt(M_MMAP_THRESHOLD, 256 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h" || std::string(argv[1]) == "help") {
    print_help();
    return argc < 2 ? 2 : 0;
  }
  if (std::string(argv[1]) == "--version") {
    if (argc > 2) {
      std::cerr << "projbot: --version takes nothing after it, got '" << argv[2] << "'\n";
      return 2;
    }
    std::cout << "projbot " << PROJBOT_VERSION << kBuild << '\n';
    return 0;
  }
  if (print_group_help(argc, argv)) return 0;
  int first = 2;
  const Command* cmd = find_command(argc, argv, name, first);
  if (cmd == nullptr) return 2;
  if (!cmd->left_out.empty()) {
    std::cerr << "projbot " << name << ": not in this build: " << cmd->left_out << '\n';
    return projbot::tools::kLeftOutExitCode;
  }
  for (int i = first; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") {
      std::cout << "Usage: " << cmd->usage << "\nOptions:\n"
                << projbot::cli::format_options(cmd->options) << "\nGuide: docs/" << guide_page(cmd->name)
                << " in Projbot's source tree\n";
      return 0;
    }
  // The shipped scenes find what the build made for them (the content scene's video) in the build tree.
  projbot::config::set_generated_assets(projbot::tools::asset_dir(), PROJBOT_GENERATED_ASSET_DIR);
  return run_command(*cmd, argc, argv, first, name);
}

int main(int argc, char** argv) {
  std::string name;
  const int code = dispatch(argc, argv, name);
  // What went to standard output must have arrived: `align --json >/dev/full` once exited 0 with
  // nothing written. Every command and --help / --version end here.
  errno = 0;
  std::cout.flush();
  const bool flushed = std::fflush(stdout) == 0;
  const int err = errno;  // set only if these flushes failed: a write that failed during the run set it long ago
  if (!flushed || !std::cout || std::ferror(stdout)) {
    std::cerr << "projbot" << (name.empty() ? "" : " " + name)
              << ": cannot write to standard output: " << (err != 0 ? std::strerror(err) : "a write to it failed during the run")
              << '\n';
    return 1;
  }
  return code;
}
