#pragma once
// ROS 2's conventions on the DDS wire, for the translation units that speak it (the ROS 2 base's and the
// fleet's): topic names and time stamps. The message types themselves are idlc's, from
// robot/idl/ros2_base.idl; nothing here includes them.

#include <cmath>
#include <cstdint>
#include <string>

namespace projbot::robot {

/// ROS 2 topic "cmd_vel" (or "/cmd_vel") on the DDS wire: "rt/cmd_vel".
inline std::string wire_topic(const std::string& ros_name) {
  return "rt/" + (!ros_name.empty() && ros_name.front() == '/' ? ros_name.substr(1) : ros_name);
}

/// A builtin_interfaces/msg/Time (any generated Time_: sec, nanosec) of `t_s` seconds.
template <typename Time>
Time ros_time(double t_s) {
  Time t{};
  const double whole = std::floor(t_s);
  t.sec = static_cast<std::int32_t>(whole);
  t.nanosec = static_cast<std::uint32_t>((t_s - whole) * 1e9);
  return t;
}

}  // namespace projbot::robot
