#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "projbot/assets/model.hpp"

namespace fs = std::filesystem;
using projbot::assets::AssetError;
using projbot::assets::load_gltf;
using projbot::assets::Model;

namespace {

const fs::path kData = fs::path(PROJBOT_SHARED_DATA) / "gltf";

Eigen::Vector3d position(const projbot::assets::Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

// A scratch copy of BoxTextured (separate files) that a test may corrupt.
class CorruptBox : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("projbot_box_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::copy(kData / "BoxTextured" / "glTF", dir_, fs::copy_options::recursive);
    std::ifstream in(gltf());
    json_ = nlohmann::json::parse(in);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path gltf() const { return dir_ / "BoxTextured.gltf"; }
  fs::path bin() const { return dir_ / "BoxTextured0.bin"; }
  void save() const { std::ofstream(gltf()) << json_.dump(); }
  void patch_bin(std::size_t offset, const void* bytes, std::size_t n) const {
    std::fstream f(bin(), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(offset));
    f.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(n));
  }
  // Loads and returns the error message; fails the test if loading succeeded.
  std::string error() const {
    try {
      load_gltf(gltf());
    } catch (const AssetError& e) {
      return e.what();
    }
    ADD_FAILURE() << "corrupted model loaded without error";
    return "";
  }

  fs::path dir_;
  nlohmann::json json_;
};

void expect_contains(const std::string& msg, const std::string& part) {
  EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
}

}  // namespace

TEST(GltfTest, DuckGlb) {
  const Model m = load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  ASSERT_EQ(m.primitives.size(), 1U);
  EXPECT_EQ(m.primitives[0].vertices.size(), 2399U);
  EXPECT_EQ(m.triangle_count(), 4212U);
  ASSERT_EQ(m.images.size(), 1U);
  EXPECT_EQ(m.images[0].width, 512);
  EXPECT_EQ(m.images[0].height, 512);
  EXPECT_EQ(m.materials.at(static_cast<std::size_t>(m.primitives[0].material)).base_color_image, 0);
  // The 0.01 root scale turns centimetres into metres: the duck is 1-3 m across, not 100-300.
  const double size = m.bounds().diagonal().norm();
  EXPECT_GT(size, 1.0);
  EXPECT_LT(size, 3.0);
  for (const auto& v : m.primitives[0].vertices)
    ASSERT_NEAR(std::sqrt(v.normal[0] * v.normal[0] + v.normal[1] * v.normal[1] + v.normal[2] * v.normal[2]), 1.0, 1e-4);
}

TEST(GltfTest, DuckGltfMatchesGlb) {
  const Model a = load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  const Model b = load_gltf(kData / "Duck" / "glTF" / "Duck.gltf");
  ASSERT_EQ(a.primitives[0].vertices.size(), b.primitives[0].vertices.size());
  ASSERT_EQ(a.primitives[0].indices, b.primitives[0].indices);
  for (std::size_t i = 0; i < a.primitives[0].vertices.size(); ++i) {
    ASSERT_LT((position(a.primitives[0].vertices[i]) - position(b.primitives[0].vertices[i])).norm(), 1e-6);
    ASSERT_EQ(a.primitives[0].vertices[i].uv, b.primitives[0].vertices[i].uv);
  }
  EXPECT_EQ(a.images[0].rgba, b.images[0].rgba);  // same PNG, embedded vs external
}

TEST(GltfTest, BoxTexturedEmbeddedAndSeparateAgree) {
  const Model a = load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf");
  const Model b = load_gltf(kData / "BoxTextured" / "glTF" / "BoxTextured.gltf");
  EXPECT_EQ(a.triangle_count(), 12U);
  EXPECT_EQ(a.primitives[0].indices, b.primitives[0].indices);
  for (std::size_t i = 0; i < 24; ++i)
    EXPECT_LT((position(a.primitives[0].vertices[i]) - position(b.primitives[0].vertices[i])).norm(), 1e-7);
  EXPECT_EQ(a.images[0].width, 211);
  EXPECT_EQ(a.images[0].rgba, b.images[0].rgba);
  const auto& mat = a.materials[0];
  EXPECT_EQ(mat.sampler.wrap_s, projbot::assets::Wrap::kRepeat);
  EXPECT_EQ(mat.sampler.wrap_t, projbot::assets::Wrap::kRepeat);
  // Unit cube: the root node's rotation keeps it within +-0.5; UVs span [0,6] x [0,1].
  EXPECT_LT((a.bounds().max() - Eigen::Vector3d(0.5, 0.5, 0.5)).norm(), 1e-6);
  float max_u = 0;
  for (const auto& v : a.primitives[0].vertices) max_u = std::max(max_u, v.uv[0]);
  EXPECT_FLOAT_EQ(max_u, 6.0F);
}

TEST(GltfTest, WindingAgreesWithNormalsAfterNodeTransform) {
  // The box's root node rotates -90 degrees about x; counter-clockwise fronts must survive it.
  for (const auto* file : {"BoxTextured/glTF-Embedded/BoxTextured.gltf", "Duck/glTF-Binary/Duck.glb"}) {
    const Model m = load_gltf(kData / file);
    std::size_t agree = 0, total = 0;
    for (const auto& p : m.primitives)
      for (std::size_t t = 0; t < p.indices.size(); t += 3) {
        const auto& a = p.vertices[p.indices[t]];
        const Eigen::Vector3d n =
            (position(p.vertices[p.indices[t + 1]]) - position(a)).cross(position(p.vertices[p.indices[t + 2]]) - position(a));
        const Eigen::Vector3d vn(a.normal[0], a.normal[1], a.normal[2]);
        agree += n.dot(vn) > 0 ? 1 : 0;
        ++total;
      }
    EXPECT_GT(static_cast<double>(agree) / static_cast<double>(total), 0.98) << file;
  }
}

TEST(GltfTest, VertexColorsWithoutTexture) {
  const Model m = load_gltf(kData / "BoxVertexColors" / "glTF-Embedded" / "BoxVertexColors.gltf");
  EXPECT_EQ(m.triangle_count(), 12U);
  EXPECT_EQ(m.materials.at(static_cast<std::size_t>(m.primitives[0].material)).base_color_image, -1);
  std::size_t coloured = 0;
  for (const auto& p : m.primitives)
    for (const auto& v : p.vertices) coloured += (v.color[0] != 1.0F || v.color[1] != 1.0F || v.color[2] != 1.0F) ? 1 : 0;
  EXPECT_GT(coloured, 0U);
}

TEST(GltfTest, ScaleAndRecenter) {
  Model m = load_gltf(kData / "Duck" / "glTF-Binary" / "Duck.glb");
  const double size = m.bounds().diagonal().norm();
  projbot::assets::scale_and_recenter(m, 0.25, true);
  EXPECT_NEAR(m.bounds().diagonal().norm(), 0.25 * size, 1e-5);
  EXPECT_LT(m.surface_centroid().norm(), 1e-6);
  EXPECT_THROW(projbot::assets::scale_and_recenter(m, 0.0, false), AssetError);
}

TEST(SamplingTest, PointsLieOnTheSurfaceUniformlyByArea) {
  const Model m = load_gltf(kData / "BoxTextured" / "glTF-Embedded" / "BoxTextured.gltf");
  const auto s = projbot::assets::sample_surface(m, 60000, 7);
  ASSERT_EQ(s.points.size(), 60000U);
  std::array<int, 6> per_face{};
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    const Eigen::Vector3f& p = s.points[i];
    const Eigen::Vector3f& n = s.normals[i];
    ASSERT_NEAR(p.cwiseAbs().maxCoeff(), 0.5F, 1e-5F);  // on the cube's surface
    ASSERT_NEAR(n.norm(), 1.0F, 1e-5F);
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    ASSERT_NEAR(p[axis] * 2.0F, n[axis], 1e-4F);  // outward normal of that face
    ++per_face[static_cast<std::size_t>(axis * 2 + (n[axis] > 0 ? 1 : 0))];
  }
  for (int c : per_face) EXPECT_NEAR(c / 60000.0, 1.0 / 6.0, 0.01);
  const auto again = projbot::assets::sample_surface(m, 100, 7);
  EXPECT_EQ(again.points[42], s.points[42]);  // reproducible for a seed
}

// Each sample's colour is the texel it falls on, wrapped as the sampler says: a 2x1 texture (red, blue)
// mirrored at u = 1.25 reads u = 0.75 (blue); a coordinate of 1e30 (even: no mirror) reads u = 0 (red)
// without overflowing an integer on the way.
TEST(SamplingTest, ColoursFollowTheTextureAndItsWrap) {
  Model m = projbot::assets::make_box({0, 0, 0}, {1, 1, 1}, {1.0F, 1.0F, 1.0F, 1.0F});
  projbot::assets::Image texture{2, 1, {255, 0, 0, 255, 0, 0, 255, 255}};
  m.images.push_back(texture);
  m.materials[0].base_color_image = 0;
  m.materials[0].sampler.wrap_s = projbot::assets::Wrap::kMirroredRepeat;
  for (const float u : {1.25F, 1e30F}) {
    for (auto& v : m.primitives[0].vertices) v.uv = {u, 0.5F};
    const auto s = projbot::assets::sample_surface(m, 50, 3);
    ASSERT_EQ(s.colours.size(), s.points.size());
    for (const auto& c : s.colours) EXPECT_EQ(c, u < 2.0F ? Eigen::Vector3f(0, 0, 1) : Eigen::Vector3f(1, 0, 0)) << u;
  }
}

TEST(ProceduralTest, UvSphereIsLargeAndRound) {
  const Model m = projbot::assets::make_uv_sphere(0.25, 224, 224);
  EXPECT_GE(m.triangle_count(), 100000U);
  for (const auto& v : m.primitives[0].vertices) ASSERT_NEAR(position(v).norm(), 0.25, 1e-6);
}

TEST_F(CorruptBox, ComputesMissingNormals) {
  const Model original = load_gltf(gltf());
  json_["meshes"][0]["primitives"][0]["attributes"].erase("NORMAL");
  save();
  const Model m = load_gltf(gltf());
  for (std::size_t i = 0; i < 24; ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(m.primitives[0].vertices[i].normal[static_cast<std::size_t>(k)],
                  original.primitives[0].vertices[i].normal[static_cast<std::size_t>(k)], 1e-5);
}

TEST_F(CorruptBox, SceneWithoutScenesUsesRootNodes) {
  json_.erase("scenes");
  json_.erase("scene");
  save();
  EXPECT_EQ(load_gltf(gltf()).triangle_count(), 12U);
}

TEST_F(CorruptBox, MissingFile) {
  expect_contains(
      [&] {
        fs::remove(gltf());
        return error();
      }(),
      "no such model file");
}

TEST_F(CorruptBox, MalformedJson) {
  std::ofstream(gltf()) << json_.dump().substr(0, 200);
  const auto msg = error();
  expect_contains(msg, gltf().string());
}

TEST_F(CorruptBox, EmptyFile) {
  std::ofstream(gltf()).close();
  expect_contains(error(), gltf().string());
}

TEST_F(CorruptBox, MissingBuffer) {
  fs::remove(bin());
  const auto msg = error();
  expect_contains(msg, gltf().string());
  expect_contains(msg, "BoxTextured0.bin");
}

TEST_F(CorruptBox, MissingImage) {
  fs::remove(dir_ / "CesiumLogoFlat.png");
  const auto msg = error();
  expect_contains(msg, "CesiumLogoFlat.png");
  expect_contains(msg, "missing or could not be decoded");
}

TEST_F(CorruptBox, AccessorOutOfRange) {
  json_["accessors"][2]["count"] = 1000;
  save();
  const auto msg = error();
  expect_contains(msg, "POSITION");
  expect_contains(msg, "accessor 2");
}

TEST_F(CorruptBox, BufferViewPastBuffer) {
  json_["bufferViews"][1]["byteLength"] = 5000;
  save();
  expect_contains(error(), "runs past the end of buffer");
}

TEST_F(CorruptBox, AccessorIndexOutOfRange) {
  json_["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 17;
  save();
  expect_contains(error(), "out of range");
}

TEST_F(CorruptBox, PointsAreNotTriangles) {
  json_["meshes"][0]["primitives"][0]["mode"] = 0;
  save();
  expect_contains(error(), "not a triangle primitive");
}

TEST_F(CorruptBox, LinesAreNotTriangles) {
  json_["meshes"][0]["primitives"][0]["mode"] = 1;
  save();
  expect_contains(error(), "not a triangle primitive");
}

TEST_F(CorruptBox, NanPosition) {
  const float nan = std::nanf("");
  patch_bin(0, &nan, 4);  // POSITION starts the buffer
  expect_contains(error(), "POSITION 0 is not finite");
}

TEST_F(CorruptBox, IndexPastVertices) {
  const std::uint16_t bad = 99;
  patch_bin(768 + 2 * 5, &bad, 2);  // the sixth index
  expect_contains(error(), "index 99 at position 5 is out of range");
}

TEST_F(CorruptBox, NodeCycle) {
  json_["nodes"][2]["children"] = nlohmann::json::array({0});
  save();
  expect_contains(error(), "cycle");
}

TEST_F(CorruptBox, MissingMesh) {
  json_["nodes"][2]["mesh"] = 5;
  save();
  expect_contains(error(), "mesh index 5 is out of range");
}

TEST_F(CorruptBox, BadMaterialIndex) {
  json_["meshes"][0]["primitives"][0]["material"] = 3;
  save();
  expect_contains(error(), "material index 3");
}

TEST_F(CorruptBox, BadAlphaMode) {
  json_["materials"][0]["alphaMode"] = "SOMETIMES";
  save();
  expect_contains(error(), "alphaMode");
}

// Issue 72: glTF's factors lie within 0..1; [1e30, -5, 1, 1] was drawn.
TEST_F(CorruptBox, ABaseColourFactorOutsideGltfsRangeIsRefused) {
  json_["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1e30, -5.0, 1.0, 1.0};
  save();
  expect_contains(error(), "material 0: baseColorFactor must be four numbers within 0..1");
}

TEST_F(CorruptBox, AlphaModesAndDoubleSidedAreRead) {
  json_["materials"][0]["alphaMode"] = "MASK";
  json_["materials"][0]["alphaCutoff"] = 0.3;
  json_["materials"][0]["doubleSided"] = true;
  json_["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {0.5, 0.25, 1.0, 0.75};
  json_["samplers"][0]["wrapS"] = 33071;
  json_["samplers"][0]["wrapT"] = 33648;
  save();
  const auto m = load_gltf(gltf()).materials[0];
  EXPECT_EQ(m.alpha_mode, projbot::assets::AlphaMode::kMask);
  EXPECT_FLOAT_EQ(m.alpha_cutoff, 0.3F);
  EXPECT_TRUE(m.double_sided);
  EXPECT_FLOAT_EQ(m.base_color_factor[1], 0.25F);
  EXPECT_EQ(m.sampler.wrap_s, projbot::assets::Wrap::kClampToEdge);
  EXPECT_EQ(m.sampler.wrap_t, projbot::assets::Wrap::kMirroredRepeat);
}

TEST_F(CorruptBox, TruncatedGlb) {
  const fs::path glb = dir_ / "Duck.glb";
  std::ifstream in(kData / "Duck" / "glTF-Binary" / "Duck.glb", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(glb, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  try {
    load_gltf(glb);
    FAIL() << "truncated .glb loaded";
  } catch (const AssetError& e) {
    expect_contains(e.what(), glb.string());
  }
}

TEST_F(CorruptBox, RandomByteFlipsNeverCrash) {
  // A cheap in-suite fuzz: flip bytes of the JSON and the buffer; loading must succeed or throw AssetError.
  std::mt19937 rng(1234);
  std::ifstream in(gltf());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (int round = 0; round < 300; ++round) {
    std::string mutated = text;
    for (int k = 0; k < 4; ++k) mutated[rng() % mutated.size()] = static_cast<char>(rng() % 128);
    std::ofstream(gltf()) << mutated;
    try {
      const Model m = load_gltf(gltf());
      for (const auto& p : m.primitives)
        for (auto i : p.indices) ASSERT_LT(i, p.vertices.size());
    } catch (const AssetError&) {
    }
  }
}

// KHR_texture_transform (issue 44) on the base colour texture: baked into the UVs as uv' = T R S uv.
TEST_F(CorruptBox, TextureTransformIsAppliedToTheUvs) {
  const Model original = load_gltf(gltf());
  const double ox = 0.25, oy = 0.5, r = 0.3, sx = 2.0, sy = 0.5;
  json_["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
      {"offset", {ox, oy}}, {"rotation", r}, {"scale", {sx, sy}}};
  json_["extensionsUsed"] = {"KHR_texture_transform"};
  save();
  const Model m = load_gltf(gltf());
  ASSERT_EQ(m.primitives[0].vertices.size(), original.primitives[0].vertices.size());
  for (std::size_t i = 0; i < m.primitives[0].vertices.size(); ++i) {
    const double u = original.primitives[0].vertices[i].uv[0], v = original.primitives[0].vertices[i].uv[1];
    // The extension's own matrices, multiplied out here: T * R * S.
    const Eigen::Matrix3d T = (Eigen::Matrix3d() << 1, 0, ox, 0, 1, oy, 0, 0, 1).finished();
    const Eigen::Matrix3d R =
        (Eigen::Matrix3d() << std::cos(r), std::sin(r), 0, -std::sin(r), std::cos(r), 0, 0, 0, 1).finished();
    const Eigen::Matrix3d S = Eigen::Vector3d(sx, sy, 1).asDiagonal();
    const Eigen::Vector3d want = T * R * S * Eigen::Vector3d(u, v, 1);
    EXPECT_NEAR(m.primitives[0].vertices[i].uv[0], want.x(), 1e-5) << i;
    EXPECT_NEAR(m.primitives[0].vertices[i].uv[1], want.y(), 1e-5) << i;
  }
  json_["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"]["offset"] = "left";
  save();
  expect_contains(error(), "material 0: KHR_texture_transform.offset is not two numbers");
}
