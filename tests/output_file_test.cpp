// Outputs that never lie: a failed write throws naming the file and leaves the previous file whole.

#include "projbot/config/output_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <sstream>

#include "projbot/assets/image.hpp"

namespace fs = std::filesystem;
using projbot::assets::AssetError;
using projbot::config::OutputError;

namespace {

class AtomicFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("projbot_atomic_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  static std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::size_t entries() const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  fs::path dir_;
};

// Expects f to throw AssetError whose message contains `needle`.
template <class F>
void expect_error(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << needle;
  } catch (const std::runtime_error& e) {  // OutputError, or AssetError from write_png
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST_F(AtomicFile, WritesAndReplaces) {
  const fs::path p = dir_ / "report.json";
  projbot::config::write_file_atomically(p, "first");
  projbot::config::write_file_atomically(p, "second, longer");
  EXPECT_EQ(read(p), "second, longer");
  EXPECT_EQ(entries(), 1U) << "no temporary file is left behind";
}

TEST_F(AtomicFile, PreviousFileSurvivesAFileSizeLimit) {
  const fs::path p = dir_ / "frame.png";
  projbot::config::write_file_atomically(p, "the good file");
  // Under a 4 KiB file size limit a 64 KiB write fails (EFBIG once SIGXFSZ is ignored).
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 4096;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string big(64 * 1024, 'x');
  expect_error([&] { projbot::config::write_file_atomically(p, big); }, p.string());
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(read(p), "the good file");
  EXPECT_EQ(entries(), 1U) << "the temporary file is removed";
}

TEST_F(AtomicFile, FullDeviceAndMissingFolderAreErrors) {
  expect_error([] { projbot::config::write_file_atomically("/dev/full", "x"); }, "/dev/full");
  expect_error([&] { projbot::config::write_file_atomically(dir_ / "none" / "a.csv", "x"); }, "a.csv");
  expect_error([&] { projbot::config::write_file_atomically(dir_, "x"); }, "folder");
}

TEST_F(AtomicFile, CheckWritableBeforeLongWork) {
  EXPECT_NO_THROW(projbot::config::check_writable(dir_ / "new.png"));
  expect_error([&] { projbot::config::check_writable(dir_ / "none" / "new.png"); }, "does not exist");
  expect_error([&] { projbot::config::check_writable(dir_); }, "is a folder");
}

TEST_F(AtomicFile, PngRoundTripAndFailedPngWrite) {
  projbot::assets::Image img;
  img.width = 3;
  img.height = 2;
  img.rgba.assign(3 * 2 * 4, 0);
  img.pixel(2, 1)[0] = 200;
  img.pixel(2, 1)[3] = 255;
  const fs::path p = dir_ / "img.png";
  projbot::assets::write_png(p, img);
  const auto back = projbot::assets::read_image(p);
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  EXPECT_EQ(back.pixel(2, 1)[0], 200);
  expect_error([&] { projbot::assets::write_png("/dev/full", img); }, "/dev/full");
}
