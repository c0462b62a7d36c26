#pragma once
// The RGB-D camera boundary (issue 12): what the robot's session reads frames from, whichever camera
// serves it (the twin's, a Kinect v1 through libfreenect, an OpenNI2 device or recording).

#include <cstdint>

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

class RgbdCamera {
 public:
  virtual ~RgbdCamera() = default;
  /// The next frame, waiting for it. Throws AlignmentError naming the camera when none comes.
  virtual RgbdFrame next() = 0;
};

}  // namespace projbot::alignment
