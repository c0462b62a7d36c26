#include <chrono>
#include <thread>

#include "projbot/robot/ros2_base.hpp"

namespace projbot::robot {
namespace {
double steady_s() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }
}  // namespace

Ros2Navigator::Ros2Navigator(Ros2Base& base, const Pose2D& start_in_map, const ControllerConfig& controller, double rate_hz,
                             double timeout_s)
    : base_(base), controller_(controller), rate_hz_(rate_hz), timeout_s_(timeout_s), last_(base.odometry(2.0)) {
  T_map_odom_ = compose(start_in_map, inverse(last_.pose));  // the robot stands at start_in_map now
}

// The newest odometry; throws when its stamp has not moved for a second (the driver stopped).
Odometry2D Ros2Navigator::fresh(double& last_change_s) {
  const Odometry2D o = base_.odometry(1.0);
  const double now = steady_s();
  if (o.stamp_s != last_.stamp_s) last_change_s = now;
  if (now - last_change_s > 1.0) {
    base_.send({});
    throw RobotError(base_.name() + ": odometry stopped while driving (no new message for 1 s): the base was stopped");
  }
  last_ = o;
  return o;
}

StopReport Ros2Navigator::drive_to(const Pose2D& goal, int index) {
  StopReport r;
  r.index = index;
  r.goal = goal;
  controller_.reset();
  const double t0 = steady_s();
  double last_change = t0, last_step = t0;
  const auto period = std::chrono::duration<double>(1.0 / rate_hz_);
  for (auto tick = std::chrono::steady_clock::now();;
       tick += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period)) {
    std::this_thread::sleep_until(tick);
    fresh(last_change);
    const double now = steady_s();
    const BaseTwist cmd = controller_.update(believed_pose(), goal, now - last_step);
    last_step = now;
    if (controller_.arrived() || now - t0 > timeout_s_) break;
    base_.send(cmd);
  }
  base_.send({});
  r.arrived = controller_.arrived();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let it stop, then read where it stands
  fresh(last_change);
  r.drive_seconds = steady_s() - t0;
  r.estimate = r.odometry = believed_pose();
  return r;
}

}  // namespace projbot::robot
