#pragma once
// A robot of the fleet on the DDS bus (issue 69, item 1). Under its name's namespace, in ROS 2's wire
// conventions (topic "rt/NAME/...", type "package::msg::dds_::Type_"), so a ROS 2 tool on the same domain
// reads the standard ones:
//
//   rt/NAME/pose       geometry_msgs/msg/PoseStamped, frame "map": where the robot believes it is
//   rt/NAME/state      projbot_msgs RobotState: phase, visited target, visit, frame rate, blackout, paused,
//                      and each drawn target's pose in the map with the tracker's quality
//   rt/NAME/projector  geometry_msgs/msg/PoseStamped, frame "map": the projector's pose while lit
//   rt/NAME/found      projbot_msgs TargetFound, keyed by target: the newest estimate of each target it
//                      found, kept for robots that join later (transient-local)
//
// and reads the coordinator's plan (rt/fleet/plan) for the targets it is to visit, and every robot's
// estimates (their rt/NAME/state, found through DDS discovery) for where the targets are.
//
// pose and state at least five times a second (the show's state as the render thread publishes it, and
// again when none newer came in 0.2 s), the projector's at about the camera's rate (30 Hz). Reliable, the newest kept; DDS
// liveliness (automatic, a 1 s lease) tells the others when the robot is gone, even killed. Its own thread: the engine never
// waits on the bus.

#include <cstddef>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "projbot/live/show_control.hpp"
#include "projbot/live/stop_sequence.hpp"

namespace projbot::fleet {

struct FleetError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct FleetConfig {
  std::string name;  ///< the robot's name in the fleet: a ROS 2 namespace ([A-Za-z][A-Za-z0-9_]*, <= 64)
  int domain = 0;    ///< the DDS domain, 0..232
};

/// Whether `name` may name a fleet robot; empty when it may, else why not.
std::string fleet_name_problem(const std::string& name);

/// How long a robot the bus hears nothing from is alive: the writers' liveliness lease.
constexpr double kLivelinessLeaseS = 1.0;

class FleetMember {
 public:
  /// Joins the domain and starts publishing. Throws FleetError naming the name or the domain when it cannot.
  FleetMember(live::ShowControl& show, FleetConfig config);
  ~FleetMember();
  FleetMember(const FleetMember&) = delete;
  FleetMember& operator=(const FleetMember&) = delete;
  const FleetConfig& config() const;
  std::size_t published() const;  ///< states published (each with its pose where one is known)
  /// This robot's targets in the coordinator's newest plan (rt/fleet/plan), in order, as scene indices (a
  /// name the scene lacks, or a target without a stop, left out); nullopt while no plan was heard. A robot
  /// whose coordinator is gone keeps the last plan.
  std::optional<std::vector<int>> planned_targets() const;
  /// Where the newest estimate any robot on the bus published (this one's included) places scene target
  /// `target`, and whose it was; nullopt before any. For the next stop's Eq. 1 guess (live::MapPoses).
  std::optional<live::MapPose> map_pose(int target) const;
  std::size_t plans_heard() const;  ///< plans that changed this robot's list

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::fleet
