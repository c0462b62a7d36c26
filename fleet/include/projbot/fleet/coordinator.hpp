#pragma once
// The fleet's coordinator (`projbot fleet`, issue 69 item 2): hears every robot on the domain (their
// rt/NAME/state writers found through DDS discovery, their poses on rt/NAME/pose), plans which robot
// visits which target (make_plan) whenever a robot joins or is lost (its liveliness, a 1 s lease), and
// publishes the plan on rt/fleet/plan: durable, so a robot that starts late reads it, and exclusively
// owned, so of two coordinators the stronger one's plan is read and the other's once it is gone.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "projbot/config/scene.hpp"
#include "projbot/fleet/fleet_member.hpp"
#include "projbot/fleet/plan.hpp"

namespace projbot::fleet {

struct CoordinatorConfig {
  std::string name;   ///< said in the plan (default: host and process id)
  int domain = 0;     ///< the DDS domain, 0..232
  int strength = 10;  ///< DDS ownership strength: the strongest live coordinator's plan is the one read
};

/// One line about a change: a robot heard or lost, a new plan.
using CoordinatorLog = std::function<void(const std::string&)>;

class Coordinator {
 public:
  /// Joins the domain. Throws FleetError naming the domain when it cannot.
  Coordinator(const config::Scene& scene, CoordinatorConfig config);
  ~Coordinator();
  Coordinator(const Coordinator&) = delete;
  Coordinator& operator=(const Coordinator&) = delete;
  /// Hears the robots and publishes the plan (again every 0.1 s, so a standby takes over at once) until
  /// `stop` says so; `said` gets a line per change.
  void run(const std::function<bool()>& stop, const CoordinatorLog& said);
  std::uint64_t plans() const;  ///< plans made (the epoch of the newest)

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A plan as a Markdown table: robot, targets in order.
std::string plan_table(const Plan& plan);

}  // namespace projbot::fleet
