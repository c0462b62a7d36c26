// The acquisition (TargetFollower's search for a target from a guess): what is near the guess, projective
// and point-to-plane ICP on it, the candidates around a gross guess, the polish and colour's placing.
// TargetFollower's tracking and search policy are in target_follower.cpp, the worker thread in tracker_worker.cpp.

#include <algorithm>
#include <chrono>
#include <cmath>

#include "projbot/alignment/coarse_search.hpp"
#include "projbot/alignment/equations.hpp"
#include "projbot/alignment/target_follower.hpp"
#include "projbot/alignment/verification.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/stop_request.hpp"

namespace projbot::alignment {
namespace {

// Past the deadline, or a stop asked of the process: either ends the search (what was found is judged).
bool out_of_time(const std::optional<ThreadCpuClock::time_point>& deadline) {
  return ThreadCpuClock::past(deadline) || config::stop_requested();
}

// How far the model's centroid c moves between poses A and B (a symmetric shape's equivalent poses
// share it).
double centre_move_m(const Eigen::Vector3d& c, const Eigen::Matrix4d& A, const Eigen::Matrix4d& B) {
  return ((A - B).topLeftCorner<3, 3>() * c + (A - B).topRightCorner<3, 1>()).norm();
}

}  // namespace

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
  r.time_ms = config::ms_since(t0);
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
  if (out_of_time(known.deadline)) return r;
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
  Known known;
  known.floor = footing.floor, known.footing = footing, known.deadline = acquire_deadline();
  return acquire_known(frame, guess, known, grow_m, colour);
}

AlignmentResult TargetFollower::acquire(const DepthImage& frame, const Eigen::Matrix4d& guess, const GuessError& error,
                                        const assets::Image* colour) const {
  const auto deadline = acquire_deadline();  // the support's search counts against the budget too
  const double grow_m = guess_reach_m(model_, error.move_m, error.turn_deg);
  const std::optional<Footing> support = support_in_frame(model_, frame, k_, guess, grow_m);
  Known known;
  if (support) known.floor = support->floor, known.footing = support;
  known.deadline = deadline, known.frame_support = true, known.bound = bound_of(guess, error.move_m, error.turn_deg);
  return acquire_known(frame, guess, known, grow_m, colour);
}

AlignmentResult TargetFollower::acquire_known(const DepthImage& frame, const Eigen::Matrix4d& guess, const Known& given,
                                              double grow_m, const assets::Image* colour) const {
  AlignmentResult r = searched(frame, guess, given, grow_m, colour);
  // Where colour cannot say how far the target is turned about an axis its view leaves free (a plain
  // mug with its handle hidden), the guess does: ICP's turn there follows noise and neighbours.
  if (r.converged && !(colour && colour_contrast_))
    r.T_scan_model = nearest_unseen_turn(model_, r.T_scan_model, guess, frame, k_, &samples_);
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
  if (r.converged || !coarse || out_of_time(given.deadline)) return r;
  double spent_ms = r.time_ms;
  if (auto again = from_candidates(frame, guess, given, grow_m, colour)) {
    spent_ms += again->time_ms;
    if (again->converged || out_of_time(given.deadline)) {
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
    if ((best || found) && out_of_time(given.deadline)) break;
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
    if (r.converged && (beyond_bound(given, r.T_scan_model) || hidden(frame, r.T_scan_model))) r.converged = false;
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

bool TargetFollower::beyond_bound(const Known& known, const Eigen::Matrix4d& T) const {
  return known.bound && centre_move_m(model_centre_, known.bound->guess, T) > known.bound->centre_m + cfg_.reach_margin_m;
}

bool TargetFollower::hidden(const DepthImage& frame, const Eigen::Matrix4d& T) const {
  // From 50 mm / 15 degree starts on the real YCB-V frames the marker was fitted into the box behind it
  // (90 mm off: 0.67 of its outline flush, 0.30 of it behind the marker itself) and the wood block under
  // what it carries (21 mm off: 0.61 and 0.29); of 1733 right estimates none passed both (the wood block,
  // carrying a box and a banana, 0.47 and 0.43; the potted meat can packed among its neighbours, 0.65
  // and 0.01). With the support found on every third pixel, the marker was fitted into a surface
  // 99 mm off with all of its outline flush (nothing in front): embedded. Of about 500 right estimates
  // from 50 mm / 15 degree starts none had more than 0.61 of its outline flush.
  const FreeSpaceCheck c = verify(frame, T, true);
  return (c.flush_ratio() > cfg_.hidden_flush_ratio && c.in_front_ratio() > cfg_.hidden_front_ratio) ||
         c.flush_ratio() > cfg_.embedded_flush_ratio;
}

TargetFollower::Known::Bound TargetFollower::bound_of(const Eigen::Matrix4d& guess, double move_m, double turn_deg) const {
  // The bound is the centroid's, not the silhouette's reach: a turn about the centroid does not move it
  // (with the reach, 50 mm / 15 degree starts on the real YCB-V frames lit the potted meat can and the
  // banana on a neighbour 82-88 mm from the start's centroid).
  return {guess, move_m + 2.0 * std::sin(std::min(turn_deg, 180.0) * M_PI / 360.0) * model_centre_.norm()};
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
      // A stated guess says how far off it may be: an estimate whose centre lies farther than its error
      // lets the centre move is something else that fits (from 50 mm / 15 degree guesses on the real
      // YCB-V frames, a can fitted onto the box beside it, 167 mm away, with 0.88 of its points explained
      // and nothing seen through it). The centre, not every point: a symmetric shape (a can turned about
      // its axis) is right in any of its equivalent poses.
      if (r.converged && beyond_bound(known, r.T_scan_model)) r.converged = false;
      return r;
    }
    if (out_of_time(known.deadline)) {  // out of time to place it another way: not confirmed
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

}  // namespace projbot::alignment
