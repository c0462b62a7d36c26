// The only translation unit with libfreenect.

#include "projbot/alignment/freenect_source.hpp"

#include <dlfcn.h>
#include <libfreenect.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <sstream>

#include "kinect_frames.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::alignment {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr std::uint16_t kNoReading = 2047;
// The published Kinect v1 disparity fit (z = 1 / (a + b raw)).
constexpr double kA = 3.3309495161;
constexpr double kB = -0.0030711016;
constexpr double kMinM = 0.3;
constexpr double kMaxM = 10.0;

std::string kinect_name(int index) { return "Kinect v1 #" + std::to_string(index) + " (libfreenect)"; }

}  // namespace

float kinect_raw_to_metres(std::uint16_t raw) {
  if (raw >= kNoReading) return 0.0F;
  const double z = 1.0 / (kA + kB * raw);
  return z >= kMinM && z <= kMaxM ? static_cast<float>(z) : 0.0F;
}

std::uint16_t kinect_metres_to_raw(float depth_m) {
  if (!(depth_m >= kMinM && depth_m <= kMaxM)) return kNoReading;
  const double raw = std::round((1.0 / depth_m - kA) / kB);
  return raw >= 0.0 && raw < kNoReading ? static_cast<std::uint16_t>(raw) : kNoReading;
}

struct FreenectSource::Impl {
  FreenectOptions options;
  freenect_context* context = nullptr;
  freenect_device* device = nullptr;
  RgbdFrame pending;
  bool have_depth = false;
  bool have_colour = false;
  int frames_read = 0;

  ~Impl() {
    if (device != nullptr) {
      freenect_stop_depth(device);
      freenect_stop_video(device);
      freenect_close_device(device);
    }
    if (context != nullptr) freenect_shutdown(context);
  }

  void on_depth(const void* data, std::uint32_t timestamp) {
    DepthImage& d = pending.depth;
    d.capture_time_s = config::steady_now_s();  // its arrival, before the conversion below: that counts in a pose's age
    const auto* raw = static_cast<const std::uint16_t*>(data);
    if (options.registered) {
      d.width = kWidth;
      d.height = kHeight;
      d.depth_m.resize(static_cast<std::size_t>(kWidth) * kHeight);
      for (std::size_t i = 0; i < d.depth_m.size(); ++i) d.depth_m[i] = 0.001F * static_cast<float>(raw[i]);
    } else {
      kinect_depth_from_raw(raw, d);
    }
    pending.depth_timestamp = timestamp;
    have_depth = true;
    have_colour = false;  // the colour that belongs to it comes after it
  }

  void on_colour(const void* data, std::uint32_t timestamp) {
    if (!have_depth) return;
    kinect_colour_from_rgb(static_cast<const std::uint8_t*>(data), pending.colour);
    pending.colour_timestamp = timestamp;
    have_colour = true;
  }

  static void depth_callback(freenect_device* dev, void* data, std::uint32_t timestamp) {
    static_cast<Impl*>(freenect_get_user(dev))->on_depth(data, timestamp);
  }
  static void video_callback(freenect_device* dev, void* data, std::uint32_t timestamp) {
    static_cast<Impl*>(freenect_get_user(dev))->on_colour(data, timestamp);
  }
};

namespace {

freenect_context* open_context(const std::string& who) {
  freenect_context* context = nullptr;
  if (freenect_init(&context, nullptr) < 0 || context == nullptr)
    throw AlignmentError(who + ": libfreenect cannot start (no USB access: is libusb able to see /dev/bus/usb?)");
  freenect_set_log_level(context, FREENECT_LOG_FATAL);
  freenect_select_subdevices(context, FREENECT_DEVICE_CAMERA);
  return context;
}

}  // namespace

FreenectSource::FreenectSource(const FreenectOptions& options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  const std::string who = kinect_name(options.index);
  // Debian's fakenect (a libfreenect.so that plays a dump) aborts on any depth mode but raw 11-bit; it is
  // recognised by a helper only it exports.
  if (options.registered && dlsym(RTLD_DEFAULT, "sleep_highres") != nullptr)
    throw AlignmentError(who +
                         ": this libfreenect is fakenect (playing a recorded dump), which plays raw depth only: "
                         "set the camera's registered: false");
  m.context = open_context(who);
  const int found = freenect_num_devices(m.context);
  if (options.index < 0 || options.index >= found)
    throw AlignmentError(who + ": not found (libfreenect sees " + std::to_string(std::max(found, 0)) + " Kinect" +
                         (found == 1 ? "" : "s") + ")");
  if (freenect_open_device(m.context, &m.device, options.index) < 0) {
    m.device = nullptr;
    throw AlignmentError(who + ": cannot open (in use by another program, or no permission on its USB device)");
  }
  freenect_set_user(m.device, &m);
  freenect_set_depth_callback(m.device, Impl::depth_callback);
  freenect_set_video_callback(m.device, Impl::video_callback);
  const freenect_frame_mode depth_mode =
      freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, options.registered ? FREENECT_DEPTH_REGISTERED : FREENECT_DEPTH_11BIT);
  const freenect_frame_mode video_mode = freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB);
  if (!depth_mode.is_valid || !video_mode.is_valid || freenect_set_depth_mode(m.device, depth_mode) < 0 ||
      freenect_set_video_mode(m.device, video_mode) < 0)
    throw AlignmentError(who + ": does not offer 640x480 depth and RGB");
  if (freenect_start_depth(m.device) < 0 || freenect_start_video(m.device) < 0)
    throw AlignmentError(who + ": cannot start its depth and colour streams");
}

FreenectSource::~FreenectSource() = default;

ExposureHold FreenectSource::hold_colour_exposure() {
  // Looked up, not linked: fakenect (the dump player standing in for libfreenect) lacks it.
  using SetFlag = int (*)(freenect_device*, freenect_flag, freenect_flag_value);
  const auto set_flag = reinterpret_cast<SetFlag>(dlsym(RTLD_DEFAULT, "freenect_set_flag"));
  if (set_flag == nullptr) return {false, "this libfreenect (fakenect?) cannot set the camera's flags"};
  const bool exposure = set_flag(impl_->device, FREENECT_AUTO_EXPOSURE, FREENECT_OFF) == 0;
  const bool balance = set_flag(impl_->device, FREENECT_AUTO_WHITE_BALANCE, FREENECT_OFF) == 0;
  if (exposure && balance) return {true, "automatic exposure and white balance switched off"};
  return {false, std::string("libfreenect refused to switch off ") + (exposure  ? "its white balance"
                                                                      : balance ? "its exposure"
                                                                                : "its exposure and white balance")};
}

RgbdFrame FreenectSource::next() {
  Impl& m = *impl_;
  const std::string who = kinect_name(m.options.index);
  m.have_depth = m.have_colour = false;
  const double give_up_s = config::steady_now_s() + m.options.timeout_ms / 1000.0;
  while (!(m.have_depth && m.have_colour)) {
    if (config::steady_now_s() > give_up_s)
      throw AlignmentError(who + ": no depth and colour frame within " + std::to_string(m.options.timeout_ms) + " ms");
    timeval wait{0, 100000};
    if (freenect_process_events_timeout(m.context, &wait) < 0)
      throw AlignmentError(who + ": stopped delivering frames (unplugged, or the end of a fakenect dump)");
  }
  ++m.frames_read;
  return std::move(m.pending);  // handed over, not copied: the next frame refills it
}

int FreenectSource::frames_read() const { return impl_->frames_read; }

int FreenectSource::count_devices() {
  freenect_context* context = open_context("Kinect v1 (libfreenect)");
  const int found = freenect_num_devices(context);
  freenect_shutdown(context);
  return std::max(found, 0);
}

namespace {

std::string dump_name(char kind, double time_s, int frame) {
  std::ostringstream name;
  name << kind << '-' << std::fixed << std::setprecision(6) << time_s << '-' << std::setw(10) << std::setfill('0')
       << static_cast<std::uint32_t>(frame) * 1000000U << (kind == 'd' ? ".pgm" : ".ppm");
  return name.str();
}

void write_dump_depth(const std::filesystem::path& path, const DepthImage& depth) {
  std::string bytes = "P5 640 480 65535\n";
  const std::size_t header = bytes.size();
  bytes.resize(header + depth.depth_m.size() * 2);
  for (std::size_t i = 0; i < depth.depth_m.size(); ++i) {
    const std::uint16_t raw = kinect_metres_to_raw(depth.depth_m[i]);
    std::memcpy(&bytes[header + i * 2], &raw, 2);  // fakenect hands the bytes to the callback as they are
  }
  config::write_file_atomically(path, bytes);
}

void write_dump_colour(const std::filesystem::path& path, const assets::Image& colour) {
  std::string bytes = "P6 640 480 255\n";
  const std::size_t header = bytes.size();
  bytes.resize(header + static_cast<std::size_t>(kWidth) * kHeight * 3);
  for (std::size_t i = 0; i < static_cast<std::size_t>(kWidth) * kHeight; ++i)
    std::memcpy(&bytes[header + i * 3], &colour.rgba[i * 4], 3);
  config::write_file_atomically(path, bytes);
}

}  // namespace

FakenectDumpWriter::FakenectDumpWriter(const std::filesystem::path& folder) : folder_(folder) {
  std::error_code ec;
  if (std::filesystem::exists(folder, ec) && !std::filesystem::is_empty(folder, ec))
    throw AlignmentError(folder.string() + ": not empty; a fakenect dump needs a new folder");
  std::filesystem::create_directories(folder, ec);
  if (ec) throw AlignmentError(folder.string() + ": cannot create: " + ec.message());
}

void FakenectDumpWriter::add(const FakenectFrame& f) {
  if (f.depth == nullptr || f.colour == nullptr || f.depth->width != kWidth || f.depth->height != kHeight ||
      f.colour->width != kWidth || f.colour->height != kHeight)
    throw AlignmentError(folder_.string() + ": frame " + std::to_string(frames_) + " is not a 640x480 depth and colour pair");
  const std::string d = dump_name('d', f.time_s, frames_);
  const std::string r = dump_name('r', f.time_s + 0.001, frames_);
  try {
    write_dump_depth(folder_ / d, *f.depth);
    write_dump_colour(folder_ / r, *f.colour);
    index_ += d + "\n" + r + "\n";
    config::write_file_atomically(folder_ / "INDEX.txt", index_);
  } catch (const config::OutputError& e) {
    throw AlignmentError(e.what());
  }
  ++frames_;
}

void write_fakenect_dump(const std::filesystem::path& folder, const std::vector<FakenectFrame>& frames) {
  FakenectDumpWriter writer(folder);
  for (const FakenectFrame& f : frames) writer.add(f);
}

}  // namespace projbot::alignment
