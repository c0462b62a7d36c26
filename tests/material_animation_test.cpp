// Materials that move (issue 44): glTF emission (KHR_materials_emissive_strength, an emissive texture and its
// KHR_texture_transform) and KHR_animation_pointer channels on material properties, loaded from a copy of
// BoxTextured with the animation's keys in a data-URI buffer, and played against glTF's own formulas.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "projbot/assets/model.hpp"

namespace fs = std::filesystem;
using projbot::assets::animate_materials;
using projbot::assets::AssetError;
using projbot::assets::load_gltf;
using projbot::assets::MaterialChannel;
using projbot::assets::Model;
using json = nlohmann::json;

namespace {

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    std::uint32_t n = static_cast<std::uint8_t>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(bytes[i + 1])) << 8;
    if (i + 2 < bytes.size()) n |= static_cast<std::uint8_t>(bytes[i + 2]);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[n & 63] : '=';
  }
  return out;
}

// BoxTextured in a scratch folder, its material emitting and animated by pointer channels.
class AnimatedBox : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("projbot_anim_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy(fs::path(PROJBOT_SHARED_DATA) / "gltf" / "BoxTextured" / "glTF", dir_, fs::copy_options::recursive);
    std::ifstream in(dir_ / "BoxTextured.gltf");
    json_ = json::parse(in);
    json_["extensionsUsed"] = {"KHR_animation_pointer", "KHR_materials_emissive_strength", "KHR_texture_transform"};
    json_["animations"] = json::array({{{"name", "glow"}, {"samplers", json::array()}, {"channels", json::array()}}});
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A float accessor of `type` over `data`, in a buffer of its own (a data URI).
  int add_floats(const std::vector<float>& data, const std::string& type) {
    const std::string bytes(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
    json_["buffers"].push_back({{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}});
    json_["bufferViews"].push_back({{"buffer", json_["buffers"].size() - 1}, {"byteLength", bytes.size()}});
    const std::size_t width = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
    json_["accessors"].push_back({{"bufferView", json_["bufferViews"].size() - 1},
                                  {"componentType", 5126},
                                  {"count", data.size() / width},
                                  {"type", type}});
    return static_cast<int>(json_["accessors"].size() - 1);
  }
  void add_channel(const std::vector<float>& times, const std::vector<float>& values, const std::string& type,
                   const std::string& interpolation, const std::string& pointer) {
    json& a = json_["animations"][0];
    a["samplers"].push_back(
        {{"input", add_floats(times, "SCALAR")}, {"output", add_floats(values, type)}, {"interpolation", interpolation}});
    a["channels"].push_back(
        {{"sampler", a["samplers"].size() - 1},
         {"target", {{"path", "pointer"}, {"extensions", {{"KHR_animation_pointer", {{"pointer", pointer}}}}}}}});
  }
  // Base colour red to blue over 2 s (linear); emissive strength 0 then 3 from 1 s (step); the base colour
  // texture's offset along u from 0 to 1 over 4 s (cubic spline, leaving with slope 0.5 per second); a node
  // channel and a pointer at a property not played.
  void animate() {
    json& m = json_["materials"][0];
    m["emissiveFactor"] = {0.2, 0.4, 0.6};
    m["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 0.5}};
    m["emissiveTexture"] = {{"index", 0}, {"extensions", {{"KHR_texture_transform", {{"offset", {0.25, 0.0}}}}}}};
    add_channel({0, 2}, {1, 0, 0, 1, 0, 0, 1, 1}, "VEC4", "LINEAR", "/materials/0/pbrMetallicRoughness/baseColorFactor");
    add_channel({0, 1}, {0, 3}, "SCALAR", "STEP", "/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength");
    add_channel({0, 4}, {0, 0, 0, 0, 0.5F, 0, /**/ 0, 0, 1, 0, 0, 0}, "VEC2", "CUBICSPLINE",
                "/materials/0/pbrMetallicRoughness/baseColorTexture/extensions/KHR_texture_transform/offset");
    add_channel({0, 1}, {0.1F, 0.9F}, "SCALAR", "LINEAR", "/materials/0/pbrMetallicRoughness/metallicFactor");
    json& a = json_["animations"][0];
    a["samplers"].push_back({{"input", add_floats({0, 1}, "SCALAR")}, {"output", add_floats({0, 0, 0, 0, 1, 0}, "VEC3")}});
    a["channels"].push_back({{"sampler", a["samplers"].size() - 1}, {"target", {{"node", 0}, {"path", "translation"}}}});
  }
  fs::path save() const {
    std::ofstream(dir_ / "BoxTextured.gltf") << json_.dump();
    return dir_ / "BoxTextured.gltf";
  }
  std::string error() const {
    try {
      load_gltf(save());
    } catch (const AssetError& e) {
      return e.what();
    }
    ADD_FAILURE() << "a malformed animation loaded without error";
    return "";
  }

  fs::path dir_;
  json json_;
};

// glTF's cubic Hermite spline between two keys td apart: values v0, v1, out-tangent b0, in-tangent a1.
double hermite(double s, double td, double v0, double b0, double v1, double a1) {
  return (2 * s * s * s - 3 * s * s + 1) * v0 + td * (s * s * s - 2 * s * s + s) * b0 + (-2 * s * s * s + 3 * s * s) * v1 +
         td * (s * s * s - s * s) * a1;
}

}  // namespace

TEST_F(AnimatedBox, EmissionIsLoadedWithItsStrengthTextureAndPlacement) {
  animate();
  const Model m = load_gltf(save());
  const auto& mat = m.materials.at(0);
  EXPECT_FLOAT_EQ(mat.emissive_factor[1], 0.4F);
  EXPECT_FLOAT_EQ(mat.emissive_strength, 0.5F);
  EXPECT_EQ(mat.emissive_image, mat.base_color_image);
  EXPECT_DOUBLE_EQ(mat.emissive_transform.offset[0], 0.25);
  EXPECT_EQ(mat.base_color_transform, projbot::assets::TextureTransform{});
  json_["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = -1;
  EXPECT_NE(error().find("material 0: KHR_materials_emissive_strength.emissiveStrength must be a number 0..1e6"),
            std::string::npos);
  json_["materials"][0]["extensions"].erase("KHR_materials_emissive_strength");
  json_["materials"][0]["emissiveTexture"]["index"] = 7;
  EXPECT_NE(error().find("material 0: emissiveTexture index 7 is out of range"), std::string::npos);
}

TEST_F(AnimatedBox, PointerChannelsPlayAsGltfSaysAndRepeat) {
  animate();
  const Model m = load_gltf(save());
  ASSERT_EQ(m.material_animations.size(), 1U);
  const auto& a = m.material_animations[0];
  EXPECT_EQ(a.name, "glow");
  EXPECT_DOUBLE_EQ(a.duration_s, 4.0);
  ASSERT_EQ(a.channels.size(), 3U);  // not the node channel, not metallicFactor
  EXPECT_EQ(a.channels[2].interpolation, MaterialChannel::Interpolation::kCubicSpline);
  for (const double t : {0.0, 0.5, 1.5, 2.0, 3.0, 4.5, 7.0, -1.0}) {
    const auto states = animate_materials(m, t);
    ASSERT_EQ(states.size(), 1U);
    ASSERT_EQ(states[0].first, 0);
    const auto& s = states[0].second;
    const double in = t < 0 ? 0.0 : std::fmod(t, 4.0);  // every channel repeats over the animation's 4 s
    const double w = std::min(in / 2.0, 1.0);           // red to blue, then held
    EXPECT_NEAR(s.base_color_factor[0], 1.0 - w, 1e-6) << t;
    EXPECT_NEAR(s.base_color_factor[2], w, 1e-6) << t;
    EXPECT_FLOAT_EQ(s.emissive_strength, in < 1.0 ? 0.0F : 3.0F) << t;
    EXPECT_NEAR(s.base_color_transform.offset[0], hermite(in / 4.0, 4.0, 0.0, 0.5, 1.0, 0.0), 1e-5) << t;
    EXPECT_FLOAT_EQ(s.emissive_factor[2], 0.6F) << t;  // not animated: as loaded
    EXPECT_DOUBLE_EQ(s.emissive_transform.offset[0], 0.25) << t;
  }
  // A .glb carries the same channels in its JSON chunk.
  std::string text = json_.dump();
  while (text.size() % 4 != 0) text += ' ';
  std::ofstream glb(dir_ / "box.glb", std::ios::binary);
  const std::uint32_t header[5] = {0x46546C67U, 2U, static_cast<std::uint32_t>(20 + text.size()),
                                   static_cast<std::uint32_t>(text.size()), 0x4E4F534AU};
  glb.write(reinterpret_cast<const char*>(header), sizeof header);
  glb << text;
  glb.close();
  const Model from_glb = load_gltf(dir_ / "box.glb");
  ASSERT_EQ(from_glb.material_animations.size(), 1U);
  EXPECT_EQ(from_glb.material_animations[0].channels.size(), 3U);
  EXPECT_NEAR(animate_materials(from_glb, 1.0)[0].second.base_color_factor[0], 0.5, 1e-6);
}

TEST_F(AnimatedBox, MalformedChannelsAreRefusedNamingThem) {
  animate();
  json& ch = json_["animations"][0]["channels"][0];
  ch["sampler"] = 9;
  EXPECT_NE(error().find("animation 0 channel 0: sampler index 9 is out of range"), std::string::npos);
  ch["sampler"] = 4294967296LL;  // issue 72: read as int it wrapped to 0 and was then used as 2^32
  EXPECT_NE(error().find("animation 0 channel 0: sampler index 4294967296 is out of range"), std::string::npos);
  ch["sampler"] = 1;  // the emissive strength's scalars for the base colour's four numbers
  EXPECT_NE(error().find("animation 0 channel 0: its output must be 4 float"), std::string::npos);
  ch["sampler"] = 0;
  ch["target"]["extensions"]["KHR_animation_pointer"].erase("pointer");
  EXPECT_NE(error().find("animation 0 channel 0: target path 'pointer' without a KHR_animation_pointer.pointer"),
            std::string::npos);
  ch["target"]["extensions"]["KHR_animation_pointer"]["pointer"] = "/materials/5/emissiveFactor";
  EXPECT_NE(error().find("animation 0 channel 0: material index 5 is out of range"), std::string::npos);
  ch["target"]["extensions"]["KHR_animation_pointer"]["pointer"] = "/materials/0/pbrMetallicRoughness/baseColorFactor";
  json_["animations"][0]["samplers"][0]["interpolation"] = "SMOOTH";
  EXPECT_NE(error().find("interpolation 'SMOOTH' is not LINEAR, STEP or CUBICSPLINE"), std::string::npos);
  json_["animations"][0]["samplers"][0]["interpolation"] = "LINEAR";
  // Key times that go back.
  const int times = json_["animations"][0]["samplers"][0]["input"].get<int>();
  json_["buffers"][json_["bufferViews"][json_["accessors"][times]["bufferView"].get<int>()]["buffer"].get<int>()]["uri"] =
      "data:application/octet-stream;base64," + base64(std::string("\0\0\0@\0\0\0\0", 8));  // 2.0, then 0.0
  EXPECT_NE(error().find("animation 0 channel 0: key time 1 is not a finite time"), std::string::npos);
}
