#pragma once
// Internal to the twin's tour: how its projector frames are measured. Each frame's error at the markers
// (of the pose drawn, or of where a blank frame's last lit pose would have put the light), the
// neighbours' lit frames, and a visit's timeline summed up.

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

#include "projbot/alignment/tracker_worker.hpp"
#include "projbot/live/projection_frames.hpp"
#include "projbot/live/stop_sequence.hpp"
#include "projbot/robot/pan_tilt.hpp"
#include "projbot/twin/display_error.hpp"
#include "projbot/twin/tour.hpp"
#include "projbot/twin/world.hpp"
#include "sim_clock_devices.hpp"

namespace projbot::twin::detail {

// A neighbour lit with the visited target (issue 11, item 5): what the projector draws for it, and the
// error of its lit frames so far.
struct NeighbourLight {
  std::size_t target = 0;  // index into Twin::targets()
  alignment::PoseSample drawn;
  bool shown = false;
  double sum_mm = 0.0;     // over the lit frames with a marker in the light...
  int measured = 0;        // ...this many
  NeighbourReport report;  // frames, lit_frames and worst_mm counted as the frames come
};

// Eq. 1's guess against the truth: how far off it is (cm, degrees).
std::pair<double, double> guess_error(const robot::HeadPoses& truth, const TwinTarget& t, const Eigen::Matrix4d& guess);

// A neighbour's report after the stop: the mean over its lit frames added.
NeighbourReport finished(const NeighbourLight& l);

// What a dwell's projector frames are measured against (measure_frame, measure_neighbour).
struct DwellContext {
  Twin& twin;
  std::size_t target;
  const ProjectorModels& models;
  const robot::HeadPoses& truth;
  const TourOptions& options;
  std::vector<NeighbourLight>& neighbours;
};

// Where a frame puts the target's light: at the pose it draws, or in a blank frame where the last pose lit
// would have put it at the display time (camera frame).
Eigen::Matrix4d light_pose(const live::DrawnPose* drawn, const alignment::PoseSample& last_lit, double display_s, bool predict);

// The error of one projector frame, against the target's true pose at the frame's display time: of the
// pose drawn (`drawn`), or for a blank frame of where the last pose lit (`last_lit`) would have put the light.
TimelineSample measure_frame(const DwellContext& c, const VisitReport& r, double display_s, const live::DrawnPose* drawn,
                             const alignment::PoseSample& last_lit);

// A neighbour's projector frame: counted, and the error of the pose drawn measured when it is lit
// (neighbours stand still: their motion scripts run on their own visits).
void measure_neighbour(const DwellContext& c, NeighbourLight& n, const live::DrawnPose* drawn);

// A visit's figures from its frames' timeline: the means and p95 while moving and still, the blank frames
// while moving, the longest time to light a target again once lost, the pose ages at display.
void summarise_timeline(VisitReport& r);

// A neighbour at arrival: acquired from the stop's capture (and colour) from its own Eq. 1 guess, as
// the visited target is (its tracker's acquisition), and its error at the markers measured.
NeighbourLight neighbour_light(const Twin& twin, const Acquired& a, std::size_t target, const live::LitTarget& n,
                               const robot::HeadPoses& truth, const ProjectorModels& models);

// A motion's scored frames as one (TourOptions::appearance): each figure the mean over the frames that
// saw the target, the worst frame's PSNR, how many were scored.
AppearanceSample mean_appearance(const std::vector<AppearanceSample>& samples);

}  // namespace projbot::twin::detail
