#include "projbot/fleet/fleet_member.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "bus.hpp"
#include "projbot/robot/ros2_wire.hpp"

namespace projbot::fleet {
namespace {

builtin_interfaces_msg_dds__Time_ now_stamp() {  // ROS 2 stamps with the system clock
  const double t_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  return robot::ros_time<builtin_interfaces_msg_dds__Time_>(t_s);
}

// The generated types hold C strings; the messages are written before these strings change.
char* c_str(const std::string& s) { return const_cast<char*>(s.c_str()); }

geometry_msgs_msg_dds__Pose_ ros_pose(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  geometry_msgs_msg_dds__Pose_ p{};
  p.position = {T.translation().x(), T.translation().y(), T.translation().z()};
  p.orientation = {q.x(), q.y(), q.z(), q.w()};
  return p;
}

// How long a robot listens for another one of its name before it joins: discovery on a network takes a
// few hundred milliseconds, and a robot publishes its state at least five times a second.
constexpr double kNameCheckS = 1.5;

// The projector's pose goes out at about the camera's rate while lit (a neighbour blends against it).
constexpr int kProjectorPeriodMs = 33;
constexpr double kStatePeriodS = 0.2;  // the state again when none newer came in this long

}  // namespace

std::string fleet_name_problem(const std::string& name) {
  if (name.empty()) return "it is empty";
  if (name.size() > 64) return "it is longer than 64 characters";
  if (!std::isalpha(static_cast<unsigned char>(name.front()))) return "it must begin with a letter";
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      return "it may hold letters, digits and '_' only (a ROS 2 namespace)";
  return {};
}

struct FleetMember::Impl {
  FleetConfig config;
  live::ShowControl& show;
  dds_entity_t participant = 0, pose_writer = 0, state_writer = 0, projector_writer = 0, found_writer = 0, plan_reader = 0;
  std::atomic<std::size_t> published{0};
  const std::string process = wire::host_and_pid();
  dds_entity_t publications = 0;                 // DDS discovery: the robots on the bus
  std::map<std::string, dds_entity_t> finds;     // each robot's found targets (this one's too), by name
  std::mutex mutex;                              // what the robot thread reads: under it, the next three
  std::optional<std::vector<std::string>> mine;  // this robot's part of the newest plan
  std::size_t plans_heard = 0;
  struct Heard {
    live::MapPose pose;
    double stamp_s = -1.0;  // when it was found, on the finder's clock
  };
  std::map<std::string, Heard> heard;  // the newest estimate of each target heard, by name
  std::jthread thread;

  Impl(live::ShowControl& s, FleetConfig c) : config(std::move(c)), show(s) {}
  ~Impl() {
    thread = {};  // stopped and joined before the participant goes
    if (participant > 0) dds_delete(participant);
  }

  void check(dds_return_t rc, const std::string& what) const {
    if (rc < 0) throw FleetError("fleet robot " + config.name + ": " + what + ": " + dds_strretcode(rc));
  }

  dds_entity_t writer(const dds_topic_descriptor_t* type, const std::string& topic, const dds_qos_t* qos) {
    const dds_entity_t t = dds_create_topic(participant, type, topic.c_str(), nullptr, nullptr);
    check(t, "cannot create topic " + topic);
    const dds_entity_t w = dds_create_writer(participant, t, qos, nullptr);
    check(w, "cannot create a writer on " + topic);
    return w;
  }

  // Before it writes anything: another robot already publishing under this name is named, and refused.
  void refuse_a_taken_name() {
    const dds_entity_t reader =
        wire::newest_reader(participant, &projbot_msgs_msg_dds__RobotState__desc, robot::wire_topic(config.name + "/state"));
    std::string taken;
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(kNameCheckS);
    while (taken.empty() && std::chrono::steady_clock::now() < until) {
      wire::take_each<projbot_msgs_msg_dds__RobotState_>(reader, [&taken](const projbot_msgs_msg_dds__RobotState_& s) {
        taken = s.process != nullptr && s.process[0] != '\0' ? s.process : "a process that does not say";
      });
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    dds_delete(reader);
    if (!taken.empty())
      throw FleetError("fleet name '" + config.name + "' is taken on DDS domain " + std::to_string(config.domain) +
                       ": a robot of that name runs at " + taken + " (give this one another --fleet name)");
  }

  void open() {
    participant = dds_create_participant(static_cast<dds_domainid_t>(config.domain), nullptr, nullptr);
    check(participant, "cannot join DDS domain " + std::to_string(config.domain));
    refuse_a_taken_name();
    dds_qos_t* qos = dds_create_qos();
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, DDS_MSECS(static_cast<int>(1000 * kLivelinessLeaseS)));
    try {
      pose_writer = writer(&geometry_msgs_msg_dds__PoseStamped__desc, robot::wire_topic(config.name + "/pose"), qos);
      state_writer = writer(&projbot_msgs_msg_dds__RobotState__desc, robot::wire_topic(config.name + "/state"), qos);
      projector_writer = writer(&geometry_msgs_msg_dds__PoseStamped__desc, robot::wire_topic(config.name + "/projector"), qos);
    } catch (...) {
      dds_delete_qos(qos);
      throw;
    }
    dds_delete_qos(qos);
    const dds_entity_t plan =
        dds_create_topic(participant, &projbot_msgs_msg_dds__FleetPlan__desc, wire::kPlanTopic.c_str(), nullptr, nullptr);
    check(plan, "cannot create topic " + wire::kPlanTopic);
    dds_qos_t* plan_qos = wire::plan_qos(0);
    plan_reader = dds_create_reader(participant, plan, plan_qos, nullptr);
    dds_delete_qos(plan_qos);
    check(plan_reader, "cannot read " + wire::kPlanTopic);
    publications = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    check(publications, "cannot read the domain's publications");
    dds_qos_t* kept = wire::found_qos();
    const std::string topic = robot::wire_topic(config.name + "/found");
    const dds_entity_t t =
        dds_create_topic(participant, &projbot_msgs_msg_dds__TargetFound__desc, topic.c_str(), nullptr, nullptr);
    found_writer = t < 0 ? t : dds_create_writer(participant, t, kept, nullptr);
    dds_delete_qos(kept);
    check(found_writer, "cannot create a writer on " + topic);
  }

  dds_entity_t found_reader(const std::string& robot_name) {
    const std::string topic = robot::wire_topic(robot_name + "/found");
    const dds_entity_t t =
        dds_create_topic(participant, &projbot_msgs_msg_dds__TargetFound__desc, topic.c_str(), nullptr, nullptr);
    check(t, "cannot create topic " + topic);
    dds_qos_t* kept = wire::found_qos();
    const dds_entity_t r = dds_create_reader(participant, t, kept, nullptr);
    dds_delete_qos(kept);
    check(r, "cannot read " + topic);
    return r;
  }

  // Every robot's newest estimate of each target it found (this robot's own among them, and those found
  // before this robot joined: transient-local): the newest of a target places it for the next stop's
  // guess (what one robot learns, the others use).
  void hear_estimates() {
    for (const std::string& name : wire::robots_found(publications))
      if (!finds.count(name)) finds[name] = found_reader(name);
    for (const auto& [robot_name, reader] : finds)
      wire::take_each<projbot_msgs_msg_dds__TargetFound_>(reader, [this,
                                                                   &robot_name](const projbot_msgs_msg_dds__TargetFound_& f) {
        Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
        T.translation() = Eigen::Vector3d(f.pose.position.x, f.pose.position.y, f.pose.position.z);
        T.linear() = Eigen::Quaterniond(f.pose.orientation.w, f.pose.orientation.x, f.pose.orientation.y, f.pose.orientation.z)
                         .normalized()
                         .toRotationMatrix();
        // A finder whose clock runs ahead would keep its estimates newest for ever: none later than now.
        const double now_s = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
        const double stamp_s = std::min(f.header.stamp.sec + 1e-9 * f.header.stamp.nanosec, now_s);
        const std::lock_guard lock(mutex);
        Heard& h = heard[f.name];
        if (stamp_s >= h.stamp_s) h = Heard{live::MapPose{T.matrix(), robot_name + "'s estimate"}, stamp_s};
      });
  }

  // The newest plan on the bus, if one came: this robot's part of it kept when it changed.
  void read_plan() {
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      const dds_return_t got = dds_take(plan_reader, samples, info, 1, 1);
      if (got <= 0) return;
      if (info[0].valid_data) {
        const Plan plan = wire::plan_of(*static_cast<const projbot_msgs_msg_dds__FleetPlan_*>(samples[0]));
        const auto it = plan.targets_of.find(config.name);
        std::vector<std::string> part = it == plan.targets_of.end() ? std::vector<std::string>{} : it->second;
        const std::lock_guard lock(mutex);
        if (!mine || *mine != part) mine = std::move(part), ++plans_heard;
      }
      dds_return_loan(plan_reader, samples, got);
    }
  }

  void publish_pose(dds_entity_t to, const geometry_msgs_msg_dds__Pose_& pose) {
    const std::string map = "map";
    geometry_msgs_msg_dds__PoseStamped_ stamped{};
    stamped.header.stamp = now_stamp();
    stamped.header.frame_id = c_str(map);
    stamped.pose = pose;
    dds_write(to, &stamped);
  }

  void publish(const live::ShowState& s) {
    if (s.robot) {
      geometry_msgs_msg_dds__Pose_ pose{};
      pose.position.x = (*s.robot)[0];
      pose.position.y = (*s.robot)[1];
      pose.orientation.z = std::sin(0.5 * (*s.robot)[2]);  // a turn about the map's z axis
      pose.orientation.w = std::cos(0.5 * (*s.robot)[2]);
      publish_pose(pose_writer, pose);
    }
    std::vector<projbot_msgs_msg_dds__TargetEstimate_> estimates;
    for (const live::TargetShowState& t : s.targets)
      if (t.T_map_target) estimates.push_back({c_str(t.name), ros_pose(*t.T_map_target), t.quality});
    const std::string map = "map";
    projbot_msgs_msg_dds__RobotState_ state{};
    state.header.stamp = now_stamp();
    state.header.frame_id = c_str(map);
    state.robot = c_str(config.name);
    state.phase = c_str(s.phase);
    state.target = c_str(s.visiting);
    state.visit = s.visit;
    state.frame_rate_hz = s.frame_rate_hz;
    state.blackout = s.blackout;
    state.paused = s.paused;
    state.estimates._length = state.estimates._maximum = static_cast<std::uint32_t>(estimates.size());
    state.estimates._buffer = estimates.data();
    state.estimates._release = false;
    state.process = c_str(process);
    if (dds_write(state_writer, &state) >= 0) published.fetch_add(1);
    for (const projbot_msgs_msg_dds__TargetEstimate_& e : estimates) {
      const projbot_msgs_msg_dds__TargetFound_ f{state.header, e.name, e.pose, e.quality};
      dds_write(found_writer, &f);
    }
  }

  // The show's state as it comes, and the newest again when none newer came in 0.2 s; while lit, the
  // projector's pose at about the camera's rate.
  void run(const std::stop_token& stop) {
    std::uint64_t sequence = 0;
    auto stated = std::chrono::steady_clock::now() - std::chrono::seconds(1);
    while (!stop.stop_requested()) {
      const std::shared_ptr<const live::ShowState> s = show.wait_newer(sequence, kProjectorPeriodMs);
      read_plan();
      hear_estimates();
      const auto now = std::chrono::steady_clock::now();
      if (s->T_map_projector && s->phase == "lit") publish_pose(projector_writer, ros_pose(*s->T_map_projector));
      if (s->sequence == sequence && now - stated < std::chrono::duration<double>(kStatePeriodS)) continue;
      sequence = s->sequence;
      stated = now;
      publish(*s);
    }
  }
};

FleetMember::FleetMember(live::ShowControl& show, FleetConfig config) : impl_(std::make_unique<Impl>(show, std::move(config))) {
  if (const std::string why = fleet_name_problem(impl_->config.name); !why.empty())
    throw FleetError("fleet name '" + impl_->config.name + "': " + why);
  if (impl_->config.domain < 0 || impl_->config.domain > 232)
    throw FleetError("fleet domain " + std::to_string(impl_->config.domain) + ": a DDS domain is from 0 to 232");
  impl_->open();
  impl_->thread = std::jthread([this](std::stop_token stop) { impl_->run(stop); });
}

FleetMember::~FleetMember() = default;

const FleetConfig& FleetMember::config() const { return impl_->config; }

std::size_t FleetMember::published() const { return impl_->published.load(); }

std::optional<std::vector<int>> FleetMember::planned_targets() const {
  const std::lock_guard lock(impl_->mutex);
  if (!impl_->mine) return std::nullopt;
  const std::vector<live::SiteTarget>& site = impl_->show.targets();
  std::vector<int> out;
  for (const std::string& name : *impl_->mine)
    for (std::size_t i = 0; i < site.size(); ++i)
      if (site[i].name == name && site[i].reachable) out.push_back(static_cast<int>(i));
  return out;
}

std::optional<live::MapPose> FleetMember::map_pose(int target) const {
  const std::vector<live::SiteTarget>& site = impl_->show.targets();
  if (target < 0 || static_cast<std::size_t>(target) >= site.size()) return std::nullopt;
  const std::lock_guard lock(impl_->mutex);
  const auto it = impl_->heard.find(site[static_cast<std::size_t>(target)].name);
  return it == impl_->heard.end() ? std::nullopt : std::optional(it->second.pose);
}

std::size_t FleetMember::plans_heard() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->plans_heard;
}

}  // namespace projbot::fleet
