// libFuzzer entry for the BOP dataset reader: the input is a scene's scene_gt.json beside a valid
// models_info.json, scene_camera.json and depth image; it must read or fail with AlignmentError.
#include <filesystem>
#include <fstream>

#include "fuzz_input.hpp"
#include "projbot/alignment/bop.hpp"

namespace {

std::filesystem::path dataset() {
  namespace fs = std::filesystem;
  static const fs::path root = [] {
    const fs::path r = projbot::fuzz::scratch().path("projbot_fuzz_bop_");
    fs::create_directories(r / "models");
    fs::create_directories(r / "test" / "000000" / "depth");
    std::ofstream(r / "models" / "models_info.json") << R"({"1": {"diameter": 100.0}, "2": {"diameter": 50.0}})";
    std::ofstream(r / "models" / "obj_000001.ply") << "ply\n";
    std::ofstream(r / "models" / "obj_000002.ply") << "ply\n";
    std::ofstream(r / "test" / "000000" / "scene_camera.json")
        << R"({"1": {"cam_K": [500, 0, 320, 0, 500, 240, 0, 0, 1], "depth_scale": 1.0}})";
    std::ofstream(r / "test" / "000000" / "depth" / "000001.png") << "png";
    return r;
  }();
  return root;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto root = dataset();
  const auto input = projbot::fuzz::input_file(data, size, ".json");
  std::filesystem::copy_file(input, root / "test" / "000000" / "scene_gt.json",
                             std::filesystem::copy_options::overwrite_existing);
  try {
    const auto d = projbot::alignment::read_bop_dataset(root);
    for (const auto& s : d.scenes)
      for (const auto& im : s.images)
        for (const auto& inst : im.instances)
          if (!inst.T_camera_model.allFinite() || d.object(inst.obj_id) == nullptr) __builtin_trap();
  } catch (const projbot::alignment::AlignmentError&) {
  }
  return 0;
}
