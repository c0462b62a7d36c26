// A Hokuyo UTM-30LX on a pseudo-terminal, speaking SCIP 2.0.
#include "projbot/robot/urg_emulator.hpp"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "projbot/robot/error.hpp"
#include "pseudo_terminal.hpp"

namespace projbot::robot {
namespace {

using Clock = std::chrono::steady_clock;
constexpr auto kScanPeriod = std::chrono::milliseconds(25);  // 40 Hz
constexpr std::size_t kLine = 64;                            // data characters per line

// SCIP 2.0's check character: the low 6 bits of the bytes' sum, plus 0x30.
char check(const std::string& s) {
  unsigned sum = 0;
  for (const char c : s) sum += static_cast<unsigned char>(c);
  return static_cast<char>((sum & 0x3F) + 0x30);
}
std::string line(const std::string& s) { return s + check(s) + "\n"; }
// `value` in SCIP's n-character encoding (6 bits a character, + 0x30).
std::string encode(std::uint32_t value, int chars) {
  std::string s;
  for (int i = chars - 1; i >= 0; --i) s.push_back(static_cast<char>(((value >> (6 * i)) & 0x3F) + 0x30));
  return s;
}
// The parameter lines of PP, VV and II: "KEY:value;" and its check character (over the text before ';').
std::string info(const std::vector<std::string>& fields) {
  std::string out;
  for (const std::string& f : fields) out += f + ";" + check(f) + "\n";
  return out;
}

}  // namespace

struct UrgEmulator::Impl {
  detail::PseudoTerminal pty{"URG emulator"};
  mutable std::mutex mutex;
  std::vector<std::uint32_t> ranges;
  std::vector<std::string> received;
  std::string streaming;  // the MD/ME command being served, empty when idle
  std::string outbox;     // written to the line as it takes it
  int scans = 0;
  Clock::time_point start = Clock::now(), next_scan = start;
  std::jthread thread;

  std::string answer(const std::string& cmd) {
    std::lock_guard lock(mutex);
    received.push_back(cmd);
    const std::string echo = cmd + "\n";
    const std::string ok = echo + line("00");
    if (cmd == "SCIP2.0" || cmd == "BM" || cmd == "RS" || cmd.rfind("SS", 0) == 0 || cmd.rfind("HS", 0) == 0 ||
        cmd.rfind("CR", 0) == 0)
      return ok + "\n";
    if (cmd == "QT") {
      streaming.clear();
      return ok + "\n";
    }
    if (cmd == "PP")
      return ok +
             info({"MODL:UTM-30LX(Projbot emulator)", "DMIN:23", "DMAX:60000", "ARES:1440", "AMIN:0", "AMAX:1080", "AFRT:540",
                   "SCAN:2400"}) +
             "\n";
    if (cmd == "VV")
      return ok +
             info({"VEND:Hokuyo Automatic Co., Ltd.", "PROD:SOKUIKI Sensor TOP-URG UTM-30LX", "FIRM:1.20.01(Projbot)",
                   "PROT:SCIP 2.0", "SERI:00000001"}) +
             "\n";
    if (cmd == "II")
      return ok + info({"MODL:UTM-30LX", "LASR:ON", "SCSP:2400", "MESM:Measuring", "SBPS:Unknown", "TIME:" + encode(ms(), 4)}) +
             "\n";
    const auto digits = [&] { return std::all_of(cmd.begin() + 2, cmd.end(), [](char c) { return c >= '0' && c <= '9'; }); };
    if ((cmd.rfind("MD", 0) == 0 || cmd.rfind("ME", 0) == 0) && cmd.size() == 15 && digits()) {
      streaming = cmd;
      next_scan = Clock::now();
      return ok + "\n";
    }
    return echo + line("0E") + "\n";  // not a command this unit knows
  }

  std::uint32_t ms() const {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count()) &
           0xFFFFFF;
  }

  // One scan of the command being served: echo, status 99, time stamp, the steps asked for.
  std::string scan() {
    std::lock_guard lock(mutex);
    const int first = std::stoi(streaming.substr(2, 4)), last = std::stoi(streaming.substr(6, 4));
    const bool intensity = streaming[1] == 'E';
    std::string data;
    for (int s = std::max(first, 0); s <= std::min(last, kSteps - 1); ++s) {
      const std::uint32_t r = ranges[static_cast<std::size_t>(s)];
      data += encode(r, 3);
      if (intensity) data += encode(r == 0 ? 0 : 1000, 3);
    }
    std::string out = streaming + "\n" + line("99") + line(encode(ms(), 4));
    for (std::size_t i = 0; i < data.size(); i += kLine) out += line(data.substr(i, kLine));
    ++scans;
    return out + "\n";
  }

  // Writes what the line takes of the outbox now.
  void flush() {
    while (!outbox.empty()) {
      const ssize_t w = ::write(pty.master, outbox.data(), outbox.size());
      if (w <= 0) return;  // full: later
      outbox.erase(0, static_cast<std::size_t>(w));
    }
  }

  void run(const std::stop_token& stop) {
    std::string pending;
    while (!stop.stop_requested()) {
      pollfd p{pty.master, static_cast<short>(POLLIN | (outbox.empty() ? 0 : POLLOUT)), 0};
      ::poll(&p, 1, 5);
      if (p.revents & POLLIN) {
        char buf[256];
        const ssize_t n = ::read(pty.master, buf, sizeof buf);
        for (ssize_t i = 0; i < n; ++i) {
          if (buf[i] != '\n' && buf[i] != '\r') {
            if (pending.size() < 64) pending.push_back(buf[i]);
            continue;
          }
          if (!pending.empty()) outbox += answer(pending);
          pending.clear();
        }
      }
      bool due = false;
      {
        std::lock_guard lock(mutex);
        due = !streaming.empty() && Clock::now() >= next_scan;
        if (due) next_scan += kScanPeriod;
      }
      if (due && outbox.empty()) outbox = scan();  // a line still busy with the last one drops this one
      flush();
    }
  }
};

UrgEmulator::UrgEmulator(std::vector<std::uint32_t> ranges_mm) : impl_(std::make_unique<Impl>()) {
  set_ranges(std::move(ranges_mm));
  ::fcntl(impl_->pty.master, F_SETFL, ::fcntl(impl_->pty.master, F_GETFL) | O_NONBLOCK);
  impl_->thread = std::jthread([impl = impl_.get()](const std::stop_token& stop) { impl->run(stop); });
}

UrgEmulator::~UrgEmulator() {
  impl_->thread.request_stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::string UrgEmulator::port() const { return impl_->pty.slave_path; }

void UrgEmulator::set_ranges(std::vector<std::uint32_t> ranges_mm) {
  if (ranges_mm.size() != static_cast<std::size_t>(kSteps))
    throw RobotError("URG emulator: " + std::to_string(ranges_mm.size()) + " ranges, the UTM-30LX has " + std::to_string(kSteps) +
                     " steps");
  std::lock_guard lock(impl_->mutex);
  impl_->ranges = std::move(ranges_mm);
}

int UrgEmulator::scans_sent() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->scans;
}

std::vector<std::string> UrgEmulator::received() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->received;
}

RoomUrg::RoomUrg(const config::Room& room, std::filesystem::path link, const Pose2D& T_room_odometry)
    : map_(OccupancyMap::from_room(room)),
      unit_(std::vector<std::uint32_t>(UrgEmulator::kSteps, 0)),
      link_(std::move(link)),
      T_room_odometry_(T_room_odometry) {
  std::error_code ec;
  if (std::filesystem::is_symlink(link_, ec)) std::filesystem::remove(link_, ec);
  std::filesystem::create_symlink(unit_.port(), link_, ec);
  if (ec) throw RobotError(link_.string() + ": cannot link the laser's pseudo-terminal there: " + ec.message());
  laser_.rays = UrgEmulator::kSteps;  // the UTM-30LX: 270 degrees in 0.25 degree steps
}

RoomUrg::~RoomUrg() {
  std::error_code ec;
  std::filesystem::remove(link_, ec);
}

void RoomUrg::stand_at(const Pose2D& pose) {
  const LaserScan scan = map_.simulate_scan(compose(T_room_odometry_, pose), laser_, rng_);
  std::vector<std::uint32_t> mm(scan.ranges_m.size(), 0);
  for (std::size_t i = 0; i < mm.size(); ++i)
    if (scan.valid[i]) mm[i] = static_cast<std::uint32_t>(std::lround(1000.0 * scan.ranges_m[i]));
  unit_.set_ranges(std::move(mm));
}

}  // namespace projbot::robot
