// libFuzzer entry for MRPT rawlogs: MRPT's deserialiser runs in a child process (it crashes on corrupt
// archives); any input reads as steps that passed the sanity checks, or fails with RobotError. A crash
// of this process, an ASan report in our code or another exception type is a finding.
#include <cmath>

#include "fuzz_input.hpp"
#include "projbot/robot/localization.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto steps = projbot::robot::read_rawlog(projbot::fuzz::input_file(data, size, ".rawlog"));
    for (const auto& s : steps)
      if (s.scan.ranges_m.size() != s.scan.valid.size() || !std::isfinite(s.timestamp_s)) __builtin_trap();
  } catch (const projbot::robot::RobotError&) {
  }
  return 0;
}
