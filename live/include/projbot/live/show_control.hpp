#pragma once
// The show's controls and its state, shared between the live engine and whoever operates it (the
// console's page and API, OSC, a script): the operator asks (blackout, pause, go to a target) from any
// thread; the render thread reads the blackout once per frame and publishes the show's state about five
// times a second; the robot thread reads the pause and the go-to between frames. Both offer pictures
// (ShowPictures) while someone looks at them. Neither engine thread ever
// waits on an operator: every call here is a flag or a pointer swapped under a short lock.

#include <Eigen/Geometry>
#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "projbot/config/scene.hpp"
#include "projbot/live/projection_loop.hpp"
#include "projbot/live/show_pictures.hpp"

namespace projbot::live {

/// A target of the site as the operator sees it.
struct SiteTarget {
  std::string name;
  bool reachable = false;                   ///< the robot can go to it (a stop, a place on the map)
  std::optional<std::array<double, 2>> at;  ///< where the map says it stands (x, y m); nullopt: not placed
  std::string content;                      ///< the file name of the video it plays; empty: none (no switching)
};

/// The scene's targets, in order, as SiteTargets.
std::vector<SiteTarget> site_targets(const config::Scene& scene);

/// One target as the show last drew it.
struct TargetShowState {
  std::string name;
  /// "lit" (drawn in the newest frame), "blank" (lit at this stop, not drawn: not found yet, lost,
  /// unconfirmed), "idle" (not lit at this stop).
  std::string state = "idle";
  bool visited = false;                     ///< the stop's visited target (the others lit are neighbours)
  double error_mm = -1;                     ///< at its display time, where a truth is known; -1: not measured
  std::optional<std::array<double, 2>> at;  ///< where the map says it stands (x, y m)
  std::string content;                      ///< the video it plays (the last one switched to); empty: none
  /// Where the newest frame drew it in the map: the stop's believed camera (Eq. 1's T_map_camera) times the
  /// drawn T_camera_target; nullopt unless lit.
  std::optional<Eigen::Isometry3d> T_map_target;
  double quality = -1.0;  ///< the tracker's inlier ratio for that pose, 0..1; -1 unless lit
};

/// One visit of the tour as the projector lit it: its visited target's frames while the robot stood there.
struct VisitShowRow {
  int visit = 0;  ///< 1-based
  std::string target;
  std::size_t frames = 0, lit_frames = 0;  ///< the projector's frames at the stop; those that drew the target
  /// The target's error at display over its measured lit frames, mean and worst (mm; -1: none measured).
  double mean_mm = -1.0, worst_mm = -1.0;
  std::size_t measured = 0;  ///< lit frames whose error was measured (the twin's)
};

/// What the show is doing, as the render thread last saw it.
struct ShowState {
  std::uint64_t sequence = 0;  ///< grows with each state published
  double clock_s = 0.0;        ///< since the run began, on its clock
  /// "starting", "driving" (no target lit), "acquiring" (at a stop, nothing drawn yet), "lit", "stopped"
  /// (the tour is over or the robot failed).
  std::string phase = "starting";
  int visit = 0;         ///< 1-based; 0 before the first
  std::string visiting;  ///< the visited target's name; empty while driving
  /// Where the robot believed it was at each stop so far (map frame: x, y in m, heading in rad), the newest last.
  std::vector<std::array<double, 3>> stops;
  /// Where it believes it is now: while driving, its pose at the newest control step read; else the newest stop's.
  std::optional<std::array<double, 3>> robot;
  /// Where the robot believes its projector is in the map, at a stop (what a neighbour blends against).
  std::optional<Eigen::Isometry3d> T_map_projector;
  std::vector<TargetShowState> targets;  ///< by scene index
  double frame_rate_hz = 0.0;            ///< over the last second
  double pose_age_ms = -1.0;             ///< the newest drawn pose's age at display; -1: nothing drawn
  bool blackout = false, paused = false;
  std::string go_to;               ///< a target asked for and not reached yet
  std::vector<VisitShowRow> tour;  ///< a row per visit so far, the newest last
};

class ShowControl {
 public:
  /// `targets`: the scene's, in order (site_targets); go_to accepts the reachable ones. `content_folder`:
  /// the site's videos a target's content may be switched to (empty: none).
  explicit ShowControl(std::vector<SiteTarget> targets, std::filesystem::path content_folder = {});

  // The operator's side (any thread).
  /// Every projector frame black from the next one until released. `asked_s` (steady clock): when the
  /// request arrived, for the latency measured at the first black frame.
  void set_blackout(bool on, double asked_s);
  /// The tour holds at the stop it is at (or before setting off for the next) until resumed.
  void set_paused(bool on) { paused_ = on; }
  /// The robot leaves its stop now for `target`'s (a scene target's name); false (nothing changed) for a
  /// name that is not one, or one the robot cannot go to.
  bool go_to(const std::string& target);
  /// The videos a target may switch to: the files directly in the content folder, by name, sorted (hidden
  /// ones left out; a link only where it leads to a file inside the folder). Empty without a folder.
  std::vector<std::string> content_files() const;
  enum class ContentAnswer { switched, no_folder, no_target, no_video, no_file };
  /// Target `target` plays `file` (a name content_files lists; nothing else, no path) from a later frame.
  ContentAnswer switch_content(const std::string& target, const std::string& file);
  /// What a ContentAnswer other than `switched` means, for whoever asked.
  std::string said(ContentAnswer answer, const std::string& target, const std::string& file) const;
  /// The newest state published (a default one before the first).
  std::shared_ptr<const ShowState> state() const;
  /// Waits until a state newer than `sequence` is published or `timeout_ms` pass; the newest either way.
  std::shared_ptr<const ShowState> wait_newer(std::uint64_t sequence, int timeout_ms) const;
  const std::vector<SiteTarget>& targets() const { return targets_; }
  /// The projector's frame and the camera's view as small PNGs (the engine offers them while wanted).
  ShowPictures& pictures() { return pictures_; }

  // The engine's side.
  bool blackout() const { return blackout_; }
  bool paused() const { return paused_; }
  /// The target asked for (scene index), once: the robot thread takes it when it acts on it.
  std::optional<int> take_go_to();
  /// A go-to asked for and not taken yet (scene index).
  std::optional<int> pending_go_to() const;
  /// The switches asked for since last taken, in order: a scene index and the video's path.
  std::vector<std::pair<int, std::filesystem::path>> take_content_switches();
  /// The video target `index` plays as last asked (its file name; empty: none).
  std::string content_of(std::size_t index) const;
  /// When the blackout now on was asked for (steady clock), once: the render thread takes it at its
  /// first black frame to measure the latency; nullopt when taken or off.
  std::optional<double> take_blackout_asked();
  /// The render thread's pace between offscreen frames: sleeps until `until_s` (steady clock) or until a
  /// blackout asked for waits for its first black frame; true when woken for one (the frame starts now).
  bool sleep_until(double until_s) const;
  /// The render thread's: the state now (its sequence is set here). Wakes every wait_newer.
  void publish(ShowState state);

 private:
  std::vector<SiteTarget> targets_;
  std::atomic<bool> blackout_{false}, paused_{false};
  std::atomic<int> go_to_{-1};
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  mutable std::condition_variable asked_;  // a blackout asked for
  std::shared_ptr<const ShowState> state_;
  double blackout_asked_s_ = -1.0;  // under mutex_
  std::filesystem::path content_folder_;
  std::vector<std::string> content_;                             // under mutex_, by scene index
  std::vector<std::pair<int, std::filesystem::path>> switches_;  // under mutex_
  ShowPictures pictures_;
};

/// The stop as the render thread last read the robot's state.
struct StopView {
  std::vector<int> lit;                           ///< scene indices, the visited one first; empty while driving
  int visit = 0;                                  ///< 1-based; 0 before the first
  bool done = false;                              ///< the tour is over (or the robot failed)
  std::array<double, 3> believed{};               ///< where the robot believed it was at the stop (x, y m; heading rad)
  std::optional<std::array<double, 3>> moving{};  ///< while driving: where it believes it is now
  /// At a stop: where the robot believes its camera and projector are in the map (robot::HeadPoses).
  std::optional<Eigen::Isometry3d> T_map_camera{}, T_map_projector{};
};

/// The render thread's side of ShowControl: each frame seen, the show's state published about five times
/// a second (every `period_s` on the steady clock).
class ShowReporter {
 public:
  explicit ShowReporter(ShowControl& control, double period_s = 0.2) : control_(control), period_s_(period_s) {}
  /// After frame `f` started at `now_s` (steady clock, seconds since the run began: `clock_s`): the stop
  /// as last read and the figures measured so far (their newest row is the frame before).
  void frame(const DecidedFrame& f, const StopView& stop, const ProjectionFigures& figures, double now_s, double clock_s);

 private:
  ShowState build(const StopView& stop, const ProjectionFigures& figures, double clock_s) const;
  void count(const DecidedFrame& f, const StopView& stop, const ProjectionFigures& figures);
  ShowControl& control_;
  double period_s_;
  double last_published_s_ = -1e9;
  std::deque<double> starts_;     // frame starts over the last second
  std::vector<DrawnPose> drawn_;  // the newest frame's that showed the targets (a blackout's shows none)
  std::vector<std::array<double, 3>> stops_;
  int stops_visit_ = 0;  // the visit whose stop was last added
  std::vector<VisitShowRow> tour_;
  double last_counted_s_ = -1.0;  // the figures' row last counted into the tour (its clock_s)
};

}  // namespace projbot::live
