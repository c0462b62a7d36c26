#pragma once
// The subcommands of the projbot executable.

#include <functional>
#include <string>
#include <vector>

#include "cli.hpp"
#include "projbot/robot/pose2d.hpp"

namespace projbot::tools {

struct Command {
  std::string name;
  std::string summary;  ///< one line for `projbot --help`
  std::string usage;    ///< the top of `projbot NAME --help`
  std::vector<cli::OptionSpec> options;
  std::function<int(const cli::Args&)> run;  ///< returns the exit code
  /// Non-empty: this build leaves the command out (the portable build, tools/bundle.sh), and why. Called, it
  /// says so and exits kLeftOutExitCode.
  std::string left_out{};
};

/// The exit status of a command this build leaves out (sysexits.h's EX_UNAVAILABLE).
inline constexpr int kLeftOutExitCode = 69;

extern const Command kRender;
extern const Command kShow;
extern const Command kBenchRender;
extern const Command kAlign;
extern const Command kBenchTrack;
extern const Command kBenchMotion;
extern const Command kBenchAppearance;
extern const Command kBenchContent;
extern const Command kBenchAcquire;
extern const Command kBenchDataset;
extern const Command kBenchSensor;
extern const Command kTwinDataset;
extern const Command kSlam;
extern const Command kLocalize;
extern const Command kBenchLocalize;
extern const Command kTour;
extern const Command kRun;
extern const Command kDevices;
extern const Command kSimBase;
extern const Command kRecord;
extern const Command kFleet;
extern const Command kCalibrateSimulate;
extern const Command kCalibrateSolve;
extern const Command kCalibrateCapture;
extern const Command kCalibratePhotometric;

/// A planar pose from "x y phi" (metres, metres, radians; commas also separate). Throws a UsageError-like
/// config error naming `what` (the option) when it is not three finite numbers.
robot::Pose2D parse_pose(const std::string& text, const std::string& what);

}  // namespace projbot::tools
