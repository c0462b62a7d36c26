// MRPT's sensor factory for the configured laser; the only translation unit that creates MRPT sensors.

#include "projbot/robot/mrpt_laser.hpp"

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/hwdrivers/C2DRangeFinderAbstract.h>
#include <mrpt/hwdrivers/CGenericSensor.h>
#include <mrpt/hwdrivers/registerAllClasses.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <thread>

#include "mrpt_convert.hpp"
#include "serial_port.hpp"

namespace projbot::robot {

struct MrptLaser::Impl {
  std::string name;
  mrpt::hwdrivers::CGenericSensor::Ptr sensor;
};

namespace {

// MRPT's drivers report some failures only on std::cerr and in their state: keep both for the message.
class CaptureStderr {
 public:
  CaptureStderr() : old_(std::cerr.rdbuf(text_.rdbuf())) {}
  ~CaptureStderr() { std::cerr.rdbuf(old_); }
  CaptureStderr(const CaptureStderr&) = delete;
  CaptureStderr& operator=(const CaptureStderr&) = delete;
  std::string text() const {
    std::string t = text_.str();
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ')) t.pop_back();
    return t.size() > 300 ? t.substr(t.size() - 300) : t;
  }

 private:
  std::ostringstream text_;
  std::streambuf* old_;
};

// What an MRPT exception says, without its banner, location and call stack: its (innermost) "Message:".
std::string mrpt_reason(const std::exception& e) {
  std::istringstream lines(e.what());
  std::string line, reason;
  while (std::getline(lines, line))
    if (line.rfind("Message:", 0) == 0) reason = line.substr(line.find_first_not_of(' ', 8));
  return reason.empty() ? std::string(e.what()).substr(0, 300) : reason;
}

}  // namespace

MrptLaser::MrptLaser(const std::string& class_name, const std::map<std::string, std::string>& params)
    : impl_(std::make_unique<Impl>()) {
  impl_->name = "laser (MRPT " + class_name + ")";
  mrpt::hwdrivers::registerAllClasses_mrpt_hwdrivers();
  impl_->sensor = mrpt::hwdrivers::CGenericSensor::createSensorPtr(class_name);
  if (!impl_->sensor)
    throw RobotError(impl_->name + ": MRPT has no sensor class of that name (CHokuyoURG, CSickLaserSerial, ...)");
  auto* laser = dynamic_cast<mrpt::hwdrivers::C2DRangeFinderAbstract*>(impl_->sensor.get());
  if (laser == nullptr) throw RobotError(impl_->name + ": is an MRPT sensor but not a 2-D laser");
  // The drivers' own chatter (a Hokuyo's product and version tables, at INFO) stays out of our output.
  laser->setMinLoggingLevel(mrpt::system::LVL_WARN);
  mrpt::config::CConfigFileMemory config;
  for (const auto& [key, value] : params) {
    std::error_code ec;                                               // a missing port is left to MRPT's driver, which names it
    if (key == "COM_port_LIN" && std::filesystem::exists(value, ec))  // a file, a folder, /dev/null: said so
      if (const std::string problem = detail::serial_port_problem(value); !problem.empty())
        throw RobotError(impl_->name + " on " + value + ": " + problem);
    config.write("LASER", key, value);
  }
  CaptureStderr said;
  try {
    impl_->sensor->loadConfig(config, "LASER");
    impl_->sensor->initialize();
  } catch (const std::exception& e) {
    throw RobotError(impl_->name + ": cannot start: " + mrpt_reason(e) + (said.text().empty() ? "" : " (" + said.text() + ")"));
  }
  if (impl_->sensor->getState() == mrpt::hwdrivers::CGenericSensor::ssError)
    throw RobotError(impl_->name + ": cannot start" + (said.text().empty() ? std::string() : ": " + said.text()));
}

MrptLaser::~MrptLaser() = default;

LaserScan MrptLaser::next(double timeout_s) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < give_up) {
    CaptureStderr said;
    try {
      impl_->sensor->doProcess();
    } catch (const std::exception& e) {
      throw RobotError(impl_->name + ": " + mrpt_reason(e));
    }
    if (impl_->sensor->getState() == mrpt::hwdrivers::CGenericSensor::ssError)
      throw RobotError(impl_->name + ": stopped" + (said.text().empty() ? std::string() : ": " + said.text()));
    for (const auto& [time, object] : impl_->sensor->getObservations())
      if (const auto scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(object))
        return detail::from_mrpt(*scan);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  throw RobotError(impl_->name + ": no scan within " + std::to_string(timeout_s) + " s");
}

}  // namespace projbot::robot
