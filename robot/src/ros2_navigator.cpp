#include <chrono>
#include <thread>

#include "projbot/config/clock.hpp"
#include "projbot/robot/ros2_base.hpp"

namespace projbot::robot {
Ros2Navigator::Ros2Navigator(Ros2Base& base, const Pose2D& start_in_map, const ControllerConfig& controller, double rate_hz,
                             double timeout_s)
    : base_(base),
      controller_(controller),
      settle_scans_(controller.settle_scans),
      rate_hz_(rate_hz),
      timeout_s_(timeout_s),
      last_(base.odometry(2.0)) {
  T_map_odom_ = compose(start_in_map, inverse(last_.pose));  // the robot stands at start_in_map now
  T_map_odom_start_ = T_map_odom_;
}

void Ros2Navigator::use_laser(LaserSource& laser, Localizer* map) {
  laser_ = &laser;
  map_ = map;
  double last_change = config::steady_now_s();
  Corrections c;
  for (int i = 0; i < settle_scans_; ++i) correct(last_change, c);  // a robot set down a few centimetres off its start is found
}

void Ros2Navigator::correct(double& last_change_s, Corrections& c) {
  if (!laser_) return;
  LaserScan scan;
  try {
    scan = laser_->next(0.5);
  } catch (const RobotError&) {
    base_.send({});
    throw;
  }
  fresh(last_change_s);  // the odometry of the scan's moment (the newest, a control step at most after it)
  if (on_scan_) on_scan_(scan, last_.pose);
  if (!map_) return;  // a mapping run: the scans are recorded, odometry alone drives
  map_->reset(believed_pose());
  const LocalizationUpdate u = map_->correct(scan);
  ++c.count;
  c.ms += u.time_ms;
  if (!u.accepted) {
    ++c.rejected;
    return;
  }
  T_map_odom_ = compose(u.pose, inverse(last_.pose));
}

// The newest odometry; throws when its stamp has not moved for a second (the driver stopped).
Odometry2D Ros2Navigator::fresh(double& last_change_s) {
  const Odometry2D o = base_.odometry(1.0);
  const double now = config::steady_now_s();
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
  const double t0 = config::steady_now_s();
  double last_change = t0, last_step = t0;
  Corrections c;
  const auto period = std::chrono::duration<double>(1.0 / rate_hz_);
  for (auto tick = std::chrono::steady_clock::now();;
       tick += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period)) {
    std::this_thread::sleep_until(tick);
    fresh(last_change);
    correct(last_change, c);  // the laser's scan waits at most one of its periods (40 Hz: 25 ms)
    const double now = config::steady_now_s();
    const BaseTwist cmd = controller_.update(believed_pose(), goal, now - last_step);
    last_step = now;
    if (controller_.arrived() || now - t0 > timeout_s_) break;
    base_.send(cmd);
  }
  base_.send({});
  r.arrived = controller_.arrived();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let it stop, then read where it stands
  fresh(last_change);
  for (int i = 0; i < settle_scans_ && laser_; ++i) correct(last_change, c);  // standing still: the stop's best fix
  r.drive_seconds = config::steady_now_s() - t0;
  r.estimate = believed_pose();
  r.odometry = compose(T_map_odom_start_, last_.pose);
  r.corrections = c.count;
  r.rejected = c.rejected;
  r.correct_ms_mean = c.count > 0 ? c.ms / c.count : 0.0;
  return r;
}

}  // namespace projbot::robot
