// The only translation unit with OpenNI2.

#include "projbot/alignment/openni2_source.hpp"

#include <OpenNI.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/paths.hpp"

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
  openni::VideoStream depth, colour;
  bool colour_on = false;         // a colour stream registered to the depth, started
  openni::VideoFrameRef pending;  // a colour frame read ahead of its depth frame
  DeviceClock clock;
  double arrival_s = 0.0;  // host steady clock: when the last depth frame was ready
  openni::Recorder recorder;
  double metres_per_unit = 0.001;
  bool playback = false;
  int frames_read = 0;
};

namespace {

// The colour stream, where it is registered to the depth (the device's registration switched on, or the
// options say so): RGB888 at the depth's resolution, created (not started); otherwise left off.
bool make_colour(openni::Device& device, openni::VideoStream& depth, openni::VideoStream& colour, bool playback,
                 const OpenNi2Options& options) {
  // Not from a recording: its player restarts each stream's times and frame numbers from that stream's own
  // first recorded frame, so depth and colour cannot be paired (one frame apart in some recordings, measured).
  if (playback || !device.hasSensor(openni::SENSOR_COLOR)) return false;
  const bool by_device = device.isImageRegistrationModeSupported(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) &&
                         device.setImageRegistrationMode(openni::IMAGE_REGISTRATION_DEPTH_TO_COLOR) == openni::STATUS_OK;
  if (!by_device && !options.colour_registered) return false;
  if (colour.create(device, openni::SENSOR_COLOR) != openni::STATUS_OK) fail(options.uri, "cannot create the colour stream");
  const openni::VideoMode depth_mode = depth.getVideoMode();
  openni::VideoMode mode = colour.getVideoMode();
  mode.setResolution(depth_mode.getResolutionX(), depth_mode.getResolutionY());
  mode.setPixelFormat(openni::PIXEL_FORMAT_RGB888);
  if (colour.setVideoMode(mode) != openni::STATUS_OK) mode = colour.getVideoMode();
  if (mode.getPixelFormat() != openni::PIXEL_FORMAT_RGB888 || mode.getResolutionX() != depth_mode.getResolutionX() ||
      mode.getResolutionY() != depth_mode.getResolutionY()) {
    colour.destroy();  // not the depth's pixels: colour would say nothing true about them
    return false;
  }
  device.setDepthColorSyncEnabled(true);  // where the driver can; frames are paired one for one anyway
  return true;
}

}  // namespace

OpenNi2Source::OpenNi2Source(const OpenNi2Options& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  // OpenNI2 keeps one process-wide context; initialize() is safe to call again and is never shut down
  // here, because another source may still use it.
  if (openni::OpenNI::initialize() != openni::STATUS_OK) fail(options.uri, "cannot initialise OpenNI2");
  const bool is_file = options.uri.size() > 4 && options.uri.substr(options.uri.size() - 4) == ".oni";
  if (const std::string kind = is_file ? config::input_file_problem(options.uri) : std::string(); !kind.empty())
    throw AlignmentError(options.uri + (kind == "does not exist" ? std::string(": no such .oni recording") : ": " + kind));
  std::string open_uri = options.uri;
  if (is_file && !oni_declares_cropping(options.uri)) {
    // The packaged player would deliver no frame of it (see the header): play a repaired copy.
    static std::atomic<int> copies{0};
    m.repaired_copy.path = std::filesystem::temp_directory_path() /
                           ("projbot_playback_" + std::to_string(::getpid()) + "_" + std::to_string(copies++) + ".oni");
    try {
      config::copy_file(options.uri, m.repaired_copy.path);  // through EINTR: a Ctrl-C mid-copy is a stop request
    } catch (const config::OutputError& e) {
      throw AlignmentError(e.what());
    }
    try {
      add_oni_cropping_property(m.repaired_copy.path);
    } catch (const AlignmentError& e) {  // named as the user named it, not as our temporary copy
      std::string why = e.what();
      const std::string copy = m.repaired_copy.path.string();
      for (auto at = why.find(copy); at != std::string::npos; at = why.find(copy, at + options.uri.size()))
        why.replace(at, copy.size(), options.uri);
      throw AlignmentError(why);
    }
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
  m.colour_on = make_colour(m.device, m.depth, m.colour, m.playback, options);
  if (m.depth.start() != openni::STATUS_OK) fail(options.uri, "cannot start the depth stream");
  if (m.colour_on && m.colour.start() != openni::STATUS_OK) fail(options.uri, "cannot start the colour stream");
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
  if (m.colour_on) m.colour.stop();
  m.depth.stop();
  // Kept, never destroyed (one idle thread and a few kB, until the process ends; the OpenNI2 context is
  // never shut down, so nothing tears them down at exit):
  // - playback: Debian's OpenNI2 2.2.0.33 player thread can still be inside its new-data callback, waiting
  //   for the next manual trigger, when the stream is destroyed; it then wakes on the freed stream (SIGSEGV
  //   in libOniFile, 2 in 12 test runs on a loaded machine). Closing the device first does not help: the
  //   core deletes the stream before the driver joins its thread.
  // - the packaged Dummy device with colour: its frame thread runs on after its device closes (see
  //   tests/openni2_test.cpp) and crashes on a closed device's or destroyed colour stream (SIGSEGV from
  //   libDummyDevice into libOpenNI2, every run).
  if (m.playback || (m.colour_on && m.options.uri == "Dummy")) {
    std::error_code ignored;
    if (!m.repaired_copy.path.empty()) std::filesystem::remove(m.repaired_copy.path, ignored);
    m.repaired_copy.path.clear();
    [[maybe_unused]] Impl* kept = impl_.release();
    return;
  }
  if (m.colour_on) m.colour.destroy();
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
  m.arrival_s = config::steady_now_s();
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

namespace {

// RGB888 rows into an RGBA image.
assets::Image rgba_of(const openni::VideoFrameRef& frame) {
  assets::Image out;
  out.width = frame.getWidth();
  out.height = frame.getHeight();
  out.rgba.resize(static_cast<std::size_t>(out.width) * out.height * 4);
  const auto* data = static_cast<const std::uint8_t*>(frame.getData());
  for (int y = 0; y < out.height; ++y) {
    const auto* row = data + static_cast<std::size_t>(y) * frame.getStrideInBytes();
    for (int x = 0; x < out.width; ++x) {
      std::uint8_t* p = out.pixel(x, y);
      p[0] = row[3 * x], p[1] = row[3 * x + 1], p[2] = row[3 * x + 2], p[3] = 255;
    }
  }
  return out;
}

}  // namespace

bool OpenNi2Source::paired_colour(std::uint64_t depth_us, assets::Image& out) {
  Impl& m = *impl_;
  constexpr std::uint64_t kHalfFrameUs = 16667;  // at 30 Hz
  for (int tries = 0; tries < 4; ++tries) {
    if (!m.pending.isValid()) {
      openni::VideoStream* streams[] = {&m.colour};
      int ready = -1;
      if (openni::OpenNI::waitForAnyStream(streams, 1, &ready, m.options.timeout_ms) != openni::STATUS_OK ||
          m.colour.readFrame(&m.pending) != openni::STATUS_OK || !m.pending.isValid())
        throw AlignmentError(describe(m.options.uri) + ": no colour frame within " + std::to_string(m.options.timeout_ms) +
                             " ms of its depth frame");
    }
    if (m.pending.getTimestamp() + kHalfFrameUs < depth_us) {  // older than this depth: a frame it had no depth for
      m.pending.release();
      continue;
    }
    if (m.pending.getTimestamp() > depth_us + kHalfFrameUs) return false;  // the next depth frame's
    out = rgba_of(m.pending);
    m.pending.release();
    return true;
  }
  return false;
}

RgbdFrame OpenNi2Source::next_frame() {
  Impl& m = *impl_;
  RgbdFrame out;
  out.depth = next();
  const auto depth_us = static_cast<std::uint64_t>(std::llround(out.depth.capture_time_s * 1e6));
  out.depth.capture_time_s = m.clock.to_host(out.depth.capture_time_s, m.arrival_s);
  if (m.colour_on && paired_colour(depth_us, out.colour) &&
      (out.colour.width != out.depth.width || out.colour.height != out.depth.height))
    out.colour = {};  // not the depth's pixels
  return out;
}

bool OpenNi2Source::has_colour() const { return impl_->colour_on; }

ExposureHold OpenNi2Source::hold_colour_exposure() {
  if (!impl_->colour_on) return {false, "no colour stream"};
  openni::CameraSettings* settings = impl_->colour.getCameraSettings();
  if (settings == nullptr || !settings->isValid()) return {false, "its colour stream has no camera settings"};
  const bool exposure = settings->setAutoExposureEnabled(false) == openni::STATUS_OK;
  const bool balance = settings->setAutoWhiteBalanceEnabled(false) == openni::STATUS_OK;
  if (exposure && balance) return {true, "automatic exposure and white balance switched off"};
  return {false, std::string("OpenNI2 refused to switch off ") + (exposure  ? "its white balance"
                                                                  : balance ? "its exposure"
                                                                            : "its exposure and white balance")};
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
