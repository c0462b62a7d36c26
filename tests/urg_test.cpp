// The configured-laser path (MrptLaser, MRPT's CHokuyoURG driver) end to end against a Hokuyo UTM-30LX
// emulated on a pty, speaking SCIP 2.0.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <thread>

#include "projbot/robot/mrpt_laser.hpp"
#include "projbot/robot/urg_emulator.hpp"

namespace {

using namespace projbot::robot;

// A room seen from inside: 1-10 m, with a gap (no echo) over 40 steps.
std::vector<std::uint32_t> ramp(std::uint32_t offset_mm) {
  std::vector<std::uint32_t> r(UrgEmulator::kSteps);
  for (int i = 0; i < UrgEmulator::kSteps; ++i)
    r[static_cast<std::size_t>(i)] = 1000 + offset_mm + 8 * static_cast<std::uint32_t>(i);
  std::fill(r.begin() + 500, r.begin() + 540, 0U);
  return r;
}

TEST(UrgLaser, MrptsHokuyoDriverReadsTheScansTheUnitSends) {
  const auto served = ramp(0);
  UrgEmulator unit(served);
  MrptLaser laser("CHokuyoURG", {{"COM_port_LIN", unit.port()}});
  // A generous wait: it returns with the first scan; MRPT's start-up took over 2 s in a fresh root beside a build.
  const LaserScan scan = laser.next(10.0);
  // The UTM-30LX's steps 0..1080 as PP reported them: 1081 rays, 1440 to the turn (270.25 degrees), 60 m.
  ASSERT_EQ(scan.ranges_m.size(), 1081U);
  EXPECT_NEAR(scan.aperture_rad, 1081 * 2 * std::numbers::pi / 1440, 1e-6);
  EXPECT_NEAR(scan.max_range_m, 60.0, 1e-6);
  for (std::size_t i = 0; i < served.size(); ++i) {
    SCOPED_TRACE(i);
    if (served[i] == 0) {
      EXPECT_EQ(scan.valid[i], 0);  // no echo
    } else {
      ASSERT_EQ(scan.valid[i], 1);
      ASSERT_NEAR(scan.ranges_m[i], 0.001 * served[i], 1e-4);  // ray i is step i: right to left, as the unit counts
    }
  }
  // MRPT's start-up over SCIP 2.0: the laser on, the parameters read, then continuous scans of every step.
  const auto cmds = unit.received();
  for (const char* c : {"SCIP2.0", "BM", "PP", "MD0000108001000"})
    EXPECT_NE(std::find(cmds.begin(), cmds.end(), c), cmds.end()) << c;
}

TEST(UrgLaser, FollowsWhatTheUnitSeesNow) {
  UrgEmulator unit(ramp(0));
  MrptLaser laser("CHokuyoURG", {{"COM_port_LIN", unit.port()}});
  laser.next(2.0);
  unit.set_ranges(ramp(500));
  // Scans already on the line come first; within a second the new ranges arrive.
  bool moved = false;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!moved && std::chrono::steady_clock::now() < give_up) moved = std::abs(laser.next(1.0).ranges_m[0] - 1.5f) < 1e-4f;
  EXPECT_TRUE(moved);
  EXPECT_GT(unit.scans_sent(), 1);
}

// What a unit answers a command it does not know, or a scan request it cannot read: status 0E, and it
// stays ready for the next command.
TEST(UrgLaser, AMalformedCommandIsRefusedAndTheUnitAnswersOn) {
  UrgEmulator unit(ramp(0));
  const int fd = ::open(unit.port().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd, 0);
  const auto ask = [&](const std::string& cmd) {
    const std::string line = cmd + "\n";
    EXPECT_EQ(::write(fd, line.data(), line.size()), static_cast<ssize_t>(line.size()));
    std::string reply;
    char buf[512];
    for (int i = 0; i < 100 && (reply.size() < 2 || reply.substr(reply.size() - 2) != "\n\n"); ++i) {
      pollfd p{fd, POLLIN, 0};
      if (::poll(&p, 1, 20) > 0) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n > 0) reply.append(buf, static_cast<std::size_t>(n));
      }
    }
    return reply;
  };
  EXPECT_EQ(ask("MD0000108001x00"),
            "MD0000108001x00\n0E" + std::string(1, static_cast<char>((('0' + 'E') & 0x3F) + 0x30)) + "\n\n");
  EXPECT_EQ(ask("XX"), "XX\n0E" + std::string(1, static_cast<char>((('0' + 'E') & 0x3F) + 0x30)) + "\n\n");
  EXPECT_NE(ask("VV").find("PROT:SCIP 2.0;"), std::string::npos);
  EXPECT_EQ(unit.scans_sent(), 0);
  ::close(fd);
}

TEST(UrgLaser, AnEmulatorRefusesAScanOfTheWrongSize) {
  EXPECT_THROW(UrgEmulator(std::vector<std::uint32_t>(100, 1000)), RobotError);
}

}  // namespace

namespace {

// A laser port that is no serial port (a file, /dev/null) is said to be one (issue 47: "did not answer").
TEST(UrgLaser, APortThatIsNoSerialPortIsNamed) {
  const std::string file = "/tmp/projbot_urg_" + std::to_string(::getpid());
  std::ofstream(file) << "not a port\n";
  for (const auto& [port, message] : std::vector<std::pair<std::string, std::string>>{
           {"/dev/null", "not a terminal"}, {file, "is a regular file, not a serial port"}}) {
    try {
      projbot::robot::MrptLaser laser("CHokuyoURG", {{"COM_port_LIN", port}});
      ADD_FAILURE() << "opened " << port;
    } catch (const projbot::robot::RobotError& e) {
      EXPECT_NE(std::string(e.what()).find("on " + port + ": "), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
  std::remove(file.c_str());
}

}  // namespace
