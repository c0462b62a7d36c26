#pragma once
// Internal to alignment: a Kinect v1 frame (640x480) from the bytes libfreenect or a fakenect dump hands
// over, the same for the driver (freenect_source.cpp) and the dump's reader (fakenect_dump.cpp).

#include <cstdint>

#include "projbot/alignment/depth.hpp"
#include "projbot/assets/image.hpp"

namespace projbot::alignment {

/// Raw 11-bit disparity to metres through kinect_raw_to_metres() (a table of its 2048 values); 0 for
/// "no reading" and for values above 11 bits. Sizes `out` to 640x480; leaves its capture time.
void kinect_depth_from_raw(const std::uint16_t* raw, DepthImage& out);
/// RGB bytes to RGBA, alpha 255. Sizes `out` to 640x480.
void kinect_colour_from_rgb(const std::uint8_t* rgb, assets::Image& out);

}  // namespace projbot::alignment
