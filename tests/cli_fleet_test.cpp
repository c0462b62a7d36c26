// The fleet's bus (issue 69, item 1) through the executable: `run --sim --fleet r1` publishes its pose and
// state on DDS under ROS 2's names, at least five times a second, read here by a participant of the
// test's own; killed, its liveliness is lost within the lease; bad names and domains are refused.

#include <dds/dds.h>
#include <gtest/gtest.h>
#include <signal.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <set>
#include <string>

#include "cli_fixture.hpp"
#include "dds_loopback.hpp"
#include "ros2_base.h"  // the types robot/ generates from robot/idl/ros2_base.idl

using namespace cli_fixture;

namespace {

// A participant of the test's with a reader on each of the robot's topics.
struct FleetListener {
  dds_entity_t participant = 0, pose = 0, state = 0;
  explicit FleetListener(int domain) {
    participant = dds_create_participant(static_cast<dds_domainid_t>(domain), nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
    pose = dds_create_reader(
        participant, dds_create_topic(participant, &geometry_msgs_msg_dds__PoseStamped__desc, "rt/r1/pose", nullptr, nullptr),
        qos, nullptr);
    state = dds_create_reader(
        participant, dds_create_topic(participant, &projbot_msgs_msg_dds__RobotState__desc, "rt/r1/state", nullptr, nullptr), qos,
        nullptr);
    dds_delete_qos(qos);
  }
  ~FleetListener() { dds_delete(participant); }
  FleetListener(const FleetListener&) = delete;
  FleetListener& operator=(const FleetListener&) = delete;

  // Every sample waiting on `reader`, each given to `use`; how many.
  template <typename Sample, typename Use>
  int take(dds_entity_t reader, Use&& use) {
    int n = 0;
    for (;;) {
      void* samples[1] = {nullptr};
      dds_sample_info_t info[1];
      const dds_return_t got = dds_take(reader, samples, info, 1, 1);
      if (got <= 0) return n;
      if (info[0].valid_data) use(*static_cast<const Sample*>(samples[0])), ++n;
      dds_return_loan(reader, samples, got);
    }
  }
  int alive_writers(dds_entity_t reader) const {
    dds_liveliness_changed_status_t s{};
    dds_get_liveliness_changed_status(reader, &s);
    return static_cast<int>(s.alive_count);
  }
};

}  // namespace

TEST_F(CliTest, RunPublishesItsPoseAndStateOnTheFleetsBus) {
  use_loopback_dds();
  const int domain = 100 + static_cast<int>(::getpid() % 100);  // tests running beside it keep to their own
  FleetListener bus(domain);
  Background run({"run", "--sim", "--headless", "--depth-model", "kinect", "--seconds", "20", "--fleet", "r1", "--fleet-domain",
                  std::to_string(domain)},
                 dir_ / "run.log");
  ASSERT_TRUE(run.wait_for_output("fleet: r1 on DDS domain " + std::to_string(domain) + " (rt/r1/pose, rt/r1/state)",
                                  std::chrono::seconds(60)))
      << run.output();
  // Heard from at all (discovery takes a moment), then counted over 4 s.
  std::set<std::string> phases;
  int poses = 0, states = 0;
  bool named = true, in_room = true;
  const auto listen = [&] {
    states += bus.take<projbot_msgs_msg_dds__RobotState_>(bus.state, [&](const projbot_msgs_msg_dds__RobotState_& s) {
      phases.insert(s.phase);
      named = named && std::string(s.robot) == "r1" && std::string(s.header.frame_id) == "map";
    });
    poses += bus.take<geometry_msgs_msg_dds__PoseStamped_>(bus.pose, [&](const geometry_msgs_msg_dds__PoseStamped_& p) {
      const auto& q = p.pose.orientation;
      in_room = in_room && p.pose.position.x >= 0.0 && p.pose.position.x <= 8.0 && p.pose.position.y >= 0.0 &&
                p.pose.position.y <= 6.0 && std::abs(q.z * q.z + q.w * q.w - 1.0) < 1e-9;
    });
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (states == 0 && std::chrono::steady_clock::now() < deadline) {
    listen();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GT(states, 0) << run.output();
  states = poses = 0;
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(4)) {
    listen();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::cout << "heard " << states << " states and " << poses << " poses in 4 s\n";
  EXPECT_GE(states, 10) << "states in 4 s (5 Hz is 20; 10 leaves room for a loaded machine)";
  EXPECT_GE(poses, 10) << "poses in 4 s";
  EXPECT_TRUE(named);
  EXPECT_TRUE(in_room);
  for (const std::string& p : phases)
    EXPECT_TRUE(std::set<std::string>({"starting", "driving", "acquiring", "lit"}).count(p)) << p;
  ASSERT_EQ(bus.alive_writers(bus.state), 1);

  // Killed: no goodbye, and the others learn it from the lease (1 s) within 3 s.
  run.signal_and_wait(SIGKILL, std::chrono::seconds(10));
  const auto killed = std::chrono::steady_clock::now();
  while (bus.alive_writers(bus.state) > 0 && std::chrono::steady_clock::now() - killed < std::chrono::seconds(3))
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(bus.alive_writers(bus.state), 0);
  EXPECT_EQ(bus.alive_writers(bus.pose), 0);
}

TEST_F(CliTest, RunRefusesAFleetNameOrDomainItCannotUse) {
  for (const std::string bad : {"--fleet 1r", "--fleet r-1", "--fleet r1 --fleet-domain 233", "--fleet-domain 3"}) {
    const CliRun r = run_projbot("run --sim --headless --seconds 1 " + bad);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find(bad.find("domain") != std::string::npos ? "--fleet-domain" : "--fleet "), std::string::npos)
        << r.output;
  }
  const std::string tour = shipped_scene("tour.yaml");
  const fs::path far = write("far.yaml", tour + "fleet: {name: r1, domain: 999}\n");
  const CliRun domain = run_projbot("run --sim --headless --seconds 1 --config " + far.string());
  EXPECT_EQ(domain.code, 1) << domain.output;
  EXPECT_NE(domain.output.find("fleet.domain"), std::string::npos) << domain.output;
  const fs::path named = write("named.yaml", tour + "fleet: {name: \"two words\"}\n");
  const CliRun name = run_projbot("run --sim --headless --seconds 1 --config " + named.string());
  EXPECT_EQ(name.code, 2) << name.output;
  EXPECT_NE(name.output.find("fleet.name in " + named.string() + ": two words"), std::string::npos) << name.output;
}
