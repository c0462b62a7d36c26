#pragma once
// The end-to-end tour in the twin: the paper's experiment (sec. 4, Table 1). At each stop the robot
// localises, aims the pan-tilt at the target's surveyed position, captures depth, takes Eq. 1's
// initial guess, refines it (ICP), moves it to the projector (Eq. 2) and projects (Eq. 3); the
// projection error is measured at the target's markers.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/twin/appearance.hpp"
#include "projbot/twin/raycast.hpp"

namespace projbot::twin {

/// odometry: the paper's set-up (initial guess from wheel odometry, one plain ICP per stop).
/// localized: MRPT localisation and our acquisition (ICP, restarts, FPFH re-initialisation, quality gate).
/// tracking: localized, and the projective tracker follows the target while projecting.
/// A portable build (no MRPT, tools/bundle.sh) drives localized and tracking tours on odometry alone.
enum class TourMode { odometry, localized, tracking };
const char* to_string(TourMode mode);

struct VisitReport;

struct TourOptions {
  TourMode mode = TourMode::localized;
  int visits = 0;                    ///< 0: the scene's tour.visits once; otherwise this many, cycling through them
  std::uint64_t seed = 1;            ///< drift, laser and depth noise
  std::filesystem::path frames_dir;  ///< when set, the projector frame of each visit as a PNG
  double dwell_s = 3.0;              ///< simulated projection time per visit (camera at 30 Hz), when tracking or moving
  /// Motion prediction (issue 14): the tracker starts from it and each projector frame draws the pose
  /// predicted for its display time. False: the newest measured pose, as before.
  bool predict = true;
  alignment::MotionModelConfig motion;  ///< the motion filter's tuning
  /// Time from a depth frame's capture to its pose being ready, on the simulated clock. Unset: the wall
  /// time this machine took to render the frame (the twin's sensor) and track it, as `projbot run` sees.
  std::optional<double> processing_ms;
  bool depth_noise = true;
  /// The depth camera: KinectNoiseConfig::fitted() (the real sensor's; every command's default, --depth-model)
  /// instead of the published model (what the library's tests of single mechanisms are tuned on).
  bool fitted_depth = false;
  /// Asked between visits and between tracking frames: true ends the tour there, keeping the visits
  /// finished so far (the unfinished one is dropped) and marking the report interrupted.
  std::function<bool()> stop_requested;
  /// Called with each visit as it finishes (progress for a person watching).
  std::function<void(const VisitReport&)> on_visit;
  /// The session's projector from a calibration (issue 13): Eq. 2 and the drawing use its A_p and R_cp,
  /// T_cp while the twin's light keeps the scene's, the truth, so the markers show what the calibration's
  /// error costs. Unset: the session knows the truth.
  std::optional<config::ProjectorCalibration> calibration;
  /// Issue 43: the projector's frames compensate each target's surface (`surface:`) and the room's light;
  /// false sends the content as stored.
  bool compensation = true;
  /// Issue 43: at each arrival the visited target's reflectance is measured (the colour camera under the
  /// projector's black and grey, engine::measure_albedo at the estimated pose) and replaces the scene's
  /// `surface:` in the compensation from then on. False: the scene's is taken as known.
  bool measure_reflectance = false;
  /// With measure_reflectance: measured into each target's texture space (engine::ReflectanceMap, refined
  /// over its visits) and bound as its surface, so a printed surface is learnt; false: one colour.
  bool reflectance_map = false;
  /// Issue 43: at each arrival (and through a scripted motion) the visited target's frame is drawn with
  /// compensation off and on, and what a visitor sees of it scored (VisitReport::appearance).
  bool appearance = false;
};

/// What a visitor saw of the visited target in a projector frame (TourOptions::appearance): at arrival
/// one frame; while a scripted motion goes on, the mean over its frames scored 0.1 s apart (display time),
/// each drawn at the pose predicted for its display time: its first 0.2 s (starting: the camera's frames
/// reach the projector 50-67 ms after they are taken and the prediction needs two to see the new speed)
/// and the rest apart.
struct AppearanceSample {
  bool compensation = false;
  bool moving = false;
  bool starting = false;      ///< moving, in the first 0.2 s of the motion
  int frames = 1;             ///< the frames scored (moving: those that saw the target, each figure their mean)
  double gain = 1.0;          ///< the target's k (the same off and on)
  double ms_per_frame = 0.0;  ///< wall time to draw the projector's frame and read it back
  AppearanceScore score;
  /// Moving: the PSNR of the same frames drawn at the target's true pose (tracked exactly: what they show
  /// standing still there, the same gain); NaN otherwise. Against `score`, what the motion costs.
  double still_psnr_db = std::numeric_limits<double>::quiet_NaN();
  /// Moving: the worst frame's PSNR; NaN otherwise.
  double worst_psnr_db = std::numeric_limits<double>::quiet_NaN();
  /// At arrival, compensated: the share of the projector's pixels on the target at full in some channel
  /// (saturated_share; what the gain choice holds to about 2 %); NaN otherwise.
  double projector_saturated_share = std::numeric_limits<double>::quiet_NaN();
};

/// The projection error of one projector frame while projecting, at its display time.
struct TimelineSample {
  double t_s = 0.0;      ///< display time, since projection started
  double mean_mm = 0.0;  ///< over the markers
  double max_mm = 0.0;
  bool moving = false;   ///< the target is being moved
  bool shown = true;     ///< false while the target is blanked (lost)
  double age_ms = 0.0;   ///< of the pose drawn: from its depth frame's capture to display
  bool in_world = true;  ///< the target was there (not carried away)
  /// The target started or stopped moving after the drawn pose's capture: no frame the drawing could
  /// have come from showed it yet (the pipeline's latency, not the tracker's error).
  bool change_unseen = false;
};

/// The lit projector frames of a target that showed it far off: by their mean error at the markers (the
/// twin knows the truth), what a visitor sees as the content beside the object. Frames without a marker in
/// the light are not judged.
struct FarOff {
  int over_10mm = 0, over_20mm = 0;
  int over_20mm_change_unseen = 0;  ///< of over_20mm, those drawn before any frame showed a start or stop
  double worst_mm = 0.0;            ///< the worst lit frame's mean error (0 when none was measured)
  /// One lit frame whose mean error is `mean_mm` (NaN: none measured); `change_unseen` as TimelineSample's.
  void count(double mean_mm, bool change_unseen = false) {
    if (!(mean_mm >= 0.0)) return;
    over_10mm += mean_mm > 10.0 ? 1 : 0;
    over_20mm += mean_mm > 20.0 ? 1 : 0;
    over_20mm_change_unseen += mean_mm > 20.0 && change_unseen ? 1 : 0;
    worst_mm = std::max(worst_mm, mean_mm);
  }
  void add(const FarOff& o) {
    over_10mm += o.over_10mm;
    over_20mm += o.over_20mm;
    over_20mm_change_unseen += o.over_20mm_change_unseen;
    worst_mm = std::max(worst_mm, o.worst_mm);
  }
};

/// A target that shared the view at a stop besides the visited one (issue 11, item 5): acquired from
/// the same capture, tracked with the visited one in tracking mode, and lit or blanked on its own.
struct NeighbourReport {
  std::string target;
  bool projected = false;                                         ///< lit at arrival
  double mean_mm = 0.0, max_mm = 0.0;                             ///< at arrival; NaN when no marker is in the light
  double guess_error_cm = 0.0, guess_error_deg = 0.0;             ///< its Eq. 1 guess vs truth
  double align_ms = 0.0;                                          ///< wall time of its acquisition
  int lit_frames = 0, frames = 0;                                 ///< projector frames, the arrival's included
  double lit_mean_mm = std::numeric_limits<double>::quiet_NaN();  ///< over its lit frames (the arrival's included)
  double worst_mm = std::numeric_limits<double>::quiet_NaN();     ///< the worst of those frames' means
  FarOff far_off;                                                 ///< of its lit frames, those shown far off
};

struct VisitReport {
  int visit = 0;         ///< 1-based, over the tour
  int target_visit = 0;  ///< 1-based, this target's n-th visit
  std::string target;
  Eigen::Matrix4d T_projector_target_true = Eigen::Matrix4d::Identity();
  Eigen::Matrix4d T_projector_target_estimated = Eigen::Matrix4d::Identity();
  bool projected = false;  ///< the estimate passed the gate (the paper's set-up always projects)
  /// The last projector frame of the dwell: whether it was lit, and the pose it drew (camera frame).
  bool shown_at_end = false;
  Eigen::Matrix4d T_camera_target_at_end = Eigen::Matrix4d::Identity();
  std::vector<MarkerError> markers;
  double mean_mm = 0.0, max_mm = 0.0;  ///< at acquisition (the paper's Table 1 figure)
  alignment::AlignmentResult icp;
  alignment::FreeSpaceCheck free_space;                ///< the estimate at arrival against the measured depth
  alignment::ViewConstraints view;                     ///< how well the view at arrival pins the estimate down (weak directions)
  double base_error_cm = 0.0, base_error_deg = 0.0;    ///< believed vs true base pose at the stop
  double odometry_error_cm = 0.0;                      ///< raw wheel odometry vs truth
  double guess_error_cm = 0.0, guess_error_deg = 0.0;  ///< Eq. 1's initial guess vs the true T_camera_target
  double drive_s = 0.0;                                ///< simulated driving time to the stop
  double capture_ms = 0.0, align_ms = 0.0, frame_ms = 0.0;  ///< wall time: depth render, acquisition, projector frame
  std::vector<TimelineSample> timeline;                     ///< while projecting (empty when the visit projects one frame)
  bool moved = false;                                       ///< the target moved during this visit
  double max_mm_moving = 0.0;                               ///< worst mean error while it moved
  /// Over the lit projector frames while it moved: mean and 95th percentile of their mean errors.
  double moving_mean_mm = 0.0, moving_p95_mm = 0.0;
  int moving_blank_frames = 0;                ///< projector frames blanked while it moved (lost)
  double still_mean_mm = 0.0;                 ///< over the lit frames while it did not move
  double age_p50_ms = 0.0, age_p95_ms = 0.0;  ///< pose age at display over the lit frames
  /// After the target was lost (blanked while it was there and had been lit): the longest time until
  /// it was lit again, s; 0 when it was never lost, -1 when it was not lit again within the dwell.
  double recovery_s = 0.0;
  /// Seconds from the end of the motion until the mean error is back under 3 mm and stays there;
  /// 0 when it never left, -1 when it never came back within the dwell.
  double reconverge_s = 0.0;
  double track_ms_mean = 0.0;  ///< tracking mode: wall time per frame
  /// Tracking mode: camera frames the worker took, and those it dropped because it was still busy.
  int tracked_frames = 0, dropped_frames = 0;
  /// Tracking mode: frames on which tracking's first pass lost the target and its wider second pass
  /// ran (TargetFollower::second_passes).
  int second_pass_frames = 0;
  bool target_present = true;  ///< the target was in the world when the robot arrived
  int lit_frames = 0;          ///< projector frames that showed the target, the arrival's included
  FarOff far_off;              ///< of those, the frames shown far off
  /// Simulated seconds from arrival to the first lit frame: 0 when the acquisition lit it at once, -1
  /// when it never did.
  double first_light_s = -1.0;
  double first_light_wall_ms = -1.0;  ///< wall time spent in acquisition and search until then
  alignment::SearchStats search;      ///< tracking mode: the bounded search's attempts and cost
  /// motion.removed: seconds from the first depth frame without the target to the first blank
  /// projector frame; -1 when it was never blanked (or nothing was removed).
  double blank_after_removal_s = -1.0;
  std::vector<NeighbourReport> neighbours;         ///< other targets in view at this stop, nearest first
  std::vector<AppearanceSample> appearance;        ///< TourOptions::appearance: off and on at arrival, and while moving
  std::optional<Eigen::Vector3d> measured_albedo;  ///< TourOptions::measure_reflectance: what this visit measured
};

struct TourReport {
  TourMode mode = TourMode::localized;
  std::uint64_t seed = 1;
  bool predict = true;                  ///< TourOptions::predict
  std::optional<double> processing_ms;  ///< TourOptions::processing_ms: unset, as measured on the machine
  std::string depth_model = "kinect";   ///< the twin's depth camera: "kinect" (published), "fitted" or "none"
  config::ProjectorConfig projector;
  std::vector<VisitReport> visits;  ///< the finished visits
  double wall_s = 0.0;
  bool interrupted = false;  ///< stopped early (stop_requested), before all the visits asked for
};

/// Runs the tour on a scene with tour sections. Throws TwinError / ConfigError / EngineError naming
/// what is wrong.
TourReport run_tour(const config::Scene& scene, const TourOptions& options);

/// The paper's Table 1 beside ours: a row per visit of each target, a column per target, mm.
void print_table(const TourReport& report, std::ostream& out);
/// The lit frames shown far off over the whole tour, the visited targets' and their neighbours'.
FarOff far_off(const TourReport& report);
/// The whole report as JSON (see the README for the fields).
void write_report_json(const TourReport& report, const std::filesystem::path& path);

}  // namespace projbot::twin
