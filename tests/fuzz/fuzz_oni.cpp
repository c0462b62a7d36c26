// libFuzzer entry for our .oni record walker (the cropping check and its in-place repair, which run
// before OpenNI2 plays a recording): any input is walked, repaired and walked again, or fails with
// AlignmentError; after a repair the recording must declare its cropping.
#include "fuzz_input.hpp"
#include "projbot/alignment/openni2_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = projbot::fuzz::input_file(data, size, ".oni");
  try {
    if (!projbot::alignment::oni_declares_cropping(file) && projbot::alignment::add_oni_cropping_property(file) &&
        !projbot::alignment::oni_declares_cropping(file))
      __builtin_trap();  // the repair promised the property
  } catch (const projbot::alignment::AlignmentError&) {
  }
  return 0;
}
