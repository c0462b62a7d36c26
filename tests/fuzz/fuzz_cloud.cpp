// libFuzzer entry for point clouds (PCD, or PLY when built with FUZZ_EXTENSION=".ply"): our header check,
// then PCL's reader. Any input loads as a cloud of the size its header claims, or fails with
// AlignmentError; a crash, an ASan report, an allocation beyond -malloc_limit_mb or another exception
// type is a finding.
#include "fuzz_input.hpp"
#include "projbot/alignment/depth.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto cloud = projbot::alignment::read_cloud(projbot::fuzz::input_file(data, size, FUZZ_EXTENSION));
    if (cloud.points.empty()) __builtin_trap();  // an empty cloud is an error, never a result
  } catch (const projbot::alignment::AlignmentError&) {
  }
  return 0;
}
