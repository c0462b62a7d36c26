#pragma once
// The RGB-D camera boundary (issue 12): what the robot's session reads frames from, whichever camera
// serves it (the twin's, a Kinect v1 through libfreenect, an OpenNI2 device or recording).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "projbot/alignment/depth.hpp"
#include "projbot/assets/image.hpp"

namespace projbot::alignment {

/// One depth frame and the colour frame registered to it.
struct RgbdFrame {
  DepthImage depth;                   ///< metres; capture_time_s on the host's steady clock
  assets::Image colour;               ///< RGBA; empty when the camera has no colour
  std::uint32_t depth_timestamp = 0;  ///< the device's own counters (0 where it has none)
  std::uint32_t colour_timestamp = 0;
  double delivered_s = 0.0;  ///< when next() handed it over (host steady clock), stamped by the session
};

/// A device's own clock mapped to the host's steady clock, from when its frames arrive: the offset is the
/// smallest (arrival - device time) seen, the frame that came fastest, so a frame's host time is its
/// arrival less the latency it had beyond that one (never later than its arrival). The offset may grow
/// by max_drift (relative) of the device time elapsed, so a device clock that runs slow is followed too;
/// a device clock that goes back (a device reset, a recording restarted) starts the mapping afresh.
class DeviceClock {
 public:
  explicit DeviceClock(double max_drift = 1e-4) : max_drift_(max_drift) {}
  /// The host steady-clock time of a frame stamped `device_s` by the device that arrived at `arrival_s`.
  double to_host(double device_s, double arrival_s) {
    if (!std::isfinite(offset_s_) || device_s < last_device_s_) offset_s_ = arrival_s - device_s;
    offset_s_ = std::min(offset_s_ + max_drift_ * (device_s - last_device_s_), arrival_s - device_s);
    last_device_s_ = device_s;
    return device_s + offset_s_;
  }

 private:
  double max_drift_;
  double offset_s_ = std::numeric_limits<double>::quiet_NaN();
  double last_device_s_ = 0.0;
};

/// What a camera did when asked to hold its colour exposure (RgbdCamera::hold_colour_exposure).
struct ExposureHold {
  bool held = false;   ///< automatic exposure and white balance are off
  std::string detail;  ///< what was done, or why not
};

class RgbdCamera {
 public:
  virtual ~RgbdCamera() = default;
  /// The next frame, waiting for it. Throws AlignmentError naming the camera when none comes.
  virtual RgbdFrame next() = 0;
  /// Switches the colour camera's automatic exposure and white balance off where the device lets it, so
  /// that its values follow the light (photometric calibration). Call between next() calls.
  virtual ExposureHold hold_colour_exposure() { return {false, "this camera offers no exposure control"}; }
};

}  // namespace projbot::alignment
