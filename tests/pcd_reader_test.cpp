// Hostile PCD files: each is refused with one message naming the file and what is wrong, before PCL's
// reader (which crashed on several of them, or allocated what POINTS claimed) sees it.

#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <random>

#include "../alignment/src/ply_body.hpp"
#include "projbot/alignment/depth.hpp"
#include "projbot/alignment/registration.hpp"

namespace fs = std::filesystem;
using namespace projbot::alignment;

namespace {

const fs::path kData = PROJBOT_SHARED_DATA;

const std::string kHeader =
    "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
    "POINTS 3\n";

class PcdReader : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("projbot_pcd_" + std::to_string(::getpid()) + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& bytes) const {
    const fs::path p = dir_ / "cloud.pcd";
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
    return p;
  }
  // The file is refused with a message naming it and containing `needle`.
  void expect_refused(const std::string& bytes, const std::string& needle) const {
    const fs::path p = write(bytes);
    try {
      read_cloud(p);
      ADD_FAILURE() << "accepted; expected an error containing '" << needle << "'";
    } catch (const AlignmentError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(p.string()), std::string::npos) << what;
      EXPECT_NE(what.find(needle), std::string::npos) << what;
    }
  }
  fs::path dir_;
};

std::string binary_floats(int n) {
  std::string s(static_cast<std::size_t>(n) * 12, '\0');
  for (int i = 0; i < n * 3; ++i) {
    const float v = 0.1F * static_cast<float>(i);
    std::memcpy(s.data() + i * 4, &v, 4);
  }
  return s;
}

}  // namespace

TEST_F(PcdReader, GoodFilesStillRead) {
  EXPECT_EQ(read_cloud(write(kHeader + "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n")).points.size(), 3U);
  const PointCloud b = read_cloud(write(kHeader + "DATA binary\n" + binary_floats(3)));
  ASSERT_EQ(b.points.size(), 3U);
  EXPECT_FLOAT_EQ(b.points[2].z(), 0.8F);
  EXPECT_EQ(read_cloud(kData / "bunny" / "bun0.pcd").points.size(), 397U);
  // binary_compressed, organised 640x480 (a real Kinect frame from PCL's grabber tests).
  EXPECT_EQ(read_cloud(kData / "rgbd" / "pcl_grabber_sequence" / "frame_20121214T142255.814212.pcd").points.size(), 307200U);
}

TEST_F(PcdReader, EmptyHeaderOnlyAndRandomBytes) {
  expect_refused("", "empty");
  expect_refused(kHeader, "no DATA line");
  expect_refused(kHeader + "DATA ascii\n", "claims 3 points");
  expect_refused(kHeader + "DATA binary\n", "claims 3 points");
  expect_refused(kHeader + "DATA binary_compressed\n", "compressed data section is missing");
  std::mt19937 rng(7);
  std::string noise(4096, '\0');
  for (auto& c : noise) c = static_cast<char>(rng());
  expect_refused(noise, "malformed PCD file");
}

TEST_F(PcdReader, HeaderContradictions) {
  expect_refused("FIELDS a b c\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n", "no 'x' field");
  expect_refused("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n", "3 FIELDS but 2 SIZE");
  expect_refused("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n", "SIZE must be 1, 2, 4 or 8");
  expect_refused("FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1 2 3\n", "TYPE must be");
  expect_refused("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n", "POINTS 3 is not");
  expect_refused("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH -1\nHEIGHT 1\nDATA ascii\n1 2 3\n", "WIDTH must be a whole number");
  expect_refused("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nHEIGHT 1\nDATA ascii\n", "WIDTH and HEIGHT must be > 0");
  expect_refused("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nDATA json\n", "DATA must be");
  expect_refused(kHeader + "DATA binary\n" + binary_floats(2), "claims 3 points of 12 bytes");
  // A compressed section that says it unpacks to more than the points need.
  std::string lying = kHeader + "DATA binary_compressed\n";
  const std::uint32_t sizes[2] = {4, 1000000};
  lying.append(reinterpret_cast<const char*>(sizes), 8).append("abcd");
  expect_refused(lying, "unpacks to 1000000 bytes");
}

// A 4.9 KB file claiming 2e9 points once made the process allocate 21 GB: now refused from its header,
// before anything is allocated for the points, in every DATA mode.
TEST_F(PcdReader, HugeClaimIsRefusedQuicklyInLittleMemory) {
  std::string body = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2000000000\nHEIGHT 1\nPOINTS 2000000000\nDATA binary\n";
  body += std::string(4800, '\1');
  const fs::path p = write(body);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    read_cloud(p);
    ADD_FAILURE() << "accepted";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("claims 2000000000 points"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  for (const char* mode : {"ascii", "binary_compressed"}) {
    std::string other = body;
    other.replace(other.find("binary\n"), 7, std::string(mode) + "\n");
    expect_refused(other, "2000000000 points");
  }
}

// A PLY cloud's body must end where its header's counts say (issue 47: a binary PLY holding more
// vertices than it declared was half read and its pose accepted).
namespace {

std::string ply_cloud(const std::string& format, int declared, int stored) {
  std::string s = "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(declared) +
                  "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (int i = 0; i < stored; ++i) {
    const float v[3] = {0.01f * static_cast<float>(i), 0.02f * static_cast<float>(i % 7), 1.0f};
    if (format == "ascii")
      s += std::to_string(v[0]) + " " + std::to_string(v[1]) + " " + std::to_string(v[2]) + "\n";
    else
      s.append(reinterpret_cast<const char*>(v), sizeof v);
  }
  return s;
}

TEST_F(PcdReader, PlyBodiesMustMatchTheirHeaders) {
  const fs::path p = dir_ / "cloud.ply";
  const auto refused = [&](const std::string& bytes, const std::string& needle) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
    try {
      read_cloud(p);
      ADD_FAILURE() << "accepted: " << needle;
    } catch (const AlignmentError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  for (const std::string format : {"binary_little_endian", "ascii"}) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << ply_cloud(format, 40, 40);
    EXPECT_EQ(read_cloud(p).points.size(), 40u) << format;
  }
  refused(ply_cloud("binary_little_endian", 30, 40), "120 bytes follow them");
  refused(ply_cloud("binary_little_endian", 40, 30), "more than the file holds");
  refused(ply_cloud("ascii", 30, 40), "the body holds 40 lines");
  refused(ply_cloud("binary_little_endian", 40, 40).replace(4, 27, "format binary_middle_endian"), "binary_middle_endian");
  // Issue 72: without x, y and z PCL read points at the origin and align said "NOT converged".
  refused(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float a\nproperty float b\nproperty float c\nend_header\n"
      "0 0 1\n1 0 1\n",
      "its vertex element has no x, y and z properties");
}

// The shared real models (binary, with normals and face lists) pass the same walk.
TEST_F(PcdReader, RealPlyMeshesPassTheBodyCheck) {
  int checked = 0;
  for (const auto& e : fs::directory_iterator(kData / "ycbv-bop" / "models"))
    if (e.path().extension() == ".ply") {
      EXPECT_NO_THROW(detail::check_ply_body(e.path())) << e.path();
      ++checked;
    }
  EXPECT_GE(checked, 10);
}

}  // namespace

// A model with too few points is named by its file (issue 47: "model needs at least 10 points ... (got 0)").
TEST(ModelCloudMessages, NameTheFile) {
  ModelCloud m;
  m.points = {Eigen::Vector3f(0, 0, 1)};
  m.normals = {Eigen::Vector3f(0, 0, 1)};
  m.source = "/models/tiny.ply";
  try {
    Aligner aligner(m, AcquisitionConfig{});
    ADD_FAILURE() << "a one-point model was accepted";
  } catch (const AlignmentError& e) {
    EXPECT_NE(std::string(e.what()).find("/models/tiny.ply: the model needs at least 10 points"), std::string::npos) << e.what();
  }
}
