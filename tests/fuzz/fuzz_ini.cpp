// libFuzzer entry for the icp-slam .ini: the strict check, then (when it passes) MRPT's own reader of
// the same file, as build_map runs them. Any input is accepted or fails with RobotError.
#include "fuzz_input.hpp"
#include "projbot/robot/localization.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    projbot::robot::check_icp_slam_config(projbot::fuzz::input_file(data, size, ".ini"));
  } catch (const projbot::robot::RobotError&) {
  }
  return 0;
}
