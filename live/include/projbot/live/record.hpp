#pragma once
// `projbot record`: the projection session at every stop of the tour, written so that `run --replay` runs
// it again with no device and no twin: each stop's camera stream as a fakenect dump (depth kept to the
// Kinect's disparity steps, for the trackers too), what the base and pan-tilt answered there, the pose
// every lit target's tracker gave for every frame (tracked in lockstep), and the robot's laser scans with
// its odometry as an MRPT rawlog.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>

#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/live/rig.hpp"

namespace projbot::live {

struct RecordOptions {
  int visits = 1;          ///< cycling through the tour
  double dwell_s = 2.0;    ///< seconds at each stop
  std::uint64_t seed = 1;  ///< the twin's drive and noise, as written into the recording (open_rig's twin uses it)
  bool sim = false;        ///< no device opened, whatever `devices:` configures: the twin's (open_rig's choice)
};

struct RecordHooks {
  std::function<bool()> interrupted;      ///< Ctrl-C: ends the stop in progress; during set-up, nothing is written
  std::function<void(int frames)> frame;  ///< after each frame written (progress)
  std::ostream* log = nullptr;            ///< each stop as it is written; required
  OpenRig open_rig;                       ///< what serves the session, from the devices opened; required
};

struct Recorded {
  config::Recording recording;  ///< as written to recording.yaml
  int frames = 0;
  bool started = false;  ///< false: interrupted while setting up; no folder was made
};

/// Opens the scene's devices (its projector left out; a laser needs no map: a mapping run), builds the rig
/// (the configured robot, or the twin with a configured camera, if any) and records each visit into `out`,
/// made only once set-up is done. Each stop is written as it ends, so a recording cut short holds every
/// stop that was left. Throws live::DeviceError naming an absent device.
Recorded record(const config::Scene& scene, const RecordOptions& options, const std::filesystem::path& out,
                const RecordHooks& hooks);

}  // namespace projbot::live
