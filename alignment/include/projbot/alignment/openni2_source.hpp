#pragma once
// Depth frames from OpenNI2: a live device by URI (PrimeSense / Asus Xtion class through the PS1080
// driver; "Dummy" for the packaged test device) or an .oni recording, optionally recorded to an .oni.
// One thread per source. OpenNI2 types stay in src/.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "projbot/alignment/depth.hpp"

namespace projbot::alignment {

struct OpenNi2Options {
  std::string uri;                  ///< "" for the first device, "Dummy", a device URI, or an .oni path
  std::filesystem::path record_to;  ///< record the depth stream to this .oni while reading (empty: no)
  int timeout_ms = 2000;            ///< next() gives up after this long without a frame
};

class OpenNi2Source {
 public:
  /// Opens the device and starts its depth stream. Throws AlignmentError naming the URI and OpenNI's reason.
  explicit OpenNi2Source(const OpenNi2Options& options);
  ~OpenNi2Source();
  OpenNi2Source(const OpenNi2Source&) = delete;
  OpenNi2Source& operator=(const OpenNi2Source&) = delete;

  /// The next depth frame in metres (0 = no depth), capture time from the device's timestamp, seconds.
  /// Throws AlignmentError when no frame arrives within timeout_ms.
  DepthImage next();
  /// Pinhole intrinsics from the stream's resolution and fields of view (principal point at the centre);
  /// empty when the device reports no field of view (the Dummy device): then calibrate and pass them.
  std::optional<CameraIntrinsics> intrinsics() const;
  /// Frames in the recording when playing an .oni, -1 for a live device.
  int recorded_frames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::alignment
