#include "projbot/fleet/coordinator.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "bus.hpp"
#include "projbot/robot/ros2_wire.hpp"

namespace projbot::fleet {
namespace {

constexpr auto kStep = std::chrono::milliseconds(20);        // how often the bus is read
constexpr auto kRepublish = std::chrono::milliseconds(100);  // the plan again, for a takeover within a lease
constexpr auto kNobodyAfter = std::chrono::seconds(10);      // no robot heard this long: said, once

char* c_str(const std::string& s) { return const_cast<char*>(s.c_str()); }  // written before it changes

// A robot as the coordinator hears it.
struct Heard {
  dds_entity_t state = 0, pose = 0;
  std::optional<std::array<double, 2>> at;
  bool alive = false;
  bool clock_said = false;  // its clock was found out of step and said so
};

// A robot's stamps further than this from the coordinator's clock (beyond the bus's own delay) say its
// clock is off: its estimates' times cannot be compared with the others'.
constexpr double kClockToleranceS = 2.0;

double system_now_s() { return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count(); }

// A robot whose clock is out of step with this one's, said once: "robot r9's clock is 10.0 s ahead ...".
void check_clock(const std::string& name, Heard& h, double stamp_s, const CoordinatorLog& said) {
  const double off_s = stamp_s - system_now_s();
  if (h.clock_said || std::abs(off_s) <= kClockToleranceS) return;
  char text[64];
  std::snprintf(text, sizeof text, "%.1f s %s", std::abs(off_s), off_s > 0 ? "ahead of" : "behind");
  said("robot " + name + "'s clock is " + text + " this coordinator's: the times it stamps (its estimates') are out of step; " +
       "set its clock (NTP)");
  h.clock_said = true;
}

}  // namespace

struct Coordinator::Impl {
  const config::Scene& scene;
  CoordinatorConfig config;
  FloorMap floor;
  dds_entity_t participant = 0, publications = 0, plan_writer = 0;
  std::map<std::string, Heard> robots;
  Plan plan;
  std::uint64_t epoch = 0;

  Impl(const config::Scene& s, CoordinatorConfig c) : scene(s), config(std::move(c)), floor(s) {}
  ~Impl() {
    if (participant > 0) dds_delete(participant);
  }

  void check(dds_return_t rc, const std::string& what) const {
    if (rc < 0) throw FleetError("fleet coordinator: " + what + ": " + dds_strretcode(rc));
  }

  void open() {
    participant = dds_create_participant(static_cast<dds_domainid_t>(config.domain), nullptr, nullptr);
    check(participant, "cannot join DDS domain " + std::to_string(config.domain));
    publications = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    check(publications, "cannot read the domain's publications");
    const dds_entity_t topic =
        dds_create_topic(participant, &projbot_msgs_msg_dds__FleetPlan__desc, wire::kPlanTopic.c_str(), nullptr, nullptr);
    check(topic, "cannot create topic " + wire::kPlanTopic);
    dds_qos_t* qos = wire::plan_qos(config.strength);
    plan_writer = dds_create_writer(participant, topic, qos, nullptr);
    dds_delete_qos(qos);
    check(plan_writer, "cannot create a writer on " + wire::kPlanTopic);
  }

  // Robots whose state writers discovery has found since the last call.
  void discover(const CoordinatorLog& said) {
    for (const std::string& name : wire::robots_found(publications)) {
      if (robots.count(name)) continue;
      Heard& h = robots[name];
      h.state = wire::newest_reader(participant, &projbot_msgs_msg_dds__RobotState__desc, robot::wire_topic(name + "/state"));
      h.pose = wire::newest_reader(participant, &geometry_msgs_msg_dds__PoseStamped__desc, robot::wire_topic(name + "/pose"));
      said("robot " + name + " found on the bus");
    }
  }

  // Each robot's newest pose and whether it is alive; true when the robots a plan counts changed.
  bool listen(const CoordinatorLog& said) {
    bool changed = false;
    for (auto& [name, h] : robots) {
      const bool counted = h.alive && h.at;
      wire::take_each<geometry_msgs_msg_dds__PoseStamped_>(h.pose, [&h](const geometry_msgs_msg_dds__PoseStamped_& p) {
        h.at = std::array<double, 2>{p.pose.position.x, p.pose.position.y};
      });
      wire::take_each<projbot_msgs_msg_dds__RobotState_>(h.state, [&](const projbot_msgs_msg_dds__RobotState_& st) {
        check_clock(name, h, st.header.stamp.sec + 1e-9 * st.header.stamp.nanosec, said);
      });
      dds_liveliness_changed_status_t live{};
      dds_get_liveliness_changed_status(h.state, &live);
      if (h.alive != (live.alive_count > 0)) said("robot " + name + (live.alive_count > 0 ? " is alive" : " is lost"));
      h.alive = live.alive_count > 0;
      changed = changed || counted != (h.alive && h.at.has_value());
    }
    return changed;
  }

  void replan(const CoordinatorLog& said) {
    std::vector<RobotSeen> seen;
    for (const auto& [name, h] : robots)
      if (h.alive && h.at) seen.push_back({name, *h.at});
    Plan next = make_plan(scene, floor, seen);
    if (epoch > 0 && next == plan) return;
    plan = std::move(next);
    ++epoch;
    said("plan " + std::to_string(epoch) + " for " + std::to_string(seen.size()) + " robot(s):\n" + plan_table(plan));
  }

  void publish() {
    std::vector<std::vector<char*>> targets;
    std::vector<projbot_msgs_msg_dds__Assignment_> assignments;
    targets.reserve(plan.targets_of.size());
    for (const auto& [robot, list] : plan.targets_of) {
      std::vector<char*>& names = targets.emplace_back();
      for (const std::string& t : list) names.push_back(c_str(t));
      assignments.push_back(
          {c_str(robot),
           {static_cast<std::uint32_t>(names.size()), static_cast<std::uint32_t>(names.size()), names.data(), false}});
    }
    std::vector<char*> unreachable;
    for (const std::string& t : plan.unreachable) unreachable.push_back(c_str(t));
    projbot_msgs_msg_dds__FleetPlan_ sample{};
    const std::string map = "map";
    const double now_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
    sample.header.stamp = robot::ros_time<builtin_interfaces_msg_dds__Time_>(now_s);
    sample.header.frame_id = c_str(map);
    sample.coordinator = c_str(config.name);
    sample.epoch = epoch;
    sample.assignments = {static_cast<std::uint32_t>(assignments.size()), static_cast<std::uint32_t>(assignments.size()),
                          assignments.data(), false};
    sample.unreachable = {static_cast<std::uint32_t>(unreachable.size()), static_cast<std::uint32_t>(unreachable.size()),
                          unreachable.data(), false};
    dds_write(plan_writer, &sample);
  }
};

Coordinator::Coordinator(const config::Scene& scene, CoordinatorConfig config)
    : impl_(std::make_unique<Impl>(scene, std::move(config))) {
  if (impl_->config.domain < 0 || impl_->config.domain > 232)
    throw FleetError("fleet domain " + std::to_string(impl_->config.domain) + ": a DDS domain is from 0 to 232");
  if (impl_->config.name.empty()) impl_->config.name = wire::host_and_pid();
  impl_->open();
}

Coordinator::~Coordinator() = default;

void Coordinator::run(const std::function<bool()>& stop, const CoordinatorLog& said) {
  impl_->replan(said);  // the plan with no robot: every target waits for one
  const auto started = std::chrono::steady_clock::now();
  auto published = started - kRepublish;
  bool said_alone = false;
  while (!stop()) {
    impl_->discover(said);
    if (!said_alone && impl_->robots.empty() && std::chrono::steady_clock::now() - started > kNobodyAfter) {
      said("no robot heard on DDS domain " + std::to_string(impl_->config.domain) + " in " +
           std::to_string(kNobodyAfter.count()) + " s: robots join with `projbot run --fleet NAME` on the same domain " +
           "(--fleet-domain, or the site file's fleet.domain)");
      said_alone = true;
    }
    if (impl_->listen(said)) impl_->replan(said);
    if (std::chrono::steady_clock::now() - published >= kRepublish) {
      impl_->publish();
      published = std::chrono::steady_clock::now();
    }
    std::this_thread::sleep_for(kStep);
  }
}

std::uint64_t Coordinator::plans() const { return impl_->epoch; }

std::string plan_table(const Plan& plan) {
  std::ostringstream out;
  out << "| robot | targets, in order |\n|---|---|\n";
  for (const auto& [robot, targets] : plan.targets_of) {
    out << "| " << robot << " | ";
    for (std::size_t i = 0; i < targets.size(); ++i) out << (i ? ", " : "") << targets[i];
    out << (targets.empty() ? "(none)" : "") << " |\n";
  }
  if (plan.targets_of.empty()) out << "| (no robot heard) | - |\n";
  if (!plan.unreachable.empty()) {
    out << "\nNo robot can reach:";
    for (const std::string& t : plan.unreachable) out << ' ' << t;
    out << '\n';
  }
  return out.str();
}

}  // namespace projbot::fleet
