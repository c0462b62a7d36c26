#include "projbot/alignment/tracker_worker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "projbot/alignment/equations.hpp"

namespace projbot::alignment {
namespace {

// The tracker's second try on a frame where it lost the target: correspondences up to reach_m apart.
TrackerConfig wide(const WorkerConfig& c) {
  TrackerConfig t = c.tracking;
  t.max_distance_m = std::max(t.max_distance_m, c.reach_m);
  t.iterations = std::vector<int>(t.iterations.size(), 8);
  return t;
}

// The polish's settings: the silhouette's edges only where colour will not place the model next (the
// edges' pull along the face-on box's one visible side cost it: 2 of 50 from 5 cm guesses ended 3 mm
// or 0.5 degrees off, one from a gross guess lit 10 mm off; bench acquire).
TrackerConfig polish(const WorkerConfig& c, bool colour_contrast) {
  TrackerConfig t = c.tracking;
  t.edge_weight = colour_contrast ? 0.0 : c.polish_edge_weight;
  return t;
}

// How far the model's centroid c moves between poses A and B (a symmetric shape's equivalent poses
// share it).
double centre_move_m(const Eigen::Vector3d& c, const Eigen::Matrix4d& A, const Eigen::Matrix4d& B) {
  return ((A - B).topLeftCorner<3, 3>() * c + (A - B).topRightCorner<3, 1>()).norm();
}

// A sample at rest: the motion to draw it with is the pose itself.
PoseSample still_sample(const Eigen::Matrix4d& T, double capture_time_s, bool lost, double inlier_ratio, double rmse_mm) {
  PoseSample s;
  s.T_camera_target = s.motion.T = T;
  s.capture_time_s = s.motion.time_s = capture_time_s;
  s.lost = lost;
  s.inlier_ratio = inlier_ratio;
  s.rmse_mm = rmse_mm;
  return s;
}

}  // namespace

TargetFollower::TargetFollower(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : model_(model),
      colour_contrast_(has_colour_contrast(model_)),
      aligner_(model, config.acquisition),
      tracker_(model, intrinsics, config.tracking),
      wide_tracker_(model, intrinsics, wide(config)),
      polish_tracker_(std::move(model), intrinsics, polish(config, colour_contrast_)),
      k_(intrinsics),
      cfg_(std::move(config)),
      filter_(cfg_.motion),
      silhouette_grow_m_(guess_reach_m(model_, cfg_.guess_uncertainty_m, cfg_.guess_uncertainty_deg)),
      model_radius_m_(guess_reach_m(model_, 0.0, 60.0)),  // a 60 degree turn moves the farthest point by the radius
      model_centre_(centroid_of(model_)),
      turns_(colour_contrast_ ? box_turns(model_) : std::vector<Eigen::Matrix4d>{}) {}

Eigen::Matrix4d TargetFollower::nearest_guess(const DepthImage& frame, const Eigen::Matrix4d& T,
                                              const Eigen::Matrix4d& guess) const {
  return nearest_look_alike(model_, T, guess, turns_, frame, k_);
}

void TargetFollower::set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing) {
  set_initial_guess(T_camera_target, footing.floor);
  known_.footing = footing;
}

void TargetFollower::set_initial_guess(const Eigen::Matrix4d& T_camera_target, const std::optional<Plane>& floor) {
  guess_ = T_camera_target;
  known_ = Known{floor, std::nullopt, std::nullopt};
  find_support_ = !floor;  // no map: the first search looks for what the target rests on in the frame
  map_floor_ = floor.has_value();
  have_guess_ = true;
  pose_.reset();
  rejected_ = 0;
  lost_reported_ = false;
  wait_ = 0;
  stats_ = {};
  search_attempts_ = 0;
  second_passes_ = 0;
  last_attempt_.reset();
  filter_.reset();
  hold_.reset();
}

void TargetFollower::set_pose(const Eigen::Matrix4d& T_camera_target) {
  set_initial_guess(T_camera_target);
  pose_ = T_camera_target;
}

FreeSpaceCheck TargetFollower::verify(const DepthImage& frame, const Eigen::Matrix4d& T_camera_target) const {
  return check_free_space(model_, T_camera_target, frame, k_);
}

bool TargetFollower::verified(const DepthImage& frame, const Eigen::Matrix4d& T) {
  check_ = verify(frame, T);
  return passes(check_);
}

PoseSample TargetFollower::found(const DepthImage& frame, const Eigen::Matrix4d& T, double inlier_ratio, double rmse_mm) {
  pose_ = T;
  rejected_ = 0;
  lost_reported_ = false;
  last_found_s_ = frame.capture_time_s;
  PoseSample sample = still_sample(T, frame.capture_time_s, false, inlier_ratio, rmse_mm);
  filter_.update(T, frame.capture_time_s);
  if (cfg_.predict) sample.motion = filter_.state();
  return sample;
}

std::optional<PoseSample> TargetFollower::step(const DepthImage& frame, const assets::Image* colour) {
  if (!have_guess_ && !pose_) return std::nullopt;  // nothing to start from yet
  return pose_ ? track(frame) : search(frame, colour);
}

bool TargetFollower::coloured(const DepthImage& frame, const assets::Image* colour, Eigen::Matrix4d& T) {
  hold_.reset();
  if (!colour) return true;
  AlignmentResult r;
  r.T_scan_model = T;
  r.converged = true;
  by_colour(frame, known_, *colour, r);
  stats_.colour_shift_mm = r.colour_shift_mm;
  stats_.colour_agreement = r.colour_agreement;
  if (!r.converged) return false;
  hold_ = r.T_scan_model;
  T = r.T_scan_model;
  return true;
}

DepthImage TargetFollower::near_guess(const DepthImage& frame, const Eigen::Matrix4d& from, const Known& known,
                                      std::optional<double> grow_m) const {
  // The floor is known (map and camera pose): left out, so a figure standing on it is aligned to and
  // judged on its own points. With the target's footing, so is what it stands on: what lies below the
  // surveyed height of its lowest point (a table's top, a pedestal's sides). A neighbour that touches
  // the crop is left out by clustering (crop_to_silhouette), for a guess known to within half the
  // model's size.
  // Both are cuts below one horizontal plane: one pass, at the higher of the two.
  double cut_m = known.footing && !known.footing->upright_known ? cfg_.frame_support_margin_m : cfg_.floor_margin_m;
  if (known.footing && known.footing->height_m > cut_m) cut_m = std::max(cut_m, known.footing->height_m + cfg_.support_margin_m);
  DepthImage left = known.floor ? without_plane(frame, k_, *known.floor, cut_m) : frame;
  if (grow_m) left = crop_to_silhouette(left, k_, model_, from, *grow_m, cfg_.cluster_neighbours && close_guess(*grow_m));
  return left;
}

AlignmentResult TargetFollower::recropped(const DepthImage& frame, const AlignmentResult& r, const Known& known,
                                          SearchStage stage, bool hold) const {
  // The guess's crop, grown by all of its uncertainty, takes in what stands beside the target (the
  // shop's shelf beside the figure's hand), and that pulls ICP: from 10-degree guesses the figure
  // settled 11-19 mm sideways and failed the gate. Cropped again at the estimate, grown only by
  // recrop_m, most of it is left out, and ICP from the estimate settles on the target's own points.
  const PointCloud tight = depth_to_cloud(near_guess(frame, r.T_scan_model, known, cfg_.recrop_m), k_);
  if (tight.finite_count() < aligner_.config().min_points) return r;
  // From a converged estimate only ICP's finest stage: the coarse ones would find it where it is.
  AlignmentResult again = aligner_.align(tight, r.T_scan_model, r.converged ? SearchStage::finish : stage, known.footing, hold,
                                         known.deadline, known.close);
  again.iterations += r.iterations;
  again.time_ms += r.time_ms;
  return again.converged || !r.converged ? again : r;
}

std::optional<AlignmentResult> TargetFollower::projective_first(const DepthImage& frame, const DepthImage& near,
                                                                const Eigen::Matrix4d& guess, const Known& known,
                                                                bool hold) const {
  const auto t0 = std::chrono::steady_clock::now();
  Eigen::Matrix4d T = guess;
  for (int pass = 0; pass < 2; ++pass) T = wide_tracker_.track(near, T).T_camera_target;  // accepted or not: the gate judges
  if (!T.allFinite()) return std::nullopt;
  const PointCloud tight = depth_to_cloud(near_guess(frame, T, known, cfg_.recrop_m), k_);
  if (tight.finite_count() < aligner_.config().min_points) return std::nullopt;
  AlignmentResult r = aligner_.align(tight, T, SearchStage::finish, known.footing, hold, known.deadline, known.close);
  if (!r.converged) return std::nullopt;
  // Without colour, the projective association settled up to a degree turned along a weak direction,
  // which ICP's finest stage keeps: ICP coarse to fine then (a box-only shop, 5 cm / 10 degree guesses:
  // 80 % within 3 mm and 0.5 degrees without this check, 90 % with it, 97 % always coarse to fine; a
  // firmer threshold, 0.05, sent the figure and duck the slow way too).
  if (!hold && !view_constraints(model_, r.T_scan_model, k_).weak.empty()) return std::nullopt;
  r.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

AlignmentResult TargetFollower::align_near(const DepthImage& frame, const DepthImage& near_depth, const PointCloud& near,
                                           const Eigen::Matrix4d& guess, const Known& known, double grow_m, SearchStage stage,
                                           Weak weak) const {
  // Where the view leaves a direction weak (a box seen face-on), ICP's finest stage crept along it for
  // all its 40 iterations (300-500 ms of the shop box's acquisition) to no better place: with colour to
  // place it after, held.
  const bool hold = weak != Weak::depth;
  // Too little near the guess: the aligner's error says so.
  if (!(grow_m > cfg_.recrop_m) || near.finite_count() < aligner_.config().min_points)
    return aligner_.align(near, guess, stage, known.footing, hold, known.deadline, known.close);
  // The projective tracker's association reaches a 5 cm / 10 degree guess in a few passes of a few ms;
  // ICP's coarse stages took 0.5-1.5 s of the shop figure's acquisition for the same estimate.
  // Only from a guess known to within half the model's size: from a gross one it could settle on a box's
  // other face, which stands as surveyed too.
  if (close_guess(grow_m) && weak != Weak::coarse_colour)
    if (auto fast = projective_first(frame, near_depth, guess, known, hold)) return *fast;
  // ICP from the guess and the refine on the tighter crop: the restarts and the global search of
  // `stage` only when that fails.
  // (Bounded when `stage` is: a tracking-mode search runs one attempt per frame.)
  const SearchStage first = stage == SearchStage::full ? SearchStage::icp_only : SearchStage::refine;
  AlignmentResult r =
      recropped(frame, aligner_.align(near, guess, first, known.footing, hold, known.deadline, known.close), known, first, hold);
  if (r.converged || stage == SearchStage::refine || stage == SearchStage::icp_only) return r;
  if (ThreadCpuClock::past(known.deadline)) return r;
  AlignmentResult wider =
      recropped(frame, aligner_.align(near, guess, stage, known.footing, hold, known.deadline, known.close), known, first, hold);
  wider.iterations += r.iterations;
  wider.time_ms += r.time_ms;
  return wider;
}

ThreadCpuClock::time_point TargetFollower::acquire_deadline() const {
  return ThreadCpuClock::now() + std::chrono::microseconds(static_cast<long long>(1000.0 * cfg_.acquire_budget_ms));
}

AlignmentResult TargetFollower::acquire(const DepthImage& frame, const Eigen::Matrix4d& guess, const Footing& footing,
                                        double grow_m, const assets::Image* colour) const {
  return acquire_known(frame, guess, Known{footing.floor, footing, acquire_deadline()}, grow_m, colour);
}

AlignmentResult TargetFollower::acquire(const DepthImage& frame, const Eigen::Matrix4d& guess, double grow_m,
                                        const assets::Image* colour) const {
  const auto deadline = acquire_deadline();  // the support's search counts against the budget too
  const std::optional<Footing> support = support_in_frame(model_, frame, k_, guess, grow_m);
  return acquire_known(frame, guess,
                       Known{support ? std::optional<Plane>(support->floor) : std::nullopt, support, deadline, false, true},
                       grow_m, colour);
}

AlignmentResult TargetFollower::acquire_known(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& given,
                                              double grow_m, const assets::Image* colour) const {
  AlignmentResult r = searched(frame, guess, given, grow_m, colour);
  // Where colour cannot say how far the target is turned about an axis its view leaves free (a plain
  // mug with its handle hidden), the guess does: ICP's turn there follows noise and neighbours.
  if (r.converged && !(colour && colour_contrast_))
    r.T_scan_model = nearest_unseen_turn(model_, r.T_scan_model, guess, frame, k_);
  return r;
}

AlignmentResult TargetFollower::searched(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& given, double grow_m,
                                         const assets::Image* colour) const {
  const bool coarse = cfg_.coarse_search && grow_m <= cfg_.coarse_max_reach_m;
  if (coarse && !close_guess(grow_m))
    if (auto r = from_candidates(frame, guess, given, grow_m, colour)) return *r;
  // A close guess: ICP from it; where that fails (the mug pulled onto its neighbours, 2 in 20 from 20 mm /
  // 5 degree starts on the real frames), the candidates around it, then the restarts and global search.
  AlignmentResult r = acquire_at(frame, guess, given, grow_m, colour, coarse ? SearchStage::icp_only : SearchStage::full);
  if (r.converged || !coarse || ThreadCpuClock::past(given.deadline)) return r;
  double spent_ms = r.time_ms;
  if (auto again = from_candidates(frame, guess, given, grow_m, colour)) {
    spent_ms += again->time_ms;
    if (again->converged || ThreadCpuClock::past(given.deadline)) {
      again->time_ms = spent_ms;
      return *again;
    }
  }
  // The restarts and global search last, their deadline a tenth of the budget early: the stage running
  // at the deadline finishes (the wood block, refused, took 1556 ms of a 1500 ms budget).
  Known last = given;
  if (given.deadline)
    last.deadline = *given.deadline - std::chrono::microseconds(static_cast<long long>(100.0 * cfg_.acquire_budget_ms));
  AlignmentResult wide = acquire_at(frame, guess, last, grow_m, colour);
  wide.time_ms += spent_ms;
  return wide;
}

std::optional<AlignmentResult> TargetFollower::from_candidates(const DepthImage& frame, const Eigen::Matrix4d& guess,
                                                               const Known& given, double grow_m,
                                                               const assets::Image* colour) const {
  CoarseSearch search = cfg_.coarse;
  search.reach_m = grow_m;
  // Each candidate is a close guess: off by at most about a grid step and a turn. ICP from it alone, no
  // restarts or global search: the candidates are the search (with them, 50 mm / 15 degree starts on
  // the real frames were lit wrong 3 times in 260 and took up to 1.6 s; without, none and 0.74 s).
  const double close_grow = std::min(guess_reach_m(model_, search.grid_step_m(), search.turn_deg), 0.49 * model_radius_m_);
  std::optional<AlignmentResult> best, found;
  double spent_ms = 0.0, found_move_m = 0.0;
  for (const auto& c : coarse_candidates(model_, guess, frame, k_, search)) {
    if ((best || found) && ThreadCpuClock::past(given.deadline)) break;
    // Without a map, the support is the one under the candidate: under a gross guess's wider reach
    // another plane may qualify (a neighbour's top) that the target does not stand on.
    Known known = given;
    if (given.frame_support) {
      const std::optional<Footing> support = support_in_frame(model_, frame, k_, c.T_camera_model, close_grow);
      known.floor = support ? std::optional<Plane>(support->floor) : std::nullopt;
      known.footing = support;
    }
    AlignmentResult r = acquire_at(frame, c.T_camera_model, known, close_grow, colour, SearchStage::icp_only);
    spent_ms += r.time_ms;
    r.time_ms = spent_ms;
    if (r.converged && beyond_bound(guess, r.T_scan_model, grow_m)) r.converged = false;
    // The nearest the guess of those that converge: from 50 mm / 15 degree starts the potted meat can
    // was fitted onto its look-alike neighbour (3 in 20, 116-119 mm off) by a candidate scored first.
    if (r.converged) {
      const double move_m = centre_move_m(model_centre_, guess, r.T_scan_model);
      if (!found || move_m < found_move_m) found = r, found_move_m = move_m;
      if (move_m <= cfg_.nearest_candidate_share * grow_m) break;
      continue;
    }
    if (!best || r.inlier_ratio > best->inlier_ratio) best = r;
  }
  if (found) best = found;
  if (best) best->time_ms = spent_ms;
  return best;
}

bool TargetFollower::beyond_bound(const Eigen::Matrix4d& guess, const Eigen::Matrix4d& T, double grow_m) const {
  return cfg_.guess_bounds_estimate && centre_move_m(model_centre_, guess, T) > grow_m + cfg_.reach_margin_m;
}

AlignmentResult TargetFollower::acquire_at(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& given,
                                           double grow_m, const assets::Image* colour, SearchStage stage) const {
  Known known = given;
  known.close = close_guess(grow_m);
  const DepthImage near = near_guess(frame, guess, known, grow_m);
  const PointCloud near_cloud = depth_to_cloud(near, k_);
  // Colour places what ICP held, where the model has colours to place it by (not the figure's one grey
  // material). Where it cannot (from a 5 cm guess the projective association once left the face-on
  // box's slide 5 cm off, beyond colour's reach): ICP coarse to fine, its finest stage still held, then
  // depth alone.
  Weak weak = colour && colour_contrast_ ? Weak::colour : Weak::depth;
  for (;;) {
    AlignmentResult r = acquired(frame, near, near_cloud, guess, known, grow_m, weak, stage);
    if (!r.converged) return r;
    if (colour) by_colour(frame, known, *colour, r);  // last: the polish is depth alone and would undo it
    if (weak == Weak::depth || !r.weak_held || r.colour_agreement >= cfg_.min_held_colour_agreement) {
      // From a gross guess the search may find the textured box turned 180 degrees onto a face that
      // shows the same texture (2 of 50 in bench acquire): the seen faces cannot tell, the guess can.
      if (r.converged) r.T_scan_model = nearest_guess(frame, r.T_scan_model, guess);
      // The guess says how far off it may be: an estimate whose centre lies farther than any point of
      // the model may move is something else that fits (from 50 mm / 15 degree guesses on the real YCB-V
      // frames, a can fitted onto the box beside it, 167 mm away, with 0.88 of its points explained and
      // nothing seen through it). The centre, not every point: a symmetric shape (a can turned about its
      // axis) is right in any of its equivalent poses.
      if (r.converged && beyond_bound(guess, r.T_scan_model, grow_m)) r.converged = false;
      return r;
    }
    if (ThreadCpuClock::past(known.deadline)) {  // out of time to place it another way: not confirmed
      r.converged = false;
      return r;
    }
    // A view without contrast (agreement NaN) goes straight to depth alone: colour will not say there.
    weak = weak == Weak::colour && std::isfinite(r.colour_agreement) ? Weak::coarse_colour : Weak::depth;
  }
}

AlignmentResult TargetFollower::acquired(const DepthImage& frame, const DepthImage& near, const PointCloud& near_cloud,
                                         const Eigen::Matrix4d& guess, const Known& known, double grow_m, Weak weak,
                                         SearchStage stage) const {
  AlignmentResult r = align_near(frame, near, near_cloud, guess, known, grow_m, stage, weak);
  if (!r.converged) return r;
  // The polish: projective association, which a touching neighbour pulls less; held sideways by the
  // silhouette's edges where the model has no colours to place it by (the figure).
  const Eigen::Matrix4d before = r.T_scan_model;
  for (int i = 0; i < 3; ++i) {
    const TrackResult t = polish_tracker_.track(frame, r.T_scan_model);
    if (!t.accepted) break;
    r.T_scan_model = t.T_camera_target;
  }
  if (!polish_kept(frame, known, before, r.T_scan_model)) r.T_scan_model = before;
  return r;
}

bool TargetFollower::polish_kept(const DepthImage& frame, const Known& known, const Eigen::Matrix4d& before,
                                 const Eigen::Matrix4d& after) const {
  // Judged as ICP's estimate was: on real frames the silhouette's edges are ragged (a third of the pixels
  // around an object missing, the IR shadow on one side: bench sensor) and the polish turned the mug
  // 16 degrees up off its table, into free space (0.01 -> 0.26 of its silhouette seen through).
  if (before == after) return true;
  const double was = verify(frame, before).behind_ratio();
  if (verify(frame, after).behind_ratio() > std::max(was, 0.5 * cfg_.max_behind_ratio)) return false;
  if (!known.footing) return true;
  const PointCloud tight = depth_to_cloud(near_guess(frame, after, known, cfg_.recrop_m), k_);
  return tight.finite_count() >= aligner_.config().min_points &&
         aligner_.score(tight, after, known.footing, known.close).converged;
}

void TargetFollower::by_colour(const DepthImage& frame, const Known& known, const assets::Image& colour,
                               AlignmentResult& r) const {
  // Colour may move the pose only where depth does not object: on the duck, which depth pins, colour's
  // best agreement lay 2.7-3.3 mm off in 2 of 20 captures, and the depth RMSE grew 45-65 % there; along
  // the face-on box's face it changed by under 2 %. Judged against the pose colour started from.
  std::optional<PointCloud> tight;
  AlignmentResult before;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  // A search that ran out of reach (the shop box's projective start left it 26 mm along its face, and
  // the pose there was 1.4-2.8 mm and up to 0.55 degrees off, agreement 0.94-0.97 where the others reach
  // 0.99): once more from where it got to, its colours sampled where the pose now stands.
  for (int pass = 0; pass < 2; ++pass) {
    const ColourRefinement c = colour_refined(model_, r.T_scan_model, frame, colour, k_);
    if (pass == 0) r.colour_agreement = c.agreement_before;
    if (!c.moved()) break;
    if (!tight) {
      tight = depth_to_cloud(near_guess(frame, r.T_scan_model, known, cfg_.recrop_m), k_);
      before = aligner_.score(*tight, r.T_scan_model, std::nullopt, known.close);
    }
    const AlignmentResult after = aligner_.score(*tight, c.T_camera_model, std::nullopt, known.close);
    if (!(after.rmse_mm <= before.rmse_mm * (1.0 + cfg_.colour_max_rmse_growth) &&
          after.inlier_ratio >= before.inlier_ratio - 0.02))
      break;
    r.T_scan_model = c.T_camera_model;
    shift += c.shift_m;
    r.colour_shift_mm = 1000.0 * shift.norm();
    r.colour_agreement = c.agreement_after;
    if (!c.out_of_reach) break;
  }
  // A pose whose colours disagree with the image is not the target's, however well the depth fits.
  if (std::isfinite(r.colour_agreement) && r.colour_agreement < cfg_.min_colour_agreement) r.converged = false;
}

std::optional<AlignmentResult> TargetFollower::attempt(const DepthImage& frame, const Eigen::Matrix4d& from, SearchStage stage) {
  // Acquisition from a guess looks near it: only at what lies inside its silhouette, grown by its
  // uncertainty (a wall behind, a neighbour beside drop out). Global stages search wider on purpose, and
  // a refine after dropped frames starts from a pose the target may have left by more than that.
  const auto grow_m = stage == SearchStage::local ? std::optional<double>(silhouette_grow_m_) : std::nullopt;
  if (find_support_ && grow_m) {  // as acquire() without a map does
    find_support_ = false;
    known_.frame_support = true;
    if (const auto support = support_in_frame(model_, frame, k_, from, *grow_m))
      known_.floor = support->floor, known_.footing = support;
  }
  const DepthImage near = near_guess(frame, from, known_, grow_m);
  const PointCloud scan = depth_to_cloud(near, k_);
  if (scan.finite_count() < aligner_.config().min_points) return std::nullopt;
  Known known = known_;
  known.close = grow_m && close_guess(*grow_m);
  last_attempt_ = grow_m ? align_near(frame, near, scan, from, known, *grow_m, stage, Weak::depth)
                         : aligner_.align(scan, from, stage, known_.footing);
  return last_attempt_;
}

std::optional<AlignmentResult> TargetFollower::first_acquisition(const DepthImage& frame, const assets::Image* colour) {
  const auto deadline = acquire_deadline();  // the support's search counts against the budget, as in acquire()
  if (find_support_) {
    find_support_ = false;
    known_.frame_support = true;
    if (const auto support = support_in_frame(model_, frame, k_, guess_, silhouette_grow_m_))
      known_.floor = support->floor, known_.footing = support;
  }
  Known known = known_;
  known.deadline = deadline;
  try {
    last_attempt_ = acquire_known(frame, guess_, known, silhouette_grow_m_, colour);
  } catch (const AlignmentError&) {  // too little depth near the guess (an absent target): as attempt() says
    return std::nullopt;
  }
  return last_attempt_;
}

std::optional<PoseSample> TargetFollower::track(const DepthImage& frame) {
  // A moving target is looked for where its motion has taken it by this frame's capture: 1 m/s is
  // 3.3 cm between 30 Hz frames, most of the tracker's reach from the last pose.
  const Eigen::Matrix4d start = cfg_.predict ? filter_.predict(frame.capture_time_s) : *pose_;
  const TrackResult r = tracker_.track(frame, start, hold_ ? &*hold_ : nullptr);
  if (r.accepted && verified(frame, r.T_camera_target)) {
    PoseSample s = found(frame, r.T_camera_target, r.inlier_ratio, r.rmse_mm);
    // Colour's placement holds while the target stays where it was placed.
    if (hold_) {
      const Eigen::Matrix4d moved = rigid_inverse(*hold_) * r.T_camera_target;
      if (filter_.state().moving() || translation_norm_m(moved) > cfg_.hold_release_m ||
          rotation_angle_deg(moved) > cfg_.hold_release_deg)
        hold_.reset();
    }
    return s;
  }
  hold_.reset();  // tracking lost it on this frame: whatever finds it again is depth alone
  // The target moved more than tracking follows: once more on this same frame with a wider reach
  // (reach_m), a few milliseconds. Only when frames were dropped since the last pose (the worker was
  // busy, the target may be far from it) one ICP from there as well: on consecutive frames that ICP
  // (over a second on a full frame) kept a target that had been carried away lit all that time.
  ++second_passes_;
  const TrackResult w = wide_tracker_.track(frame, start);
  if (w.accepted && verified(frame, w.T_camera_target)) return found(frame, w.T_camera_target, w.inlier_ratio, w.rmse_mm);
  if (frame.capture_time_s - last_found_s_ > 2.5 / cfg_.camera_hz) {
    const auto a = attempt(frame, start, SearchStage::refine);
    if (a && a->converged && verified(frame, a->T_scan_model)) return found(frame, a->T_scan_model, a->inlier_ratio, a->rmse_mm);
  }
  if (++rejected_ < cfg_.lost_after) return std::nullopt;  // one bad frame: keep showing the last pose
  // Lost: blank it now and search from where it was last seen, or where its motion was taking it.
  guess_ = start;
  pose_.reset();
  filter_.reset();
  wait_ = 0;
  search_attempts_ = 0;  // a new search: from the first stage, the first one an acquisition
  if (!map_floor_) {     // a support found in an earlier frame is where it was then: the camera may have moved
    known_ = Known{};
    find_support_ = true;
  }
  lost_reported_ = true;
  return still_sample(guess_, frame.capture_time_s, true, w.inlier_ratio, w.rmse_mm);
}

std::optional<PoseSample> TargetFollower::search(const DepthImage& frame, const assets::Image* colour) {
  if (wait_ > 0) {
    --wait_;
    ++stats_.frames_waited;
    return std::nullopt;
  }
  static constexpr SearchStage kEscalation[] = {SearchStage::local, SearchStage::global_near, SearchStage::global_wide};
  // Without global re-initialisation (AcquisitionConfig::reinitialise) every attempt is a local one.
  const SearchStage stage = aligner_.config().reinitialise ? kEscalation[search_attempts_ % 3] : SearchStage::local;
  const auto t0 = std::chrono::steady_clock::now();
  const auto elapsed = [&] {
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++stats_.attempts;
    ++search_attempts_;
    stats_.last_attempt_ms = ms;
    stats_.total_ms += ms;
    stats_.max_attempt_ms = std::max(stats_.max_attempt_ms, ms);
  };
  // The projective tracker from the guess first: a few ms, and enough when Eq. 1's guess is right to a
  // centimetre (a localised robot's is). Trusted only when it barely had to move the guess and agrees
  // almost everywhere: from a guess 10 cm off it once settled half-way with 80 % inliers.
  const TrackResult quick = tracker_.track(frame, guess_);
  const Eigen::Matrix4d correction = rigid_inverse(guess_) * quick.T_camera_target;
  Eigen::Matrix4d T = quick.T_camera_target;
  if (quick.accepted && quick.inlier_ratio >= 0.95 && translation_norm_m(correction) < 0.02 &&
      rotation_angle_deg(correction) < 3.0 && verified(frame, T) && check_.behind_ratio() < 0.05 && coloured(frame, colour, T)) {
    elapsed();
    return found(frame, T, quick.inlier_ratio, quick.rmse_mm);
  }
  // Depth alone here: one bounded attempt per frame, and a held pose colour cannot place would cost a
  // second one in the same frame (acquire() holds weak directions for colour).
  const bool acquiring = search_attempts_ == 0 && cfg_.first_search_acquires;
  const auto a = acquiring ? first_acquisition(frame, colour) : attempt(frame, guess_, stage);
  elapsed();
  if (acquiring && a && a->converged && verified(frame, T = a->T_scan_model)) {  // colour and the look-alike turn done
    hold_.reset();
    if (colour && std::isfinite(a->colour_agreement)) hold_ = T;
    stats_.colour_shift_mm = a->colour_shift_mm;  // as coloured() reports it on the other paths
    stats_.colour_agreement = a->colour_agreement;
    return found(frame, T, a->inlier_ratio, a->rmse_mm);
  }
  if (!acquiring && a && a->converged && verified(frame, T = a->T_scan_model) && coloured(frame, colour, T)) {
    T = nearest_guess(frame, T, guess_);  // a look-alike turn, as in acquire()
    if (hold_) hold_ = T;
    return found(frame, T, a->inlier_ratio, a->rmse_mm);
  }
  const auto& spacing = cfg_.search_spacing_frames;
  if (!spacing.empty()) wait_ = spacing[std::min(static_cast<std::size_t>(search_attempts_ - 1), spacing.size() - 1)];
  const double last_ms = stats_.last_attempt_ms;
  if (cfg_.search_duty > 0.0 && cfg_.search_duty < 1.0)
    wait_ = std::max(wait_, static_cast<int>(std::ceil(last_ms * (1.0 / cfg_.search_duty - 1.0) * cfg_.camera_hz / 1000.0)));
  if (lost_reported_) return std::nullopt;
  lost_reported_ = true;  // not found at this stop yet: say so once, so the renderer blanks it
  return still_sample(guess_, frame.capture_time_s, true, a ? a->inlier_ratio : 0.0, a ? a->rmse_mm : 0.0);
}

TrackerWorker::TrackerWorker(ModelCloud model, CameraIntrinsics intrinsics, WorkerConfig config)
    : follower_(std::move(model), intrinsics, std::move(config)), thread_([this](std::stop_token stop) { run(stop); }) {}

TrackerWorker::~TrackerWorker() {
  thread_.request_stop();
  wake_.notify_all();
}  // jthread joins

std::uint64_t TrackerWorker::post(std::shared_ptr<const DepthImage> frame) {
  std::uint64_t ticket = 0;
  {
    std::lock_guard lock(mutex_);
    inbox_ = std::move(frame);  // a frame not yet taken is dropped: only the newest matters
    ticket = ++submitted_;
  }
  wake_.notify_one();
  return ticket;
}

void TrackerWorker::submit(std::shared_ptr<const DepthImage> frame) { post(std::move(frame)); }

std::optional<PoseSample> TrackerWorker::track(std::shared_ptr<const DepthImage> frame) {
  const std::uint64_t ticket = post(std::move(frame));
  std::unique_lock lock(mutex_);
  done_.wait(lock, [&] { return finished_ >= ticket || error_; });
  if (error_) std::rethrow_exception(error_);
  return finished_sample_;
}

void TrackerWorker::set_initial_guess(const Eigen::Matrix4d& T_camera_target) {
  if (!T_camera_target.allFinite()) throw AlignmentError("initial guess is not finite");
  std::lock_guard lock(mutex_);
  guess_ = Start{T_camera_target, std::nullopt, nullptr};
}

void TrackerWorker::set_initial_guess(const Eigen::Matrix4d& T_camera_target, const Footing& footing,
                                      std::shared_ptr<const assets::Image> colour) {
  if (!T_camera_target.allFinite()) throw AlignmentError("initial guess is not finite");
  std::lock_guard lock(mutex_);
  guess_ = Start{T_camera_target, footing, std::move(colour)};
}

std::exception_ptr TrackerWorker::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void TrackerWorker::run(std::stop_token stop) {
  std::uint64_t sequence = 0;
  std::shared_ptr<const assets::Image> colour;  // the stop's arrival colour, until its first frame
  std::uint64_t ticket = 0;                     // the frame taken: the submitted_ count when it was
  try {
    while (!stop.stop_requested()) {
      std::shared_ptr<const DepthImage> frame;
      {
        std::unique_lock lock(mutex_);
        if (!wake_.wait(lock, stop, [&] { return inbox_ != nullptr || guess_.has_value(); })) break;
        if (guess_) {  // a new stop: acquire afresh from Eq. 1's guess
          if (guess_->footing)
            follower_.set_initial_guess(guess_->T_camera_target, *guess_->footing);
          else
            follower_.set_initial_guess(guess_->T_camera_target);
          colour = std::move(guess_->colour);
          guess_.reset();
        }
        frame = std::move(inbox_);
        ticket = submitted_;
      }
      if (!frame) continue;
      ++processed_;
      // The arrival's colour serves the stop's first frame only: later the projector lights the target.
      auto sample = follower_.step(*frame, colour.get());
      colour.reset();
      if (sample) {
        sample->sequence = ++sequence;
        poses_.publish(*sample);
      }
      {
        std::lock_guard lock(mutex_);
        finished_ = ticket;
        finished_sample_ = sample;
      }
      done_.notify_all();
    }
  } catch (...) {
    {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
    }
    done_.notify_all();
    PoseSample lost = still_sample(follower_.last_pose(), 0.0, true, 0.0, 0.0);  // the renderer blanks the target
    lost.sequence = ++sequence;
    poses_.publish(lost);
  }
}

}  // namespace projbot::alignment
