// Reading fakenect dumps back without libfreenect (the replay's camera).

#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "kinect_frames.hpp"
#include "projbot/alignment/freenect_source.hpp"
#include "projbot/config/clock.hpp"

namespace projbot::alignment {
namespace {

// "d-1234.500000-0001000000.pgm": kind, time (s) and the device's stamp; false when it is not such a name.
bool parse_name(const std::string& name, char kind, double& time_s, std::uint32_t& stamp) {
  const std::string ext = kind == 'd' ? ".pgm" : ".ppm";
  if (name.size() < 8 || name[0] != kind || name[1] != '-' || name.compare(name.size() - 4, 4, ext) != 0) return false;
  if (name.find('/') != std::string::npos) return false;
  const std::size_t dash = name.rfind('-');
  if (dash <= 2) return false;
  try {
    std::size_t used = 0;
    const std::string t = name.substr(2, dash - 2), s = name.substr(dash + 1, name.size() - 4 - dash - 1);
    time_s = std::stod(t, &used);
    if (used != t.size() || !std::isfinite(time_s)) return false;
    const unsigned long v = std::stoul(s, &used);
    if (used != s.size() || v > 0xFFFFFFFFUL) return false;
    stamp = static_cast<std::uint32_t>(v);
  } catch (const std::exception&) {
    return false;
  }
  return true;
}

// A binary PNM (P5 or P6) of 640x480 with the given maxval: its pixel bytes.
std::string read_pnm(const std::filesystem::path& path, const char* magic, int maxval, std::size_t bytes_per_pixel) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw AlignmentError(path.string() + ": cannot open (the dump's INDEX.txt lists it)");
  std::string m;
  int w = 0, h = 0, mv = 0;
  in >> m >> w >> h >> mv;
  if (!in || m != magic || w != 640 || h != 480 || mv != maxval)
    throw AlignmentError(path.string() + ": not a 640x480 " + magic + " image with maxval " + std::to_string(maxval));
  in.get();  // the one whitespace byte after the header
  std::string data(static_cast<std::size_t>(w) * h * bytes_per_pixel, '\0');
  in.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (in.gcount() != static_cast<std::streamsize>(data.size()))
    throw AlignmentError(path.string() + ": cut short (" + std::to_string(in.gcount()) + " of " + std::to_string(data.size()) +
                         " pixel bytes)");
  return data;
}

}  // namespace

void kinect_depth_from_raw(const std::uint16_t* raw, DepthImage& out) {
  static const std::vector<float> metres = [] {  // kinect_raw_to_metres() of every 11-bit value, once
    std::vector<float> t(2048);
    for (std::size_t v = 0; v < t.size(); ++v) t[v] = kinect_raw_to_metres(static_cast<std::uint16_t>(v));
    return t;
  }();
  out.width = 640;
  out.height = 480;
  out.depth_m.resize(640 * 480);
  for (std::size_t i = 0; i < out.depth_m.size(); ++i) out.depth_m[i] = raw[i] < 2048 ? metres[raw[i]] : 0.0F;
}

void kinect_colour_from_rgb(const std::uint8_t* rgb, assets::Image& out) {
  out.width = 640;
  out.height = 480;
  out.rgba.resize(640 * 480 * 4);
  for (std::size_t i = 0; i < 640 * 480; ++i) {
    std::memcpy(&out.rgba[i * 4], rgb + i * 3, 3);
    out.rgba[i * 4 + 3] = 255;
  }
}

DepthImage kinect_quantised(DepthImage depth) {
  for (float& z : depth.depth_m) z = kinect_raw_to_metres(kinect_metres_to_raw(z));
  return depth;
}

FakenectDumpReader::FakenectDumpReader(const std::filesystem::path& folder, bool realtime, config::Clock clock)
    : folder_(folder), realtime_(realtime), clock_(std::move(clock)) {
  const std::filesystem::path index = folder / "INDEX.txt";
  std::ifstream in(index);
  if (!in) throw AlignmentError(index.string() + ": cannot read (not a fakenect dump?)");
  std::string line;
  Entry pending;
  bool have_depth = false;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::string where = index.string() + ":" + std::to_string(n) + ": ";
    if (line[0] == 'a') continue;  // accelerometer records: not used
    double t = 0.0;
    std::uint32_t stamp = 0;
    if (!parse_name(line, line[0], t, stamp) || (line[0] != 'd' && line[0] != 'r'))
      throw AlignmentError(where + "'" + line + "' is not a fakenect frame name (d-TIME-STAMP.pgm or r-TIME-STAMP.ppm)");
    if (line[0] == 'd') {
      pending = Entry{line, "", t, stamp, 0};
      have_depth = true;
    } else if (have_depth) {  // the colour that followed the depth: a pair
      pending.colour = line;
      pending.colour_stamp = stamp;
      entries_.push_back(pending);
      have_depth = false;
    }
  }
  if (entries_.empty()) throw AlignmentError(index.string() + ": no depth and colour frame pair listed");
}

RgbdFrame FakenectDumpReader::next() {
  if (next_ >= frames())
    throw AlignmentError(folder_.string() + ": the recording ends after " + std::to_string(frames()) + " frames");
  const Entry& e = entries_[static_cast<std::size_t>(next_)];
  RgbdFrame f;
  const std::string bytes = read_pnm(folder_ / e.depth, "P5", 65535, 2);
  std::vector<std::uint16_t> raw(640 * 480);
  std::memcpy(raw.data(), bytes.data(), bytes.size());  // as fakenect hands it to the driver: the host's byte order
  kinect_depth_from_raw(raw.data(), f.depth);
  kinect_colour_from_rgb(reinterpret_cast<const std::uint8_t*>(read_pnm(folder_ / e.colour, "P6", 255, 3).data()), f.colour);
  if (next_ == 0) offset_s_ = clock_.now_s() - e.time_s;
  f.depth.capture_time_s = e.time_s + offset_s_;
  if (realtime_) clock_.sleep_until(f.depth.capture_time_s);
  f.depth_timestamp = e.depth_stamp;
  f.colour_timestamp = e.colour_stamp;
  ++next_;
  return f;
}

}  // namespace projbot::alignment
