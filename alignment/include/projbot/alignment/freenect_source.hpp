#pragma once
// Kinect v1 (the paper's sensor) through libfreenect: depth + colour at 640x480, 30 Hz, with the
// device's timestamps. Debian's OpenNI2 has no Kinect v1 driver, hence this second source. libfreenect
// types stay in src/.
//
// libfreenect's `fakenect` (Debian libfreenect-bin) is a drop-in libfreenect.so that plays a dump
// folder (INDEX.txt plus one PGM / PPM file per frame) through the same API: write_fakenect_dump()
// writes the twin's frames in that format, so CI runs this driver on them (FAKENECT_PATH, and the
// fakenect library first on LD_LIBRARY_PATH).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/rgbd_camera.hpp"
#include "projbot/assets/image.hpp"
#include "projbot/config/clock.hpp"

namespace projbot::alignment {

/// Kinect v1 raw 11-bit disparity to depth in metres (the published fit z = 1 / (3.3309495161 -
/// 0.0030711016 raw)); 0 for 2047 ("no reading") and for values outside 0.3..10 m.
float kinect_raw_to_metres(std::uint16_t raw);
/// The raw disparity whose depth is nearest to depth_m; 2047 (no reading) for 0, NaN and depths outside
/// what the sensor reports.
std::uint16_t kinect_metres_to_raw(float depth_m);

struct FreenectOptions {
  int index = 0;  ///< which Kinect (0-based)
  /// true: depth registered to the colour camera in millimetres (FREENECT_DEPTH_REGISTERED, the device's
  /// factory registration); false: raw 11-bit disparity converted by kinect_raw_to_metres(), in the depth
  /// camera's own frame (what a fakenect dump without registration tables can play).
  bool registered = true;
  int timeout_ms = 2000;  ///< next() gives up after this long without a frame pair
};

class FreenectSource final : public RgbdCamera {
 public:
  /// Opens Kinect `index` and starts depth and colour. Throws AlignmentError naming the index and how many
  /// Kinects libfreenect found (or why it could not look).
  explicit FreenectSource(const FreenectOptions& options);
  ~FreenectSource() override;
  FreenectSource(const FreenectSource&) = delete;
  FreenectSource& operator=(const FreenectSource&) = delete;

  /// The next depth frame and the colour frame that followed it (depth: capture_time_s at its arrival).
  /// Throws AlignmentError when none arrives within timeout_ms or the device (or a fakenect dump) stops.
  RgbdFrame next() override;
  /// freenect_set_flag: automatic exposure and white balance off (not offered by fakenect).
  ExposureHold hold_colour_exposure() override;
  /// Frame pairs returned so far.
  int frames_read() const;

  /// How many Kinects libfreenect sees; throws AlignmentError with libfreenect's failure when it cannot look.
  static int count_devices();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One frame of a fakenect dump: depth in metres (640x480), colour (640x480, alpha ignored), and the
/// time it was taken, seconds (the dump's playback keeps the gaps between frames).
struct FakenectFrame {
  const DepthImage* depth = nullptr;
  const assets::Image* colour = nullptr;
  double time_s = 0.0;
};
/// A fakenect dump written frame by frame: raw 11-bit depth PGMs, RGB PPMs and INDEX.txt, which is
/// rewritten (atomically) after every frame, so a dump cut short (Ctrl-C, a full disk) plays what it holds.
class FakenectDumpWriter {
 public:
  /// Creates `folder`, which must be empty or absent. Throws AlignmentError naming it.
  explicit FakenectDumpWriter(const std::filesystem::path& folder);
  /// Appends a frame. Throws AlignmentError naming the file on a write failure or a frame that is not 640x480.
  void add(const FakenectFrame& frame);
  int frames() const { return frames_; }

 private:
  std::filesystem::path folder_;
  std::string index_;
  int frames_ = 0;
};
/// Writes `frames` into `folder` (created; must be empty or absent) as a fakenect dump.
void write_fakenect_dump(const std::filesystem::path& folder, const std::vector<FakenectFrame>& frames);

/// Depth as a fakenect dump gives it back: each value through the Kinect's raw 11-bit disparity and back
/// (kinect_metres_to_raw, then kinect_raw_to_metres). What a recording's tracker sees, so a replay of the
/// dump sees the same.
DepthImage kinect_quantised(DepthImage depth);

/// A fakenect dump read back frame by frame without libfreenect (`projbot run --replay` plays one per
/// stop): depth through kinect_raw_to_metres() as the Kinect driver converts raw disparity, colour as
/// RGBA. Frame k is stamped on `clock` (the host's steady clock, or a replay's) at the first frame's
/// reading time plus its recorded offset from the first; with `realtime`, next() also waits until then.
class FakenectDumpReader final : public RgbdCamera {
 public:
  /// Reads folder/INDEX.txt (pairs of d-TIME-STAMP.pgm and r-TIME-STAMP.ppm lines, as libfreenect's
  /// record tool and FakenectDumpWriter write them). Throws AlignmentError naming the file (and line).
  FakenectDumpReader(const std::filesystem::path& folder, bool realtime, config::Clock clock = config::Clock::steady());
  /// The next frame. Throws AlignmentError naming the file for a missing or malformed one, and at the end
  /// of the dump.
  RgbdFrame next() override;
  int frames() const { return static_cast<int>(entries_.size()); }
  int frames_read() const { return next_; }

 private:
  struct Entry {
    std::string depth, colour;  // file names in the folder
    double time_s = 0.0;        // recorded, seconds
    std::uint32_t depth_stamp = 0, colour_stamp = 0;
  };
  std::filesystem::path folder_;
  bool realtime_;
  config::Clock clock_;
  std::vector<Entry> entries_;
  int next_ = 0;
  double offset_s_ = 0.0;  // the clock's time minus recorded time, set at the first frame
};

}  // namespace projbot::alignment
