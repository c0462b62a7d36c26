// libFuzzer entry for the BOP dataset reader: the input is a scene's scene_gt.json beside a valid
// models_info.json, scene_camera.json and depth image; it must read or fail with AlignmentError.
#include <filesystem>
#include <string_view>

#include "fuzz_input.hpp"
#include "projbot/alignment/bop.hpp"

namespace {

namespace fs = std::filesystem;

// The dataset's fixed files, made once; each input is then written straight over scene_gt.json (no copy).
fs::path dataset() {
  static const fs::path root = [] {
    using projbot::fuzz::write_file;
    const fs::path r = projbot::fuzz::scratch().path("projbot_fuzz_bop_");
    projbot::fuzz::make_folders(r / "models");
    projbot::fuzz::make_folders(r / "test" / "000000" / "depth");
    write_file(r / "models" / "models_info.json", R"({"1": {"diameter": 100.0}, "2": {"diameter": 50.0}})");
    write_file(r / "models" / "obj_000001.ply", "ply\n");
    write_file(r / "models" / "obj_000002.ply", "ply\n");
    write_file(r / "test" / "000000" / "scene_camera.json",
               R"({"1": {"cam_K": [500, 0, 320, 0, 500, 240, 0, 0, 1], "depth_scale": 1.0}})");
    write_file(r / "test" / "000000" / "depth" / "000001.png", "png");
    return r;
  }();
  return root;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto root = dataset();
  projbot::fuzz::write_file(root / "test" / "000000" / "scene_gt.json",
                            std::string_view(reinterpret_cast<const char*>(data), size));
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
