#pragma once
// The live engine (`projbot run`): the render thread draws every frame from the newest accepted pose of
// each lit target's tracker worker (live::ProjectionLoop); a robot thread runs the session at each stop of
// the tour (the twin's robot, the configured one, or a recording's stops in lockstep), aims, hands each
// stop's initial guess (Eq. 1) to the workers and plays the camera. Times are seconds on the steady clock.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "projbot/config/recording.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/engine/renderer.hpp"
#include "projbot/live/devices.hpp"
#include "projbot/live/projection_loop.hpp"
#include "projbot/live/replay.hpp"
#include "projbot/live/rig.hpp"
#include "projbot/live/show_control.hpp"

namespace projbot::live {

struct RunOptions {
  int visits = 0;  ///< 0: the tour's list once
  double dwell_s = 4.0;
  double seconds = 0.0;    ///< 0: until the tour ends
  bool headless = false;   ///< offscreen, paced like a 60 Hz projector
  bool predict = true;     ///< each pose moved on to its frame's display time
  bool compensate = true;  ///< radiometric compensation of each target's surface and the room's light
  /// At each stop, once the visited target's pose is accepted, its reflectance is measured (ReflectanceProbe:
  /// the projector black, then mid grey, for a moment each) and compensated for from then on.
  bool learn_reflectance = false;
  /// With learn_reflectance: what was learnt written here after each measurement (ReflectanceProbe::save_to).
  std::filesystem::path reflectance_out;
};

/// What serves the session and how it talks: what run() needs besides the scene.
struct RunSources {
  Devices* devices = nullptr;                 ///< opened devices (none: the twin serves them); required
  OpenRig open_rig;                           ///< what serves the session, from the devices or the recording; required
  const config::Recording* replay = nullptr;  ///< a recording serves every device (run --replay)
  live::PoseCheck* check = nullptr;           ///< with a replay: each lockstep pose against the recording's
  std::function<std::unique_ptr<engine::RenderTarget>(engine::Renderer&)> open_output;  ///< the projector's output
  std::function<bool()> interrupted;  ///< Ctrl-C: the loop ends at the next frame
  std::ostream* log = nullptr;        ///< each stop as it is lit, the content's reloads; required
  std::ostream* errors = nullptr;     ///< the content's failures; required
  /// The operator's controls (blackout, pause, go to a target) and the state they are shown (the console,
  /// OSC); null: none. Not with a replay, whose frames wait on the robot's.
  ShowControl* show = nullptr;
  /// A fleet's plan (run --fleet): this robot's targets (scene indices, in order), nullopt while it has
  /// none. Asked before each stop: its targets are visited in turn (from the first of a new list); given
  /// none, the robot waits where it is; given only the one it is at, it stays lit there; with no plan the
  /// tour goes on as listed. While a plan is followed the tour goes on past its visits, to --seconds or
  /// Ctrl-C. Empty: no fleet.
  std::function<std::optional<std::vector<int>>()> planned_targets;
  /// A fleet's shared estimates (run --fleet): where another robot (or this one, earlier) found a target,
  /// used instead of its survey for Eq. 1's guess and the aim. Empty: the survey alone.
  MapPoses map_poses;
};

/// What a run measured.
struct RunResult {
  live::ProjectionFigures figures;
  engine::FrameSummary summary;
  std::size_t silent_frames = 0;  ///< blanked because the camera had handed over nothing for silent_camera_s
  double silent_camera_s = 0.0;
  int visits = 0;                        ///< visits begun
  std::size_t reflectance_measured = 0;  ///< stops whose target's reflectance was measured (learn_reflectance)
  /// Per live camera frame: from its capture stamp, and from the camera's next() returning, to the frame
  /// handed to every lit worker (ms).
  std::vector<double> handoff_from_capture_ms, handoff_in_session_ms;
  std::size_t tracked = 0;  ///< frames the tracker workers processed
  std::string content;      ///< what the content played (engine::SceneContent::summary); empty: none
  std::string failure;      ///< a device (or the twin) failed while projecting: the projection was blanked
  /// Per blackout asked for (ShowControl): from the request's arrival to the first black frame's expected
  /// display (ms), and the frames shown black.
  std::vector<double> blackout_latency_ms;
  std::size_t blackout_frames = 0;
  bool measured = false;  ///< the twin served the session: the display errors are against its truth
};

/// Runs the tour (`options.visits` visits, or the recording's stops) while drawing into the output, until
/// the tour ends, `options.seconds` pass, the output is closed or `interrupted` says so. A failure of a
/// device or the twin while projecting blanks the projector and is returned; a tracker worker's failure,
/// or one before the loop starts (a bad model or video), is thrown; std::invalid_argument when `sources`
/// lacks what it requires.
RunResult run(engine::Renderer& renderer, const config::Scene& scene, const RunOptions& options, const RunSources& sources);

}  // namespace projbot::live
