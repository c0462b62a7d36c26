#pragma once
// The twin's camera frames at a stop, as the device tests feed them to the Kinect driver.

#include <cstdint>
#include <vector>

#include "projbot/alignment/freenect_source.hpp"
#include "projbot/twin/world.hpp"

/// `count` of the twin's depth and colour frames from T_world_camera, noise seeds first_seed.., and the
/// fakenect frames pointing at them, 1/30 s apart from start_s.
struct TwinFrames {
  std::vector<projbot::alignment::DepthImage> depths;
  std::vector<projbot::assets::Image> colours;
  std::vector<projbot::alignment::FakenectFrame> frames() const {
    std::vector<projbot::alignment::FakenectFrame> out;
    for (std::size_t k = 0; k < depths.size(); ++k)
      out.push_back({&depths[k], &colours[k], start_s + static_cast<double>(k) / 30.0});
    return out;
  }
  double start_s = 0.0;
};
inline TwinFrames twin_frames(projbot::twin::Twin& twin, const Eigen::Matrix4d& T_world_camera, std::uint32_t count,
                              std::uint32_t first_seed, double start_s) {
  TwinFrames f;
  f.start_s = start_s;
  for (std::uint32_t k = 0; k < count; ++k) {
    f.depths.push_back(twin.capture(T_world_camera, first_seed + k));
    f.colours.push_back(twin.capture_colour(T_world_camera, first_seed + k));
  }
  return f;
}
