// A PTU-D46-17 on a pseudo-terminal, speaking the unit's ASCII protocol in verbose, echo mode.
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <thread>

#include "projbot/config/write_all.hpp"
#include "projbot/robot/ptu_d46.hpp"
#include "pseudo_terminal.hpp"

namespace projbot::robot {
namespace {

constexpr long kPanMax = 3090, kPanMin = -3090;  // PTU-D46-17 positions
constexpr long kTiltMax = 604, kTiltMin = -907;
constexpr const char* kResolution = "185.1428";  // arc-seconds per position

bool parse_long(const std::string& s, long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtol(s.c_str(), &end, 10);
  return errno == 0 && end && *end == '\0';
}

}  // namespace

struct PtuD46Emulator::Impl {
  detail::PseudoTerminal pty{"PTU emulator"};
  mutable std::mutex mutex;
  long pan = 0, tilt = 0;
  long pan_speed = 1000, tilt_speed = 1000;
  bool limits_enabled = true;
  std::vector<std::string> received;
  std::atomic<bool> silent{false};
  std::jthread thread;

  // The reply to one command, or empty for none.
  std::string answer(const std::string& cmd) {
    std::lock_guard lock(mutex);
    received.push_back(cmd);
    const auto ok = [&](const std::string& text) { return cmd + " *" + (text.empty() ? "" : " " + text) + "\r\n"; };
    const auto err = [&](const std::string& text) { return cmd + " ! " + text + "\r\n"; };
    if (cmd == "FV" || cmd == "FT" || cmd == "EE" || cmd == "ED" || cmd == "I" || cmd == "S" || cmd == "A" || cmd == "H" ||
        cmd == "HP" || cmd == "HT" || cmd == "DR" || cmd == "DS" || cmd == "DF")
      return ok("");
    if (cmd == "R") {
      pan = tilt = 0;
      return ok("");
    }
    if (cmd == "PR" || cmd == "TR") return ok(std::string(kResolution) + " seconds arc per position");
    if (cmd == "V") return ok("Pan-Tilt Controller v2.14.0 (Projbot emulator)");
    if (cmd == "L") return ok(limits_enabled ? "Limits ENABLED" : "Limits DISABLED");
    if (cmd == "LE" || cmd == "LD") {
      limits_enabled = cmd == "LE";
      return ok("");
    }
    if (cmd.size() >= 2 && (cmd[0] == 'P' || cmd[0] == 'T')) {
      const bool is_pan = cmd[0] == 'P';
      const char* name = is_pan ? "Pan" : "Tilt";
      long& pos = is_pan ? pan : tilt;
      long& speed = is_pan ? pan_speed : tilt_speed;
      const long lo = is_pan ? kPanMin : kTiltMin, hi = is_pan ? kPanMax : kTiltMax;
      const char op = cmd[1];
      const std::string arg = cmd.substr(2);
      if (op == 'X' && arg.empty()) return ok("Maximum " + std::string(name) + " position is " + std::to_string(hi));
      if (op == 'N' && arg.empty()) return ok("Minimum " + std::string(name) + " position is " + std::to_string(lo));
      if (op == 'S' && arg.empty()) return ok("Target speed is " + std::to_string(speed) + " positions/sec");
      if (op == 'S') {
        long v = 0;
        if (!parse_long(arg, v)) return err("Illegal Command Argument");
        if (v <= 0 || v > 2900) return err("Value out of range");
        speed = v;
        return ok("");
      }
      if (op == 'P' || op == 'O') {
        if (arg.empty()) return ok("Current " + std::string(name) + " position is " + std::to_string(pos));
        long v = 0;
        if (!parse_long(arg, v)) return err("Illegal Command Argument");
        const long target = op == 'P' ? v : pos + v;
        if (limits_enabled && target > hi)
          return err("Maximum allowable " + std::string(name) + " position is " + std::to_string(hi));
        if (limits_enabled && target < lo)
          return err("Minimum allowable " + std::string(name) + " position is " + std::to_string(lo));
        pos = target;
        return ok("");
      }
    }
    return err("Illegal Command");
  }

  void run(const std::stop_token& stop) {
    std::string pending;
    while (!stop.stop_requested()) {
      pollfd p{pty.master, POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0 || !(p.revents & POLLIN)) continue;
      char buf[256];
      const ssize_t n = ::read(pty.master, buf, sizeof buf);
      if (n <= 0) continue;
      for (ssize_t i = 0; i < n; ++i) {
        const char c = buf[i];
        if (c == ' ' || c == '\r' || c == '\n') {
          if (pending.empty()) continue;
          const std::string reply = answer(pending);
          pending.clear();
          if (!silent.load() && !reply.empty()) {
            // Whole, through short writes and signals; a driver that has closed its end hears nothing.
            [[maybe_unused]] const int err = config::write_all(pty.master, reply.data(), reply.size());
          }
        } else if (pending.size() < 64) {
          pending.push_back(c);
        }
      }
    }
  }
};

PtuD46Emulator::PtuD46Emulator() : impl_(std::make_unique<Impl>()) {
  impl_->thread = std::jthread([impl = impl_.get()](const std::stop_token& stop) { impl->run(stop); });
}

PtuD46Emulator::~PtuD46Emulator() {
  impl_->thread.request_stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

std::string PtuD46Emulator::port() const { return impl_->pty.slave_path; }
long PtuD46Emulator::pan_steps() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->pan;
}
long PtuD46Emulator::tilt_steps() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->tilt;
}
void PtuD46Emulator::set_silent(bool silent) { impl_->silent.store(silent); }
std::vector<std::string> PtuD46Emulator::received() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->received;
}

}  // namespace projbot::robot
