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

#include "projbot/alignment/kinect_noise.hpp"
#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::live {

struct RecordOptions {
  int visits = 1;          ///< cycling through the tour
  double dwell_s = 2.0;    ///< seconds at each stop
  std::uint64_t seed = 1;  ///< the twin's drive and noise
  bool sim = false;        ///< the twin's devices, whatever `devices:` configures
  /// The twin's depth camera: the real sensor's fitted model (the default), or KinectNoiseConfig{} the published one.
  alignment::KinectNoiseConfig depth_model = alignment::KinectNoiseConfig::fitted();
};

struct RecordHooks {
  std::function<bool()> interrupted;      ///< Ctrl-C: ends the stop in progress; during set-up, nothing is written
  std::function<void(int frames)> frame;  ///< after each frame written (progress)
  std::ostream* log = nullptr;            ///< each stop as it is written; required
};

struct Recorded {
  config::Recording recording;  ///< as written to recording.yaml
  int frames = 0;
  bool started = false;  ///< false: interrupted while setting up; no folder was made
};

/// Opens the scene's devices (its projector left out; a laser needs no map: a mapping run), builds the rig
/// (the configured robot, or the twin with a configured camera, if any) and records each visit into `out`,
/// made only once set-up is done. Each stop is written as it ends, so a recording cut short holds every
/// stop that was left. Throws hardware::DeviceError naming an absent device.
Recorded record(const config::Scene& scene, const RecordOptions& options, const std::filesystem::path& out,
                const RecordHooks& hooks);

}  // namespace projbot::live
