// The only translation unit with OpenNI2.

#include "projbot/alignment/openni2_source.hpp"

#include <OpenNI.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>

namespace projbot::alignment {
namespace {

std::string describe(const std::string& uri) {
  return uri.empty() ? std::string("the first OpenNI2 device") : "OpenNI2 device '" + uri + "'";
}

[[noreturn]] void fail(const std::string& uri, const std::string& what) {
  throw AlignmentError(describe(uri) + ": " + what + ": " + openni::OpenNI::getExtendedError());
}

// A file removed when this goes, also when the constructor throws half way.
struct TemporaryFile {
  std::filesystem::path path;
  TemporaryFile() = default;
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile() {
    std::error_code ignored;
    if (!path.empty()) std::filesystem::remove(path, ignored);
  }
};

}  // namespace

struct OpenNi2Source::Impl {
  TemporaryFile repaired_copy;  // a copy of a recording that lacked the cropping property; outlives the device
  OpenNi2Options options;
  openni::Device device;
  openni::VideoStream depth;
  openni::Recorder recorder;
  double metres_per_unit = 0.001;
  bool playback = false;
  int frames_read = 0;
};

OpenNi2Source::OpenNi2Source(const OpenNi2Options& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  // OpenNI2 keeps one process-wide context; initialize() is safe to call again and is never shut down
  // here, because another source may still use it.
  if (openni::OpenNI::initialize() != openni::STATUS_OK) fail(options.uri, "cannot initialise OpenNI2");
  const bool is_file = options.uri.size() > 4 && options.uri.substr(options.uri.size() - 4) == ".oni";
  if (is_file && !std::filesystem::is_regular_file(options.uri)) throw AlignmentError(options.uri + ": no such .oni recording");
  std::string open_uri = options.uri;
  if (is_file && !oni_declares_cropping(options.uri)) {
    // The packaged player would deliver no frame of it (see the header): play a repaired copy.
    static std::atomic<int> copies{0};
    m.repaired_copy.path = std::filesystem::temp_directory_path() /
                           ("projbot_playback_" + std::to_string(::getpid()) + "_" + std::to_string(copies++) + ".oni");
    std::filesystem::copy_file(options.uri, m.repaired_copy.path, std::filesystem::copy_options::overwrite_existing);
    add_oni_cropping_property(m.repaired_copy.path);
    open_uri = m.repaired_copy.path.string();
  }
  if (m.device.open(open_uri.empty() ? openni::ANY_DEVICE : open_uri.c_str()) != openni::STATUS_OK)
    fail(options.uri, "cannot open");
  if (auto* control = m.device.getPlaybackControl(); control != nullptr && control->isValid()) {
    // Step: the player waits for each read to release the next frame, and stops at the end.
    m.playback = true;
    if (control->setSpeed(-1.0F) != openni::STATUS_OK || control->setRepeatEnabled(false) != openni::STATUS_OK)
      fail(options.uri, "cannot set frame-by-frame playback");
  }
  if (!m.device.hasSensor(openni::SENSOR_DEPTH)) throw AlignmentError(describe(options.uri) + ": has no depth sensor");
  if (m.depth.create(m.device, openni::SENSOR_DEPTH) != openni::STATUS_OK) fail(options.uri, "cannot create the depth stream");
  const openni::PixelFormat format = m.depth.getVideoMode().getPixelFormat();
  if (format == openni::PIXEL_FORMAT_DEPTH_1_MM)
    m.metres_per_unit = 0.001;
  else if (format == openni::PIXEL_FORMAT_DEPTH_100_UM)
    m.metres_per_unit = 0.0001;
  else
    throw AlignmentError(describe(options.uri) + ": depth pixel format " + std::to_string(static_cast<int>(format)) +
                         " is not in mm or 100 um");
  if (m.depth.start() != openni::STATUS_OK) fail(options.uri, "cannot start the depth stream");
  if (!options.record_to.empty()) {
    if (m.recorder.create(options.record_to.c_str()) != openni::STATUS_OK || m.recorder.attach(m.depth) != openni::STATUS_OK ||
        m.recorder.start() != openni::STATUS_OK)
      fail(options.uri, "cannot record to " + options.record_to.string());
  }
}

OpenNi2Source::~OpenNi2Source() {
  Impl& m = *impl_;
  if (m.recorder.isValid()) {
    m.recorder.stop();
    m.recorder.destroy();                  // writes the seek table and closes the file
    if (!m.depth.isCroppingSupported()) {  // then the recorder left the property out (see the header)
      try {
        add_oni_cropping_property(m.options.record_to);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "projbot: %s: the recording will not play back with the packaged OpenNI2\n", e.what());
      }
    }
  }
  m.depth.stop();
  if (m.playback) {
    // Debian's OpenNI2 2.2.0.33 player thread can still be inside its new-data callback, waiting for
    // the next manual trigger, when the stream is destroyed; it then wakes on the freed stream (SIGSEGV
    // in libOniFile, 2 in 12 test runs on a loaded machine). Closing the device first does not help:
    // the core deletes the stream before the driver joins its thread. So a playback device and stream
    // are stopped but never destroyed: one idle thread and a few kB per recording played, kept until
    // the process ends (the OpenNI2 context is never shut down, so nothing tears them down at exit).
    std::error_code ignored;
    if (!m.repaired_copy.path.empty()) std::filesystem::remove(m.repaired_copy.path, ignored);
    m.repaired_copy.path.clear();
    [[maybe_unused]] Impl* kept = impl_.release();
    return;
  }
  m.depth.destroy();
  m.device.close();
}

DepthImage OpenNi2Source::next() {
  Impl& m = *impl_;
  if (m.playback && m.frames_read >= recorded_frames())
    throw AlignmentError(describe(m.options.uri) + ": end of the recording (" + std::to_string(m.frames_read) + " frames)");
  openni::VideoStream* streams[] = {&m.depth};
  int ready = -1;
  if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, m.options.timeout_ms) != openni::STATUS_OK)
    throw AlignmentError(describe(m.options.uri) + ": no depth frame within " + std::to_string(m.options.timeout_ms) + " ms");
  openni::VideoFrameRef frame;
  if (m.depth.readFrame(&frame) != openni::STATUS_OK || !frame.isValid()) fail(m.options.uri, "cannot read a depth frame");
  ++m.frames_read;
  DepthImage out;
  out.width = frame.getWidth();
  out.height = frame.getHeight();
  out.capture_time_s = static_cast<double>(frame.getTimestamp()) * 1e-6;  // OpenNI timestamps are microseconds
  out.depth_m.resize(static_cast<std::size_t>(out.width) * out.height);
  const auto* data = static_cast<const std::uint8_t*>(frame.getData());
  for (int y = 0; y < out.height; ++y) {
    const auto* row = reinterpret_cast<const openni::DepthPixel*>(data + static_cast<std::size_t>(y) * frame.getStrideInBytes());
    for (int x = 0; x < out.width; ++x)
      out.depth_m[static_cast<std::size_t>(y) * out.width + x] = static_cast<float>(row[x] * m.metres_per_unit);
  }
  return out;
}

std::optional<CameraIntrinsics> OpenNi2Source::intrinsics() const {
  const Impl& m = *impl_;
  const openni::VideoMode mode = m.depth.getVideoMode();
  CameraIntrinsics k;
  k.width_px = mode.getResolutionX();
  k.height_px = mode.getResolutionY();
  const double hfov = m.depth.getHorizontalFieldOfView(), vfov = m.depth.getVerticalFieldOfView();
  if (!(hfov > 0.0) || !(vfov > 0.0)) return std::nullopt;
  k.fx_px = k.width_px / (2.0 * std::tan(hfov / 2.0));
  k.fy_px = k.height_px / (2.0 * std::tan(vfov / 2.0));
  k.cx_px = (k.width_px - 1) / 2.0;
  k.cy_px = (k.height_px - 1) / 2.0;
  return k;
}

int OpenNi2Source::frames_read() const { return impl_->frames_read; }

int OpenNi2Source::recorded_frames() const {
  auto* playback = impl_->device.getPlaybackControl();
  return playback != nullptr && playback->isValid() ? playback->getNumberOfFrames(impl_->depth) : -1;
}

std::vector<OpenNi2DeviceInfo> openni2_devices() {
  if (openni::OpenNI::initialize() != openni::STATUS_OK)
    throw AlignmentError(std::string("OpenNI2 cannot start: ") + openni::OpenNI::getExtendedError());
  openni::Array<openni::DeviceInfo> found;
  openni::OpenNI::enumerateDevices(&found);
  std::vector<OpenNi2DeviceInfo> out;
  for (int i = 0; i < found.getSize(); ++i) out.push_back({found[i].getUri(), found[i].getName(), found[i].getVendor()});
  return out;
}

}  // namespace projbot::alignment
