// PLY / OBJ / STL meshes through Assimp (assets::load_mesh): the shared YCB-V models as they come, and small
// files written here for what those do not cover.

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>

#include "projbot/assets/image.hpp"
#include "projbot/assets/model.hpp"

namespace fs = std::filesystem;
using projbot::assets::AssetError;
using projbot::assets::load_mesh;
using projbot::assets::load_model;

namespace {

const fs::path kYcbv = fs::path(PROJBOT_SHARED_DATA) / "ycbv-bop";

class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_mesh_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

std::size_t vertex_count(const projbot::assets::Model& m) {
  std::size_t n = 0;
  for (const auto& p : m.primitives) n += p.vertices.size();
  return n;
}

// A unit tetrahedron with outward faces, as ASCII PLY without normals.
const char* const kTetraPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

}  // namespace

TEST(MeshLoader, ReadsABopPlyInMillimetres) {
  auto mug = load_mesh(kYcbv / "models" / "obj_000014.ply");
  EXPECT_EQ(mug.triangle_count(), 15728U);
  EXPECT_EQ(vertex_count(mug), 7860U);
  // models_info.json: size_x 116.966, size_z 81.384 mm.
  EXPECT_NEAR(mug.bounds().sizes().x(), 116.966, 0.01);
  EXPECT_NEAR(mug.bounds().sizes().z(), 81.384, 0.01);
  projbot::assets::scale_and_recenter(mug, 0.001, false);
  EXPECT_NEAR(mug.bounds().sizes().x(), 0.116966, 1e-5);
  EXPECT_NEAR(mug.bounds().min().x(), -0.050214, 1e-5);  // the file's origin kept
  for (const auto& v : mug.primitives[0].vertices) ASSERT_NEAR(std::hypot(v.normal[0], v.normal[1], v.normal[2]), 1.0, 1e-3);
}

TEST(MeshLoader, AnObjWhoseTextureIsMissingKeepsItsBaseColour) {
  testing::internal::CaptureStderr();
  const auto box = load_model(kYcbv / "models_obj" / "003_cracker_box" / "textured_simple.obj");
  const std::string warning = testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("warning"), std::string::npos);
  EXPECT_NE(warning.find("texture_map.png not used"), std::string::npos) << warning;
  ASSERT_FALSE(box.primitives.empty());
  const auto& material = box.materials.at(static_cast<std::size_t>(box.primitives[0].material));
  EXPECT_EQ(material.base_color_image, -1);
  EXPECT_GT(material.base_color_factor[0], 0.1F);  // the .mtl's Kd, not black
  // The same box as BOP's PLY, in metres: the same extent.
  auto ply = load_mesh(kYcbv / "models" / "obj_000002.ply");
  projbot::assets::scale_and_recenter(ply, 0.001, false);
  EXPECT_LT((box.bounds().sizes() - ply.bounds().sizes()).cwiseAbs().maxCoeff(), 0.001);
}

TEST_F(MeshFiles, NormalsComeFromTheFacesWhenTheFileHasNone) {
  const auto tetra = load_mesh(write("t.ply", kTetraPly));
  EXPECT_EQ(tetra.triangle_count(), 4U);
  // Each vertex normal points away from the centroid (outward faces, smoothed).
  const Eigen::Vector3d centre(0.25, 0.25, 0.25);
  for (const auto& p : tetra.primitives)
    for (const auto& v : p.vertices) {
      const Eigen::Vector3d n(v.normal[0], v.normal[1], v.normal[2]);
      const Eigen::Vector3d out = Eigen::Vector3d(v.position[0], v.position[1], v.position[2]) - centre;
      EXPECT_NEAR(n.norm(), 1.0, 1e-4);
      EXPECT_GT(n.dot(out), 0.0);
    }
}

// What `run` watches of a mesh: the OBJ, the material library it names and the texture that names; a
// texture not there yet is watched all the same (drawn once it appears).
TEST_F(MeshFiles, AnObjsFilesAreItselfItsMaterialLibraryAndItsTextures) {
  projbot::assets::Image texture;
  texture.width = texture.height = 2;
  texture.rgba.assign(16, 200);
  projbot::assets::write_png((dir_ / "wood.png").string(), texture);
  write("wood.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd wood.png\nnewmtl stone\nKd 0.2 0.2 0.2\nmap_Kd stone.png\n");
  const fs::path obj = write("two.obj",
                             "mtllib wood.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0 1\n"
                             "usemtl wood\nf 1/1 2/2 3/3\nusemtl stone\nf 1/1 2/2 4/3\n");
  testing::internal::CaptureStderr();
  const auto model = load_model(obj);
  EXPECT_NE(testing::internal::GetCapturedStderr().find("stone.png not used"), std::string::npos);
  const std::vector<fs::path> expected = {obj, dir_ / "wood.png", dir_ / "stone.png", dir_ / "wood.mtl"};
  EXPECT_EQ(model.files, expected);
  EXPECT_EQ(load_model(write("t.ply", kTetraPly)).files, std::vector<fs::path>{dir_ / "t.ply"});
}

// Issue 72: a texture that is a FIFO blocked the load (and every command) forever; now it is not opened,
// said by kind, and the material keeps its colour.
TEST_F(MeshFiles, ATextureThatIsAFifoIsNotOpened) {
  ASSERT_EQ(::mkfifo((dir_ / "f.png").c_str(), 0600), 0);
  write("f.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd f.png\n");
  const fs::path obj =
      write("f.obj", "mtllib f.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl a\nf 1/1 2/2 3/3\n");
  testing::internal::CaptureStderr();
  const auto model = load_model(obj);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find((dir_ / "f.png").string() + " not used (" + (dir_ / "f.png").string() + ": is a FIFO, not a regular file"),
            std::string::npos)
      << said;
  EXPECT_TRUE(model.images.empty());
  for (const auto& m : model.materials) EXPECT_LT(m.base_color_image, 0);
}

TEST_F(MeshFiles, ReadsAnAsciiStl) {
  const auto stl =
      load_model(write("t.stl",
                       "solid t\n"
                       "facet normal 0 0 -1\n outer loop\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 1 0 0\n endloop\nendfacet\n"
                       "facet normal 0 -1 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\n"
                       "endsolid t\n"));
  EXPECT_EQ(stl.triangle_count(), 2U);
  EXPECT_NEAR(stl.bounds().sizes().x(), 1.0, 1e-6);
}

TEST_F(MeshFiles, BadMeshesAreNamedErrors) {
  const auto message = [](const fs::path& p) {
    try {
      load_model(p);
    } catch (const AssetError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  const fs::path points = write("points.ply",
                                "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                                "end_header\n0 0 0\n1 0 0\n0 1 0\n");
  std::string m = message(points);
  EXPECT_EQ(m.rfind(points.string() + ": ", 0), 0U) << m;
  const fs::path garbage = write("garbage.stl", std::string(300, '\x7f'));
  m = message(garbage);
  EXPECT_EQ(m.rfind(garbage.string() + ": ", 0), 0U) << m;
  // A face naming a vertex the file does not have.
  std::string bad = kTetraPly;
  bad.replace(bad.find("3 1 2 3"), 7, "3 1 2 9");
  const fs::path beyond = write("beyond.ply", bad);
  m = message(beyond);
  EXPECT_EQ(m.rfind(beyond.string() + ": ", 0), 0U) << m;
  // Issue 72: a header declaring 2 of the 4 faces it holds was drawn in half; align refused the same file.
  std::string half = kTetraPly;
  half.replace(half.find("element face 4"), 14, "element face 2");
  const fs::path halved = write("half.ply", half);
  m = message(halved);
  EXPECT_NE(m.find(halved.string() + ": the header declares 6 elements (4 vertices), the body holds 8 lines"), std::string::npos)
      << m;
  m = message(dir_ / "none.obj");
  EXPECT_EQ(m, (dir_ / "none.obj").string() + ": no such file");
  m = message(write("x.fbx2", "x"));
  EXPECT_NE(m.find("unknown model format '.fbx2'"), std::string::npos) << m;
  m = message(dir_);
  EXPECT_EQ(m, dir_.string() + ": is a folder, not a model file");
}
