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

// A drive's steps on the wall clock at rate_hz: the newest odometry and a scan matched against the map
// (with a laser) every control period.
class Ros2Navigator::Steps final : public DriveSteps {
 public:
  explicit Steps(Ros2Navigator& navigator)
      : n_(navigator),
        period_(std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(1.0 / navigator.rate_hz_))),
        tick_(std::chrono::steady_clock::now()),
        t0_(config::steady_now_s()),
        last_change_(t0_),
        last_step_(t0_) {}
  void sense(long) override {
    n_.fresh(last_change_);
    n_.correct(last_change_, corrections);  // the laser's scan waits at most one of its periods (40 Hz: 25 ms)
  }
  Pose2D believed_pose() const override { return n_.believed_pose(); }
  double step_s() override {
    const double now = config::steady_now_s(), dt = now - last_step_;
    last_step_ = now;
    return dt;
  }
  double elapsed_s() const override { return config::steady_now_s() - t0_; }
  void command(const BaseTwist& twist) override {
    n_.base_.send(twist);
    std::this_thread::sleep_until(tick_ += period_);
  }
  void halt() override { n_.base_.send({}); }
  void settle() override {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let it stop, then read where it stands
    n_.fresh(last_change_);
    for (int i = 0; i < n_.settle_scans_ && n_.laser_; ++i) n_.correct(last_change_, corrections);  // the stop's best fix
  }
  Corrections corrections;

 private:
  Ros2Navigator& n_;
  std::chrono::steady_clock::duration period_;
  std::chrono::steady_clock::time_point tick_;
  double t0_, last_change_, last_step_;
};

StopReport Ros2Navigator::drive_to(const Pose2D& goal, int index) {
  StopReport r;
  r.index = index;
  r.goal = goal;
  Steps steps(*this);
  r.arrived = drive_loop(controller_, steps, goal, timeout_s_, watch_);
  r.drive_seconds = steps.elapsed_s();
  r.estimate = believed_pose();
  r.odometry = compose(T_map_odom_start_, last_.pose);
  r.corrections = steps.corrections.count;
  r.rejected = steps.corrections.rejected;
  r.correct_ms_mean = steps.corrections.count > 0 ? steps.corrections.ms / steps.corrections.count : 0.0;
  return r;
}

}  // namespace projbot::robot
