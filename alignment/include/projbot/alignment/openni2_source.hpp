#pragma once
// Depth and colour frames from OpenNI2: a live device by URI (PrimeSense / Asus Xtion class through the
// PS1080 driver; "Dummy" for the packaged test device) or an .oni recording, optionally recorded to an
// .oni (depth only). A live device's colour is read where it is registered to the depth: by the device
// (registration depth-to-colour, which the PS1080 driver offers, switched on), or as the options say. A
// recording's is not: the packaged player restarts each stream's times and frame numbers at its own first
// recorded frame, so its depth and colour frames cannot be paired (one frame apart in some, measured).
// One thread per source. OpenNI2 types stay in src/.
//
// Recordings and Debian's OpenNI2 2.2.0.33: the OniFile player hands a frame to a stream only when the
// recording declares the stream's cropping ("xnCropping"; PlayerStream::OnNewDataCallback returns early
// when the property is missing), and the recorder writes that property only for streams that support
// cropping. The PS1080 driver's streams do; the Dummy device's do not, so its recordings open, report
// their frames and then deliver none. Recording here therefore adds the property (cropping off) when the
// stream lacked it, and playing a recording without it plays a repaired temporary copy.
// PlaybackControl::seek crashes the player thread of that build (recordings with or without the
// property), so playback steps frame by frame from the start and never seeks.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/rgbd_camera.hpp"

namespace projbot::alignment {

struct OpenNi2Options {
  std::string uri;                  ///< "" for the first device, "Dummy", a device URI, or an .oni path
  std::filesystem::path record_to;  ///< record the depth stream to this .oni while reading (empty: no)
  int timeout_ms = 2000;            ///< next() gives up after this long without a frame
  /// The live device's colour is registered to its depth already, though it offers no registration to
  /// switch on (the Dummy device: colour and depth of the same size, one pair per tick).
  bool colour_registered = false;
};

class OpenNi2Source {
 public:
  /// Opens the device and starts its depth stream. Throws AlignmentError naming the URI and OpenNI's reason.
  explicit OpenNi2Source(const OpenNi2Options& options);
  ~OpenNi2Source();
  OpenNi2Source(const OpenNi2Source&) = delete;
  OpenNi2Source& operator=(const OpenNi2Source&) = delete;

  /// The next depth frame in metres (0 = no depth), capture time from the device's timestamp, seconds.
  /// A recording is stepped: each call returns the following recorded frame, however fast it is called,
  /// and the end of the recording is an AlignmentError saying so. Throws AlignmentError when no frame
  /// arrives within timeout_ms.
  DepthImage next();
  /// The next depth frame (as next()) with its colour, RGBA at the depth's size (empty where has_colour()
  /// is false), paired by the device's timestamps, the capture time mapped to the host's steady clock
  /// (DeviceClock, from when each frame arrived). Throws AlignmentError as next(), and when a live
  /// device's colour frame does not come within timeout_ms.
  RgbdFrame next_frame();
  /// Whether next_frame() delivers colour.
  bool has_colour() const;
  /// The colour stream's automatic exposure and white balance off, through its CameraSettings.
  ExposureHold hold_colour_exposure();
  /// Pinhole intrinsics from the stream's resolution and fields of view (principal point at the centre);
  /// empty when the device reports no field of view (the Dummy device): then calibrate and pass them.
  std::optional<CameraIntrinsics> intrinsics() const;
  /// Frames in the recording when playing an .oni, -1 for a live device.
  int recorded_frames() const;
  /// Frames returned by next() so far.
  int frames_read() const;

 private:
  /// The live colour frame taken with the depth frame stamped `depth_us` (device microseconds): older ones
  /// (colour frames the depth stream dropped) are skipped, a newer one is kept for the next depth frame.
  /// False when none pairs with it (the colour read belongs to a later depth frame, or four were older).
  bool paired_colour(std::uint64_t depth_us, assets::Image& out);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A device OpenNI2 sees: its URI (what `devices.camera.uri` takes), name and vendor.
struct OpenNi2DeviceInfo {
  std::string uri;
  std::string name;
  std::string vendor;
};
/// The devices OpenNI2's drivers see now. Throws AlignmentError when OpenNI2 cannot start.
std::vector<OpenNi2DeviceInfo> openni2_devices();

/// Whether an .oni recording declares a stream's cropping (see above). Throws AlignmentError naming the
/// file when it is missing or not an .oni recording.
bool oni_declares_cropping(const std::filesystem::path& recording);
/// Adds the cropping property (cropping off) for every node that lacks it, in place, moving the file
/// positions stored after it (seek table, undo positions). Returns false when nothing was missing.
bool add_oni_cropping_property(const std::filesystem::path& recording);

}  // namespace projbot::alignment
