#pragma once
// A real 2-D laser through any MRPT laser driver (CHokuyoURG, CSickLaserSerial, CLMS100Eth, ...), chosen
// by class name with the keys of that class's own configuration section (issue 12, `devices.laser`).

#include <map>
#include <memory>
#include <string>

#include "projbot/robot/error.hpp"
#include "projbot/robot/laser.hpp"

namespace projbot::robot {

class MrptLaser final : public LaserSource {
 public:
  /// Creates the MRPT sensor `class_name`, loads `params` as its configuration section and starts it.
  /// Throws RobotError naming the class when MRPT has no such 2-D laser class or the device does not start
  /// (absent port, no answer).
  MrptLaser(const std::string& class_name, const std::map<std::string, std::string>& params);
  ~MrptLaser();
  MrptLaser(const MrptLaser&) = delete;
  MrptLaser& operator=(const MrptLaser&) = delete;

  /// Polls the driver until a scan arrives (at most timeout_s). Throws RobotError naming the class.
  LaserScan next(double timeout_s = 1.0) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace projbot::robot
