#pragma once
// The hostile-input suite's cases: what a case is (its files, arguments, exit code and the words its
// message must hold), the small scenes and files the cases are made from, and the lists of cases.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "cli_run.hpp"

namespace hostile {

namespace fs = std::filesystem;

// Files written into the scratch folder before a case runs; a plain string is the scene `bad.yaml`.
// A content "@head:N:PATH" is the first N bytes of PATH, "@random:N" N random bytes; {dir}, {data}, {src}
// and {made} (what the build made for assets/) are replaced in paths and contents. "@fifo" makes a FIFO,
// "@link:TARGET" a symbolic link.
struct Files {
  std::vector<std::pair<std::string, std::string>> list;
  Files() = default;
  Files(const char* yaml) : Files(std::string(yaml)) {}
  Files(const std::string& yaml) {
    if (!yaml.empty()) list.emplace_back("bad.yaml", yaml);
  }
  Files(std::initializer_list<std::pair<std::string, std::string>> files) : list(files) {}
};

struct Hostile {
  std::string name;
  std::string args;
  Files files;
  int code;  // 1: bad input, 2: bad usage
  std::vector<std::string> must_contain;
};

// A one-image, one-instance BOP dataset under bop/ with the camera `camera` and the translation `t_mm`.
inline Files bop_files(const std::string& camera, const std::string& t_mm) {
  return Files{{"bop/models/models_info.json", R"({"1": {"diameter": 100}})"},
               {"bop/models/obj_000001.ply", "ply\n"},
               {"bop/test/000000/depth/000001.png", "png"},
               {"bop/test/000000/scene_camera.json", R"({"1": )" + camera + "}"},
               {"bop/test/000000/scene_gt.json",
                R"({"1": [{"obj_id": 1, "cam_R_m2c": [1, 0, 0, 0, 1, 0, 0, 0, 1], "cam_t_m2c": )" + t_mm + "}]}"}};
}

// A PNG whose header claims `w` x `h` pixels (an IHDR, no data: the size is refused before any decoding).
inline std::string png_claiming(std::uint32_t w, std::uint32_t h) {
  std::string s("\x89PNG\r\n\x1a\n", 8);
  const auto be32 = [&](std::uint32_t v) {
    for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
  };
  be32(13);
  s += "IHDR";
  be32(w);
  be32(h);
  s += std::string("\x08\x06\x00\x00\x00", 5);
  be32(0);  // stb does not check the CRC
  be32(0);
  s += "IEND";
  be32(0xae426082u);
  return s;
}

// A pose folder of 14 capture images, each a real PNG cut before its IEND chunk.
inline Files truncated_captures() {
  Files f;
  for (int i = 0; i < 14; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "cap/p0/%02d.png", i);
    f.list.emplace_back(name, "@head:78:{src}/tests/fuzz/corpus/depth_png/gray16_4x3.png");
  }
  return f;
}

inline const std::string kProj = "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n";
inline const std::string kRoomProjector =
    "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, near: 0.1, far: 10}\n";
inline const std::string kRoom = kRoomProjector + "room: {width: 6, depth: 5, obstacles: [[0, 0, 1, 1]]}\n";
inline const std::string kDuckTarget =
    "  - {name: duck, model: {data}/gltf/Duck/glTF-Binary/Duck.glb, scale: 0.25, recenter: true,\n"
    "     world_pose: {translation: [3, 3.5, 0.9], rpy_deg: [90, 0, 0]}, stop: [3, 2, 90]}\n";
inline const std::string kTour = kRoom + "robot: {start: [2, 2, 0]}\ntargets:\n" + kDuckTarget + "tour: {visits: [duck]}\n";
inline std::string with(const std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("hostile_test: '" + from + "' not in the scene");
  return text.substr(0, at) + to + text.substr(at + from.size());
}

inline std::string pcd(const std::string& fields, const std::string& dims, const std::string& data, const std::string& body) {
  return "VERSION 0.7\n" + fields + dims + "VIEWPOINT 0 0 0 1 0 0 0\nDATA " + data + "\n" + body;
}
inline const std::string kXyz = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
inline std::string dims(long long w, long long h, long long n) {
  return "WIDTH " + std::to_string(w) + "\nHEIGHT " + std::to_string(h) + "\nPOINTS " + std::to_string(n) + "\n";
}
inline const std::string kPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
/// A tetrahedron's two faces, `mm` across, as an ASCII PLY (a BOP model's units).
inline std::string triangle_ply(double mm) {
  const std::string s = std::to_string(mm);
  return "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 2\n"
         "property list uchar int vertex_indices\nend_header\n0 0 0\n" +
         s + " 0 0\n0 " + s + " 0\n0 0 " + s + "\n3 0 1 2\n3 0 2 3\n";
}
inline const std::string kGood16 = "{src}/tests/fuzz/corpus/depth_png/gray16_4x3.png";
inline const std::string kIni =
    "[MappingApplication]\nlocalizationLinDistance = 0.2\n[ICP]\nmaxIterations = 80\nthresholdDist = 0.3\n";

inline std::string replace_all(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t at = 0; (at = s.find(from, at)) != std::string::npos; at += to.size()) s.replace(at, from.size(), to);
  return s;
}

/// Outputs that would destroy an input, and inputs that are not regular files.
std::vector<Hostile> clash_cases();
/// Point clouds as --scan and as --model.
std::vector<Hostile> cloud_cases();
/// Depth images, 3-D models, scenes, rawlogs, .ini files, maps and trajectories.
std::vector<Hostile> file_cases();
/// Arguments of every command.
std::vector<Hostile> argument_cases();
/// The command line itself and the render-type options, calibration boards and scenes' own files.
std::vector<Hostile> usage_cases();

}  // namespace hostile
