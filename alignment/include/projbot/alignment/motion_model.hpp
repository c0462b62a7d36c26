#pragma once
// Motion prediction (issue 14): a constant-velocity Kalman filter on SE(3) per target, fed by the
// tracker's accepted poses and their capture times, and the bounded extrapolation that lets the renderer
// draw a moving target where it will be when the projector's frame is displayed, not where it was
// when the depth was captured. Eigen only.
// The filter is not thread-safe (it lives in the tracker thread); MotionState is a plain value handed
// to the render thread with each pose.

#include <Eigen/Core>
#include <deque>

namespace projbot::alignment {

struct MotionModelConfig {
  /// Process noise: white acceleration, as the square root of its spectral density. How quickly the
  /// filter lets a target change speed; tuned in the twin on scripted motions (`projbot bench motion`).
  /// Starts and stops are the maneuver gate's (below), so between them the velocity is nearly constant:
  /// 1.0 let the rate follow the noise of a real sensor's poses (0.13 m/s per axis at 1.7 mm).
  double accel_noise = 0.2;          ///< m s^-1.5
  double angular_accel_noise = 0.6;  ///< rad s^-1.5
  double position_noise_m = 0.0007;  ///< the tracker's pose noise per frame (1 sigma, each axis), at least
  double rotation_noise_rad = 0.002;
  /// The noise is also measured, from the second differences of the last noise_window poses (a steady
  /// motion cancels out of them), and the larger of the two used: a depth camera whose error is smooth
  /// rather than per pixel (KinectNoiseConfig::fitted(), as the real PrimeSense's) moves the tracked pose
  /// by millimetres from frame to frame, which at 0.7 mm read as motion and was extrapolated (the
  /// display tour's duck at rest was drawn 12 mm off on average, 4 mm without prediction). 0: not measured.
  int noise_window = 16;
  /// Once the measured noise is this many times the configured, a still part is drawn at the mean of
  /// the stillness window's poses instead of the newest (one frame's smooth error is not the next one's:
  /// the display tour's duck 1.8-2.2 mm instead of 4.4-5.0 under the fitted depth model). Below it the
  /// newest as measured, bit for bit (a tracker at its configured noise gains nothing from the lag).
  double average_above = 2.0;
  /// A pose this far outside the prediction (normalised innovation squared, 3 degrees of freedom;
  /// 16.3 is the 99.9 % point) means the target started or stopped: the velocity restarts from the
  /// newest two poses instead of coasting on, so a sudden stop overshoots for two frames at most.
  double maneuver_gate = 16.3;
  /// Poses further apart than this restart the filter (dropped frames, a new stop).
  double max_gap_s = 0.25;
  double max_horizon_s = 0.1;     ///< predictions further ahead are held at this horizon
  double max_speed_m_s = 2.0;     ///< faster estimates are clamped (a person walking with it)
  double max_rate_deg_s = 360.0;  ///< likewise for turning
  /// A pose this much farther from the last than max_speed_m_s (or max_rate_deg_s) allows in one frame
  /// interval did not move there, it jumped: a target lifted and put down, or found again by the
  /// search after tracking lost it. The filter starts again from it, still, instead of extrapolating
  /// a clamped velocity from the jump (a duck moved 18 cm in 40 ms was drawn up to 13 cm past where it
  /// came to rest on the next frames).
  double jump_factor = 2.0;
  /// Poses since the filter (re)started before the target can be seen moving. The first poses after a
  /// restart are often the search's, rough by centimetres (the duck put down 18 cm away: found again
  /// 5 cm off, refined on the next frame), and two of them are no velocity: with 2, that refinement was
  /// extrapolated at 1.5 m/s for one frame.
  int min_poses = 3;
  /// Still or moving, decided on the poses of the last stillness_window_s: the target moves when the
  /// newest pose is farther from the oldest than still_sigmas times the noise of that difference (3-D;
  /// 4 sigmas: 0.1 % of still frames at the noise above) and than the minimum speed over that time. A
  /// still target, or a part of its motion that is still (turning in place), is drawn as measured,
  /// never extrapolated.
  double stillness_window_s = 0.2;
  /// ...and when the window's least-squares velocity stands out of its own noise (the pose noise over
  /// the spread of the window's times): |v|^2 > velocity_gate times its variance per axis (3 degrees of
  /// freedom; 11.3 is the 99 % point). Under a real sensor's noise the first test alone passed a still
  /// target a few times a second (its noise is measured from 14 poses and reads a quarter low one time
  /// in ten), and the filter's rate then extrapolated was noise of 0.1-0.4 m/s.
  double velocity_gate = 11.3;
  double still_sigmas = 4.0;
  double min_speed_m_s = 0.02;
  double min_rate_deg_s = 3.0;
};

/// What the renderer needs to extrapolate one target: the pose at `time_s` and its velocity (zero for
/// the parts of the motion that are not significant). Frames as in T_camera_target.
struct MotionState {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();                   ///< T_camera_target at time_s
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            ///< of the target's origin, camera frame
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  ///< camera frame, about the origin
  double time_s = 0.0;                                               ///< capture time of the newest pose
  double max_horizon_s = 0.1;
  bool moving() const { return !velocity_m_s.isZero(0.0) || !angular_velocity_rad_s.isZero(0.0); }
};

/// The pose at `t_s`: T moved on at constant velocity for t_s - time_s, clamped to [0, max_horizon_s].
/// A still state gives T itself, bit for bit.
Eigen::Matrix4d predict_pose(const MotionState& state, double t_s);

class MotionFilter {
 public:
  explicit MotionFilter(MotionModelConfig config = {});
  /// Forget the motion (a new stop, a lost target).
  void reset();
  /// Jumps seen (poses the filter started again from, see jump_factor), for tests and statistics.
  int jumps() const { return jumps_; }
  /// A measured pose (the tracker's) captured at t_s. A pose not newer than the last, after a gap
  /// longer than max_gap_s, or one that jumped (jump_factor) restarts the filter from it.
  void update(const Eigen::Matrix4d& T_camera_target, double t_s);
  /// The state to extrapolate from: still (the newest measured pose, zero velocity) until min_poses
  /// poses are in and the target has moved more than noise over the stillness window.
  MotionState state() const;
  /// The state to draw: state(), but still (the newest measured pose) until the noise has been measured
  /// since the last reset (kNoisePoses poses; noise_window at least that). Before that only the configured
  /// noise is known, and a real sensor's can be ten times it: the first poses of the shop figure under the
  /// fitted depth model, and of every restart after a busy worker's gap, read as motion and were drawn up
  /// to 0.4 m ahead at the markers. The tracker starts from state()'s prediction (predict()): a start is
  /// refined, and extrapolating it early is what keeps up with a target moved off at once.
  MotionState drawn_state() const;
  /// Poses the noise is measured from, at least (second differences of the last noise_window).
  static constexpr int kNoisePoses = 5;
  /// No pose since the last reset: state() and predict() know nothing yet.
  bool empty() const { return count_ == 0; }
  Eigen::Matrix4d predict(double t_s) const { return predict_pose(state(), t_s); }
  /// Whether the newest pose agreed with the motion the filter predicted for it (within maneuver_gate),
  /// or started the filter. False from a pose outside the prediction (a start, a stop or one bad pose:
  /// the velocity restarts from it) until a pose agrees with the motion restarted: what would be drawn
  /// is not yet confirmed by a frame.
  bool confirmed() const { return confirmed_; }
  /// Velocity restarts since the last reset (starts and stops detected), for tests and statistics.
  int maneuvers() const { return maneuvers_; }
  const MotionModelConfig& config() const { return cfg_; }
  /// The tracker's pose noise per frame in use (1 sigma, each axis): configured, or measured if larger.
  double position_noise_m() const { return position_noise_; }
  double rotation_noise_rad() const { return rotation_noise_; }

 private:
  // One group of three axes (translation, or rotation as a rotation vector) sharing a 2x2 covariance
  // of (value, rate) per axis: the axes are independent and equally noisy.
  struct Group {
    Eigen::Vector3d rate = Eigen::Vector3d::Zero();
    Eigen::Matrix2d P = Eigen::Matrix2d::Zero();
  };
  void restart_velocity(const Eigen::Matrix4d& T, double dt);
  bool jumped(const Eigen::Matrix4d& T, double dt) const;
  void correct(const Eigen::Matrix4d& T, double dt);
  void predict_to(double dt);
  struct Stamped {
    double t_s;
    Eigen::Matrix4d T;
  };
  struct WindowMotion {
    double span_s = 0.0, moved_m = 0.0, turned_rad = 0.0;
    double time_spread_s2 = 0.0;  // the sum of the squared differences of the poses' times from their mean
    Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero(), angular_velocity_rad_s = Eigen::Vector3d::Zero();
  };
  WindowMotion window_motion() const;
  bool stands_out(double moved, const Eigen::Vector3d& velocity, double noise, double min_rate, const WindowMotion& m) const;

  MotionModelConfig cfg_;
  int count_ = 0;  // poses since the last reset
  double t_ = 0.0;
  Eigen::Matrix4d measured_ = Eigen::Matrix4d::Identity();  // the newest measured pose
  Eigen::Matrix4d filtered_ = Eigen::Matrix4d::Identity();  // the filter's pose at t_
  Group translation_, rotation_;
  int maneuvers_ = 0;
  int jumps_ = 0;
  bool confirmed_ = true;
  std::deque<Stamped> window_;                          // the measured poses of the last stillness_window_s, oldest first
  std::deque<Stamped> history_;                         // the last noise_window measured poses, oldest first
  double position_noise_ = 0.0, rotation_noise_ = 0.0;  // in use: the configured or the measured, larger
  void measure_noise();
};

}  // namespace projbot::alignment
