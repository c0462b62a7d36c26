// The steady clock in seconds: the one time base of the live loop, the devices' arrival stamps and the
// measurements (capture, display and pose times are all on it).
#pragma once

#include <chrono>
#include <functional>
#include <thread>

namespace projbot::config {

/// Seconds on std::chrono::steady_clock (monotonic; its epoch is arbitrary, differences are what count).
inline double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// A clock and a wait on it, in seconds: the steady clock, a replay's recording clock (live::ReplayClock)
/// or a test's. Whoever keeps time through one (the live loop, a session, a recorded camera) asks it alone.
struct Clock {
  std::function<double()> now_s;
  std::function<void(double until_s)> sleep_until;  ///< returns at until_s (or at once, when past)
  /// steady_now_s and a sleep on the steady clock.
  static Clock steady() {
    return {steady_now_s, [](double until_s) {
              const double wait_s = until_s - steady_now_s();
              if (wait_s > 0.0) std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
            }};
  }
  /// Paces frames without vsync (offscreen) like a projector: sleeps until `next_s` moved on by one
  /// `period_s`, and starts the cadence afresh after a frame more than 50 ms late (no race to catch up).
  void pace(double& next_s, double period_s) const {
    next_s += period_s;
    sleep_until(next_s);
    if (const double now = now_s(); now > next_s + 0.05) next_s = now;
  }
};

/// Milliseconds since `t0` on the steady clock: how long a step took.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace projbot::config
