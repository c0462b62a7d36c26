// The only translation unit that sees mrpt::hwdrivers.
#include "projbot/robot/ptu_d46.hpp"

#include <fcntl.h>
#include <mrpt/hwdrivers/CPtuDPerception.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "serial_port.hpp"

namespace projbot::robot {
namespace {

// CPtuDPerception prints its progress to std::cout and exceptions to std::cerr; keep both for
// our error message instead.
class CaptureCout {
 public:
  CaptureCout() : old_(std::cout.rdbuf(text_.rdbuf())), old_err_(std::cerr.rdbuf(text_.rdbuf())) {}
  ~CaptureCout() {
    std::cout.rdbuf(old_);
    std::cerr.rdbuf(old_err_);
  }
  CaptureCout(const CaptureCout&) = delete;
  CaptureCout& operator=(const CaptureCout&) = delete;
  std::string text() const { return text_.str(); }

 private:
  std::ostringstream text_;
  std::streambuf* old_;
  std::streambuf* old_err_;
};

std::string describe_error(int code) {
  switch (code) {
    case 1:
      return "communication error";
    case 2:
      return "no reply within the timeout";
    case 3:
      return "initialisation error";
    case 4:
      return "both axes hit an obstacle";
    case 5:
      return "the pan axis hit an obstacle";
    case 6:
      return "the tilt axis hit an obstacle";
    case 7:
      return "the unit refused: beyond its maximum position";
    case 8:
      return "the unit refused: beyond its minimum position";
    case 9:
      return "the unit refused: value out of range";
    case 10:
      return "the unit refused: illegal command";
    default:
      return "unexpected reply";
  }
}

}  // namespace

struct PtuD46::Impl {
  mrpt::hwdrivers::CPtuDPerception ptu;
  std::string port;

  PanTiltStatus failed(const std::string& what) {
    const int code = ptu.checkErrors();
    ptu.clearErrors();
    return {false, "PTU-D46 on " + port + ": " + what + ": " + describe_error(code)};
  }

  // CPtuDPerception truncates radians / resolution toward zero; hand it the centre of the
  // nearest step so that truncation lands on that step.
  double centred(double rad, double step) const {
    const double steps = std::round(rad / step);
    return (steps + (steps >= 0 ? 0.5 : -0.5)) * step;
  }
};

PtuD46::PtuD46(const std::string& port) : impl_(std::make_unique<Impl>()) {
  impl_->port = port;
  if (const std::string problem = detail::serial_port_problem(port); !problem.empty())
    throw RobotError("PTU-D46 on " + port + ": " + problem);
  impl_->ptu.clearErrors();  // CPtuDPerception leaves its error accumulator uninitialised
  bool ok = false;
  std::string log;
  {
    CaptureCout capture;
    ok = impl_->ptu.init(port);
    log = capture.text();
  }
  if (!ok) {
    const std::string reason =
        log.find("Error opening serial port") != std::string::npos ? "cannot open the serial port" : "the unit did not answer";
    throw RobotError("PTU-D46 on " + port + ": " + reason);
  }
  if (!(impl_->ptu.panResolution > 0.0) || !(impl_->ptu.tiltResolution > 0.0))
    throw RobotError("PTU-D46 on " + port + ": the unit reported no usable resolution");
}

PtuD46::~PtuD46() = default;

double PtuD46::pan_step_rad() const { return impl_->ptu.panResolution; }
double PtuD46::tilt_step_rad() const { return impl_->ptu.tiltResolution; }

PanTiltStatus PtuD46::move_to(const PanTiltAngles& a) {
  if (!std::isfinite(a.pan_rad) || !std::isfinite(a.tilt_rad))
    return {false, "PTU-D46 on " + impl_->port + ": angles must be finite"};
  auto& ptu = impl_->ptu;
  ptu.clearErrors();
  if (!ptu.moveToAbsPos('P', impl_->centred(a.pan_rad, ptu.panResolution))) return impl_->failed("pan move");
  if (!ptu.moveToAbsPos('T', impl_->centred(a.tilt_rad, ptu.tiltResolution))) return impl_->failed("tilt move");
  if (!ptu.aWait()) return impl_->failed("await completion");
  return {};
}

PanTiltStatus PtuD46::position(PanTiltAngles& out) {
  auto& ptu = impl_->ptu;
  ptu.clearErrors();
  if (!ptu.absPosQ('P', out.pan_rad)) return impl_->failed("pan position query");
  if (!ptu.absPosQ('T', out.tilt_rad)) return impl_->failed("tilt position query");
  return {};
}

}  // namespace projbot::robot
