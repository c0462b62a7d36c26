#pragma once
// The target follower: the tracker worker's policy for one frame, without its thread (track from the last
// pose, acquire when lost or not yet found, search in bounded attempts), its configuration, and the pose
// samples it publishes. The live engine runs it in a TrackerWorker; the twin's tour on its simulated clock.

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "projbot/alignment/coarse_search.hpp"
#include "projbot/alignment/motion_model.hpp"
#include "projbot/alignment/registration.hpp"
#include "projbot/alignment/tracker.hpp"
#include "projbot/alignment/verification.hpp"

namespace projbot::alignment {

/// The tracker worker's policy. Why each value is what it is (the measurements behind it) is in the
/// commits that set it and in the README.
struct WorkerConfig {
  AcquisitionConfig acquisition;
  TrackerConfig tracking;
  /// Weight of the silhouette's edges in the projective polish that ends an acquisition, for models
  /// without colour contrast (TrackerConfig::edge_weight); not used while tracking.
  double polish_edge_weight = 1.0;
  /// Frames in a row in which neither tracking nor its second, wider pass (correspondences up to
  /// reach_m, metres) found the target, after which it is reported lost and blanked.
  int lost_after = 2;
  double reach_m = 0.10;
  /// A lost or not-yet-found target is searched for by bounded attempts (SearchStage::local ->
  /// global_near -> global_wide, round again), one per frame at most; after the n-th failed attempt the
  /// next waits search_spacing_frames[min(n - 1, size - 1)] frames...
  std::vector<int> search_spacing_frames{0, 3, 9, 15, 30};
  /// ...and long enough that searching takes at most this share of the worker's time (an attempt of t
  /// ms is followed by t (1 / search_duty - 1) ms of frames at camera_hz without one).
  double search_duty = 0.25;
  /// Until the target is first found from a new guess, every search attempt is the acquisition itself
  /// (acquire(), spaced as above): a target the acquisition finds on some frame is found on it. Once
  /// found and then lost, the first attempt acquires and later ones are the bounded attempts above.
  /// False: every attempt is a bounded one.
  bool first_search_acquires = true;
  double camera_hz = 30.0;
  /// A pose whose predicted silhouette is seen through (check_free_space) over more than this share is
  /// rejected, whether tracked, refined or found.
  double max_behind_ratio = 0.1;
  /// Motion prediction: tracking starts each frame from the motion filter's prediction at its capture
  /// time, and each sample carries the motion the renderer extrapolates to its display time. False:
  /// tracking starts from the last pose and every sample is still.
  bool predict = true;
  MotionModelConfig motion;
  /// Acquisition leaves out the scan points within this of a known floor, or under it (m).
  double floor_margin_m = 0.02;
  /// With a footing above the floor, also what lies below the support's top plus this (m; negative keeps
  /// the target's own lowest centimetre, which pins it vertically).
  double support_margin_m = -0.005;
  /// Without a map: the support found in the frame (support_in_frame) is left out up to this above it (m).
  double frame_support_margin_m = 0.008;
  /// From a guess known to within half the model's size, surfaces that run on past the crop and lie
  /// mostly outside the silhouette are left out (crop_to_silhouette's clustering).
  bool cluster_neighbours = true;
  /// The guess's uncertainty: the depth is cropped to its predicted silhouette grown by this much (m)
  /// plus this turn of the model's farthest point about its origin (degrees).
  double guess_uncertainty_m = 0.05;
  double guess_uncertainty_deg = 3.0;
  /// Once ICP has an estimate the depth is cropped again at it, grown by this (m), and ICP refines there.
  double recrop_m = 0.03;
  /// Whether the configured uncertainty is a bound on the first acquisition's answer (`bench dataset
  /// --track`), as a GuessError given to acquire() is: see GuessError. False: no bound (a map's guess of
  /// a target that may have been moved).
  bool guess_bounds_estimate = false;
  /// How much farther than a bounded guess's error an estimate's centroid may lie (m): the estimate's own.
  double reach_margin_m = 0.02;
  /// Colour at acquisition: a move along the weakest slides is taken only if the depth's RMS error grows
  /// by at most this share...
  double colour_max_rmse_growth = 0.10;
  /// ...a pose whose colours correlate with the image less than this is refused (models with colour
  /// contrast)...
  double min_colour_agreement = 0.5;
  /// ...and where ICP held the view's weak directions for colour (AlignmentResult::weak_held), a pose
  /// colour leaves agreeing less than this is found again by depth alone, coarse to fine.
  double min_held_colour_agreement = 0.9;
  /// A pose colour placed or confirmed is held (TrackerConfig::hold_prior) until the target is seen
  /// moving or tracked this far from it (m, degrees).
  double hold_release_m = 0.003;
  double hold_release_deg = 1.0;
  /// One acquisition starts no new ICP stage, restart, global round or colour retry after this many ms
  /// of its thread's CPU time, and blanks what it has not confirmed by then; the stage running at the
  /// deadline finishes. Tracking's search attempts have their own (AcquisitionConfig::attempt_budget_ms).
  /// The wall time runs past it (that stage, the global search's OpenMP threads): at 1500 the YCB-V
  /// frames' slowest refused searches took 1.18-1.61 s from run to run, at 1300 1.34-1.48 s, same results.
  double acquire_budget_ms = 1300.0;
  /// A frame tracking lost (both reaches refused it) gets the acquisition's local step from where the
  /// target was, with this much of the thread's CPU time (ms); the stage running at the deadline finishes.
  double rescue_budget_ms = 100.0;
  /// From a guess not known to within half the model's size (a gross one) whose reach (the silhouette's
  /// growth) is at most coarse_max_reach_m, and from a close guess whose own ICP fails, acquisition
  /// scores poses around the guess against the depth (coarse_candidates) and acquires from the best
  /// coarse.count of them in turn, each as from a close guess (from_candidates). Farther reaches need
  /// turns a grid cannot cover: ICP's restarts and global search.
  bool coarse_search = true;
  double coarse_max_reach_m = 0.1;
  /// Of the candidates that converge, the one whose centre lies nearest the guess is the estimate; the
  /// search stops at one within this share of the guess's reach (a fit farther off may be a neighbour).
  double nearest_candidate_share = 0.9;
  /// A candidate's fit that hides (FreeSpaceCheck): more than hidden_flush_ratio of its outline runs on
  /// flush into the surface around it, and more than hidden_front_ratio of its silhouette lies behind
  /// something nearer, is a pose sunk into what stands behind the target, not the target.
  double hidden_flush_ratio = 0.55;
  double hidden_front_ratio = 0.2;
  /// ...or more than embedded_flush_ratio of its outline runs on flush, whatever lies in front: a patch
  /// of a larger surface, not an object standing out of it.
  double embedded_flush_ratio = 0.8;
  CoarseSearch coarse;
};

/// How far a stated guess may be off (`align --guess-error`, `bench dataset`'s perturbations): the model
/// moved at most move_m and turned at most turn_deg about its origin. The depth is searched within that
/// reach, and an estimate whose centroid lies farther from the guess's than the move (plus the turn's
/// sweep of the centroid about the origin, plus reach_margin_m) is something else that fits.
struct GuessError {
  double move_m = 0.05;
  double turn_deg = 15.0;
};

/// What searching for a target has cost since its stop began.
struct SearchStats {
  int attempts = 0;              ///< bounded acquisition attempts (the same-frame refine excluded)
  double total_ms = 0.0;         ///< their wall time, summed
  double max_attempt_ms = 0.0;   ///< the longest one
  double last_attempt_ms = 0.0;  ///< the newest one
  int frames_waited = 0;         ///< frames skipped between attempts (spacing)
  /// The found pose's colour check (step with a colour image): how far colour moved it, and how well
  /// its colours agree with the image (NaN: no colour image, or a model without colour contrast).
  double colour_shift_mm = 0.0;
  double colour_agreement = std::numeric_limits<double>::quiet_NaN();
};

/// What the render thread reads: the newest accepted pose, or the news that the target is lost.
struct PoseSample {
  Eigen::Matrix4d T_camera_target = Eigen::Matrix4d::Identity();
  std::uint64_t sequence = 0;   ///< increases with every publication
  double capture_time_s = 0.0;  ///< capture time of the depth frame the pose came from
  bool lost = true;             ///< true: blank the target, do not project
  /// Found (or still followed) but blank in this frame: the pose broke the motion's prediction (a start, a
  /// stop or one bad pose, MotionFilter::confirmed), or the tracker refused this frame and follows on from
  /// the last pose (T_camera_target is that pose). Drawn on, either would be light no frame confirmed.
  bool held = false;
  bool drawable() const { return !lost && !held; }
  double inlier_ratio = 0.0;
  double rmse_mm = 0.0;
  /// The motion to draw it with: predict_pose(motion, display time). Still (motion.T is
  /// T_camera_target) unless the target is seen moving and prediction is on.
  MotionState motion;
};

/// The worker's policy for one frame, without the thread: track from the last pose; when tracking
/// fails, one ICP on the same frame from where the target was last seen; after `lost_after` frames in
/// which neither found it, report it lost (blank it) and search: bounded attempts, escalating and
/// spaced out (WorkerConfig). A new stop's guess starts the search. The twin's tour runs it in simulated
/// time. Not thread-safe.
class TargetFollower {
 public:
  /// Throws AlignmentError for a bad model or intrinsics.
  TargetFollower(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config = {});
  /// A new stop: the next frame acquires from this guess (Eq. 1). With `floor` (from the map and the
  /// camera's pose), acquisition leaves out what lies on it (floor_margin_m); without, the first local
  /// search finds what the target rests on in the frame (support_in_frame), as acquire() without a map.
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target, const std::optional<Plane>& floor = std::nullopt);
  /// ...and with the target's surveyed footing (its floor left out as above), acquisition accepts only
  /// poses that stand as surveyed (AcquisitionConfig::footing_height_m, footing_tilt_deg). Tracking is
  /// held only to not sinking into it: a target carried, lifted or tipped is followed, only not re-found so.
  void set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing);
  /// The target was already acquired at T_camera_target: the next frame tracks from there.
  void set_pose(const Eigen::Matrix4d& T_camera_target);
  /// One frame: the sample to publish (sequence left 0), or nothing when there is no guess yet, the
  /// frame was rejected without the target being lost yet, or a search attempt is not due. With
  /// `colour` (registered to the frame, taken before the projector lights the target), a pose found
  /// by the search is moved by colour where depth allows and refused when its colours disagree, as in
  /// acquire(), and the pose colour placed or confirmed is then held while the target stays still
  /// (hold_release_m).
  std::optional<PoseSample> step(const DepthImage& frame, const assets::Image* colour = nullptr);
  /// Frames since the last guess or pose on which tracking's first pass failed and its second, wider
  /// one (reach_m) ran: each costs about a tracking step more.
  int second_passes() const { return second_passes_; }
  /// Whether tracking holds a pose that colour placed or confirmed.
  bool holding() const { return hold_.has_value(); }
  /// The search since the last guess or pose was set.
  const SearchStats& search_stats() const { return stats_; }
  /// The newest acquisition attempt's result (refine or search stage), if any since the last guess.
  const std::optional<AlignmentResult>& last_attempt() const { return last_attempt_; }
  /// The free-space check of a pose on a frame, and whether it passes (see max_behind_ratio).
  /// With `outline`, also the outline's counts (check_free_space).
  FreeSpaceCheck verify(const DepthImage& frame, const Eigen::Matrix4d& T_camera_target, bool outline = false) const;
  bool passes(const FreeSpaceCheck& check) const { return check.passes(cfg_.max_behind_ratio); }
  /// The newest free-space check (of the last pose accepted or refused).
  const FreeSpaceCheck& last_check() const { return check_; }
  /// The tracked pose, or the guess while acquiring.
  Eigen::Matrix4d last_pose() const { return pose_.value_or(guess_); }
  const Aligner& aligner() const { return aligner_; }
  const MotionFilter& motion() const { return filter_; }
  /// One whole acquisition from `guess` (the tour's localized mode, a stop's first search): the footing's
  /// floor left out and only poses that stand as it says accepted; the depth cropped to the guess's
  /// silhouette grown by grow_m (silhouette_grow_m() for the configured uncertainty); ICP, refined on the
  /// depth cropped again at the estimate (recrop_m); a converged pose polished by up to three projective
  /// passes on the whole frame (inlier ratio and rmse are of the pose before the polish). With `colour`
  /// (registered to the frame), moved along its weakest slides to where its colours agree best as far
  /// as the depth allows, and refused when they disagree. Bounded by acquire_budget_ms: what is not
  /// confirmed by then is returned unconverged (blank). Throws AlignmentError when too little depth is left.
  AlignmentResult acquire(const DepthImage& frame, const Eigen::Matrix4d& guess, const Footing& footing, double grow_m,
                          const assets::Image* colour = nullptr) const;
  /// The same without a map and from a guess whose error is stated (a real frame of objects on a table,
  /// `projbot align` on a depth image, a BOP dataset): the support under the guess is found in the frame
  /// (support_in_frame, within the error's reach) and stands in for the footing (the target rests on it,
  /// any way up; where none is found, nothing is left out and no footing is asked for); an estimate
  /// beyond the error is refused (GuessError).
  AlignmentResult acquire(const DepthImage& frame, const Eigen::Matrix4d& guess, const GuessError& error,
                          const assets::Image* colour = nullptr) const;
  double silhouette_grow_m() const { return silhouette_grow_m_; }

 private:
  struct Known {  // what the map says at this stop (camera frame)
    std::optional<Plane> floor;
    std::optional<Footing> footing;
    std::optional<ThreadCpuClock::time_point> deadline;  // acquire()'s: no new search step after it
    bool close = false;          // the guess is known to within half the model's size (Aligner::align's close_guess)
    bool frame_support = false;  // no map: the floor and footing are the support found in the frame
    // A stated guess's bound: where its error lets the model's centroid lie (beyond_bound).
    struct Bound {
      Eigen::Matrix4d guess;
      double centre_m;  // how far from where `guess` puts the centroid (m)
    };
    std::optional<Bound> bound;
  };
  /// How an acquisition places the view's weak directions (a box seen face-on, along its face).
  enum class Weak {
    colour,         ///< projective_first, else ICP coarse to fine; their finest stages hold them for colour
    coarse_colour,  ///< ICP coarse to fine (its coarse stages reach farther along them), finest held for colour
    depth,          ///< depth alone: projective_first only for views without weak directions, else ICP
  };
  /// From a guess: projective_first on `near_depth` (the frame's depth near `guess`: near_guess, grown
  /// by grow_m); when that fails, ICP on `near` (the same as points), refined on the depth near its
  /// estimate (recropped); when that fails the gate, the same with `stage`'s restarts and global search.
  AlignmentResult align_near(const DepthImage& frame, const DepthImage& near_depth, const PointCloud& near,
                             const Eigen::Matrix4d& guess, const Known& known, double grow_m, SearchStage stage, Weak weak) const;
  /// Projective ICP from `guess` on `near` (the tracker's association at its wide reach), then ICP's
  /// finest stage on the depth cropped tight at that estimate: the estimate when it passes the gate. A
  /// view with weak directions (a box seen face-on): with `hold` the finest stage holds them for colour
  /// to place; without, nothing (the projective association may have left the estimate turned along
  /// them, and ICP coarse to fine does better).
  std::optional<AlignmentResult> projective_first(const DepthImage& frame, const DepthImage& near, const Eigen::Matrix4d& guess,
                                                  const Known& known, bool hold) const;
  /// When an acquisition starting now must stop starting new steps (acquire_budget_ms of CPU time).
  ThreadCpuClock::time_point acquire_deadline() const;
  /// acquire()'s body, with what is known at this stop: searched(), then, without colour to place it,
  /// turned towards the guess about an axis the view leaves free (nearest_unseen_turn).
  AlignmentResult acquire_known(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& known, double grow_m,
                                const assets::Image* colour) const;
  /// From a gross guess within coarse_max_reach_m the candidates (from_candidates); else, or when there
  /// are none, from the guess itself (acquire_at), and the candidates when that fails within the budget.
  AlignmentResult searched(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& known, double grow_m,
                           const assets::Image* colour) const;
  /// The close acquisition from each of coarse_candidates around `guess` (within grow_m) in turn: of
  /// those that converge, stay within the known bound and do not hide, the nearest the guess, stopping
  /// at one within nearest_candidate_share of grow_m; else the unconverged one with the most inliers;
  /// nothing when there are no candidates.
  std::optional<AlignmentResult> from_candidates(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& known,
                                                 double grow_m, const assets::Image* colour) const;
  /// Whether T puts the model's centroid beyond the known bound (plus reach_margin_m): something else
  /// that fits, not the target.
  bool beyond_bound(const Known& known, const Eigen::Matrix4d& T) const;
  /// Whether a candidate's fit T hides behind something nearer (hidden_flush_ratio, hidden_front_ratio)
  /// or lies embedded in a surface (embedded_flush_ratio).
  bool hidden(const DepthImage& frame, const Eigen::Matrix4d& T) const;
  /// The bound of a guess off by `move_m` and `turn_deg` (GuessError).
  Known::Bound bound_of(const Eigen::Matrix4d& guess, double move_m, double turn_deg) const;
  /// The acquisition from one guess.
  AlignmentResult acquire_at(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& known, double grow_m,
                             const assets::Image* colour, SearchStage stage = SearchStage::full) const;
  /// Whether the projective polish's pose stands as ICP's did: no more of it seen through, and with a
  /// footing, still passing the gate.
  bool polish_kept(const DepthImage& frame, const Known& known, const Eigen::Matrix4d& before,
                   const Eigen::Matrix4d& after) const;
  /// acquire() without colour's move: align_near, then the projective polish.
  AlignmentResult acquired(const DepthImage& frame, const DepthImage& near, const PointCloud& near_cloud,
                           const Eigen::Matrix4d& guess, const Known& known, double grow_m, Weak weak, SearchStage stage) const;
  /// r refined by ICP (`stage`: refine or icp_only) on the depth near its estimate, grown by recrop_m;
  /// r itself when only it passes the gate.
  AlignmentResult recropped(const DepthImage& frame, const AlignmentResult& r, const Known& known, SearchStage stage,
                            bool hold) const;
  ModelCloud model_;           // for the free-space check
  bool find_support_ = false;  // a guess without a map: the next local search finds the support in the frame
  bool map_floor_ = false;     // the floor came from the map (and the camera's pose), not from a frame
  bool colour_contrast_;       // the model's colours can say where it is (has_colour_contrast)
  Aligner aligner_;
  ProjectiveTracker tracker_;  // from a guess, or from a pose frames were dropped since
  // From the last frame's pose: a descent that has not settled within a frame's motion is sliding along
  // what the depth leaves free, not arriving (TrackerConfig::extra_descents left out).
  ProjectiveTracker next_frame_tracker_;
  ProjectiveTracker wide_tracker_;  // the same frame again, with a wider reach, when tracking failed
  // Acquisition's last step: tracking's settings, with the silhouette's edges where the model has no
  // colour contrast.
  ProjectiveTracker polish_tracker_;
  CameraIntrinsics k_;
  WorkerConfig cfg_;
  std::optional<Eigen::Matrix4d> pose_;  // tracked pose; empty while acquiring
  Eigen::Matrix4d guess_ = Eigen::Matrix4d::Identity();
  bool have_guess_ = false;
  int rejected_ = 0;
  int second_passes_ = 0;
  bool lost_reported_ = false;
  int wait_ = 0;  // frames until the next search attempt
  SearchStats stats_;
  int search_attempts_ = 0;     // attempts since this search began (a new guess, or the target lost)
  bool found_at_stop_ = false;  // a pose was found since the last guess
  std::optional<AlignmentResult> last_attempt_;
  FreeSpaceCheck check_;
  Known known_;                   // this stop's floor and footing
  MotionFilter filter_;           // fed with every pose found, reset when the target is lost or a stop begins
  double silhouette_grow_m_;      // how far the guess's configured uncertainty reaches
  double model_radius_m_;         // the model's farthest point from its origin
  Eigen::Vector3d model_centre_;  // its centroid (a stated guess bounds how far it moves)
  double last_found_s_ = 0.0;     // capture time of the newest pose found
  // Where a textured model may look like itself turned (box_turns; none without colour contrast): a
  // found pose is turned to the look-alike nearest the stop's guess (nearest_look_alike).
  std::vector<Eigen::Matrix4d> turns_;
  // The model's samples indexed for nearest-sample queries (nearest_look_alike, nearest_unseen_turn):
  // built once (brute force over 50000 samples was 5 % of an acquisition from 50 mm / 15 degree starts).
  NearestPoints samples_;
  // The free-space check passes at T (check_ holds it) and T does not sink into the known support.
  bool verified(const DepthImage& frame, const Eigen::Matrix4d& T);
  // Whether the model at T lies deeper in its known footing than acquisition lets it (footing_height_m).
  bool sunk(const Eigen::Matrix4d& T) const;
  // A guess known to within half the model's size: touching neighbours can be told from the target
  // (clustered apart, and not counted against it by the gate), and the projective tracker goes first.
  bool close_guess(double grow_m) const { return grow_m < 0.5 * model_radius_m_; }
  // T, or the pose nearest `guess` among those that look like T on the faces the camera sees.
  Eigen::Matrix4d nearest_guess(const DepthImage& frame, const Eigen::Matrix4d& T, const Eigen::Matrix4d& guess) const;
  // The frame without the known floor and, with grow_m, cropped to the silhouette at `from` grown by it.
  DepthImage near_guess(const DepthImage& frame, const Eigen::Matrix4d& from, const Known& known,
                        std::optional<double> grow_m) const;
  // The target is at T (tracked, refined or found): the sample to publish.
  PoseSample found(const DepthImage& frame, const Eigen::Matrix4d& T, double inlier_ratio, double rmse_mm);

  std::optional<PoseSample> track(const DepthImage& frame);
  // Whether frames came and went since the target was last found (the worker was busy): it may have
  // moved farther than between two frames.
  bool dropped_frames(const DepthImage& frame) const;
  std::optional<PoseSample> search(const DepthImage& frame, const assets::Image* colour);
  // The pose a search found, moved by colour where depth allows (and then held); false when its
  // colours disagree.
  bool coloured(const DepthImage& frame, const assets::Image* colour, Eigen::Matrix4d& T);
  std::optional<Eigen::Matrix4d> hold_;  // where colour placed the target, while it stays still
  // r moved by colour where depth allows, and refused when colour disagrees (see acquire).
  void by_colour(const DepthImage& frame, const Known& known, const assets::Image& colour, AlignmentResult& r) const;
  std::optional<AlignmentResult> attempt(const DepthImage& frame, const Eigen::Matrix4d& from, SearchStage stage,
                                         std::optional<ThreadCpuClock::time_point> deadline = std::nullopt);
  /// The first search from a new guess: acquire() from guess_, with what is known (or found) of its support.
  std::optional<AlignmentResult> first_acquisition(const DepthImage& frame, const assets::Image* colour);
};

}  // namespace projbot::alignment
