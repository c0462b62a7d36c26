// The fleet's plan (issue 69, item 2) without a bus: path lengths on the room's floor, every target with a
// stop given to exactly one robot, the work shared, the same plan whatever order the robots were heard in.

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "projbot/fleet/plan.hpp"

using namespace projbot;

namespace {

// A 10 x 4 m room; a wall from the floor's bottom edge to 1 m short of its top at x = 5 (a door at the top).
config::Scene room_with_a_wall() {
  config::Scene s;
  s.room.width_m = 10.0;
  s.room.depth_m = 4.0;
  s.room.obstacles = {{4.9, 0.0, 5.1, 3.0}};
  return s;
}

void add_target(config::Scene& s, const std::string& name, double x, double y) {
  config::TargetConfig t;
  t.name = name;
  t.stop = Eigen::Vector3d(x, y, 0.0);
  s.targets.push_back(t);
}

}  // namespace

TEST(FleetPlan, PathsGoAroundObstacles) {
  const config::Scene s = room_with_a_wall();
  const fleet::FloorMap floor(s);
  const std::vector<double> from = floor.lengths_from({2.0, 1.0});
  // Straight across is 6 m; through the door above the wall (its end at y 3 grown by 0.3 m) about 7.6 m.
  const double across = floor.length_to(from, {8.0, 1.0});
  EXPECT_GT(across, 7.0);
  EXPECT_LT(across, 8.5);
  EXPECT_NEAR(floor.length_to(from, {4.0, 1.0}), 2.0, 0.15);  // on the same side: straight
  EXPECT_FALSE(floor.free({5.0, 1.0}));
  EXPECT_TRUE(floor.free({5.0, 3.6}));
}

TEST(FleetPlan, EachTargetGoesToOneRobotAndTheWorkIsShared) {
  config::Scene s = room_with_a_wall();
  add_target(s, "a", 1.5, 2.0);
  add_target(s, "b", 3.0, 2.0);
  add_target(s, "c", 7.0, 2.0);
  add_target(s, "d", 8.5, 2.0);
  config::TargetConfig no_stop;  // surveyed only: nobody's to visit
  no_stop.name = "shelf";
  s.targets.push_back(no_stop);
  const fleet::FloorMap floor(s);
  const fleet::Plan plan = fleet::make_plan(s, floor, {{"west", {1.0, 1.0}}, {"east", {9.0, 1.0}}});
  ASSERT_EQ(plan.targets_of.size(), 2U);
  EXPECT_EQ(plan.targets_of.at("west"), (std::vector<std::string>{"a", "b"}));  // each on its side, nearest first
  EXPECT_EQ(plan.targets_of.at("east"), (std::vector<std::string>{"d", "c"}));
  EXPECT_TRUE(plan.unreachable.empty());
  // The same robots heard in another order: the same plan.
  EXPECT_EQ(fleet::make_plan(s, floor, {{"east", {9.0, 1.0}}, {"west", {1.0, 1.0}}}), plan);
  // One robot left: all four are its, nothing twice.
  const fleet::Plan alone = fleet::make_plan(s, floor, {{"east", {9.0, 1.0}}});
  const std::vector<std::string>& all = alone.targets_of.at("east");
  EXPECT_EQ(all.size(), 4U);
  EXPECT_EQ(std::set<std::string>(all.begin(), all.end()).size(), 4U);
}

TEST(FleetPlan, ATargetNoRobotCanReachIsSaid) {
  config::Scene s = room_with_a_wall();
  s.room.obstacles = {{4.9, 0.0, 5.1, 4.0}};  // the wall now closes the room in two
  add_target(s, "near", 2.0, 2.0);
  add_target(s, "beyond", 8.0, 2.0);
  const fleet::FloorMap floor(s);
  const fleet::Plan plan = fleet::make_plan(s, floor, {{"r1", {1.0, 1.0}}});
  EXPECT_EQ(plan.targets_of.at("r1"), (std::vector<std::string>{"near"}));
  EXPECT_EQ(plan.unreachable, (std::vector<std::string>{"beyond"}));
  // No robot heard: nothing assigned, nothing called unreachable.
  const fleet::Plan nobody = fleet::make_plan(s, floor, {});
  EXPECT_TRUE(nobody.targets_of.empty());
  EXPECT_TRUE(nobody.unreachable.empty());
}
