// Outputs that never lie: a failed write throws naming the file and leaves the previous file whole.

#include "projbot/config/output_file.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <thread>

#include "projbot/assets/image.hpp"
#include "projbot/assets/model.hpp"
#include "projbot/config/paths.hpp"

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

// A SIGALRM every 200 us whose handler has no SA_RESTART (as libFuzzer's timer has): every blocking call
// it lands in fails with EINTR unless the caller tries it again. Restores the old handler when it ends.
class SignalStorm {
 public:
  SignalStorm() {
    count() = 0;
    struct sigaction sa {};
    sa.sa_handler = [](int) { count().fetch_add(1, std::memory_order_relaxed); };
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    sigaction(SIGALRM, &sa, &old_);
    itimerval every{{0, 200}, {0, 200}};
    setitimer(ITIMER_REAL, &every, nullptr);
  }
  ~SignalStorm() {
    itimerval off{};
    setitimer(ITIMER_REAL, &off, nullptr);
    sigaction(SIGALRM, &old_, nullptr);
  }
  SignalStorm(const SignalStorm&) = delete;
  SignalStorm& operator=(const SignalStorm&) = delete;
  static std::atomic<long>& count() {
    static std::atomic<long> n{0};
    return n;
  }

 private:
  struct sigaction old_ {};
};

std::string pattern(std::size_t size) {
  std::string s(size, '\0');
  for (std::size_t i = 0; i < size; ++i) s[i] = static_cast<char>('a' + (i * 7919) % 26);
  return s;
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

// A depth image written as 16-bit PNG reads back value for value (stb writes 8 bits only; ours packs the
// rows with its deflate), and a mesh written as PLY loads back with its triangles and its scale.
TEST_F(AtomicFile, Gray16PngAndPlyMeshRoundTrip) {
  projbot::assets::Gray16Image depth{5, 3, {}};
  for (int i = 0; i < 15; ++i) depth.values.push_back(static_cast<std::uint16_t>(i * 4369));  // 0 .. 61166
  depth.values[7] = 65535;
  const fs::path png = dir_ / "depth.png";
  projbot::assets::write_png_gray16(png, depth);
  const auto back = projbot::assets::read_png_gray16(png);
  ASSERT_EQ(back.width, 5);
  ASSERT_EQ(back.height, 3);
  EXPECT_EQ(back.values, depth.values);
  expect_error([&] { projbot::assets::write_png_gray16("/dev/full", depth); }, "/dev/full");
  expect_error([&] { projbot::assets::write_png_gray16(dir_ / "empty.png", {0, 0, {}}); }, "empty");
  const projbot::assets::Model box = projbot::assets::make_box({-0.1, -0.2, 0.0}, {0.1, 0.2, 0.05}, {1.0F, 1.0F, 1.0F, 1.0F});
  const fs::path ply = dir_ / "box.ply";
  projbot::assets::write_ply(ply, box, 1000.0);
  const projbot::assets::Model mesh = projbot::assets::load_mesh(ply);
  EXPECT_EQ(mesh.triangle_count(), box.triangle_count());
  EXPECT_NEAR(mesh.bounds().max().y(), 200.0, 1e-3);  // millimetres, as written
  EXPECT_NEAR(mesh.bounds().min().z(), 0.0, 1e-3);
}

// A command's inputs against its outputs (issue 47): what would destroy an input is found, through links
// and "..", and what is harmless is not.
namespace {

using projbot::config::find_path_clash;
using projbot::config::NamedPath;

TEST_F(AtomicFile, AnOutputOnAnInputIsAClashThroughLinksAndDots) {
  std::ofstream(dir_ / "scene.yaml") << "a: 1\n";
  fs::create_symlink(dir_ / "scene.yaml", dir_ / "link.yaml");
  const std::vector<NamedPath> in{{"--scene", dir_ / "link.yaml", false}};
  const auto clash = find_path_clash(in, {{"--report", dir_ / "sub" / ".." / "scene.yaml", false}});
  ASSERT_TRUE(clash.has_value());
  EXPECT_NE(clash->find("--report"), std::string::npos) << *clash;
  EXPECT_NE(clash->find("is also the input --scene"), std::string::npos) << *clash;
  EXPECT_FALSE(find_path_clash(in, {{"--report", dir_ / "report.json", false}}).has_value());
}

TEST_F(AtomicFile, AnOutputFolderHoldingAnInputIsAClash) {
  fs::create_directories(dir_ / "rec");
  std::ofstream(dir_ / "rec" / "laser.rawlog") << "x";
  const std::vector<NamedPath> in{{"--rawlog", dir_ / "rec" / "laser.rawlog", false}};
  EXPECT_TRUE(find_path_clash(in, {{"--out-map", dir_ / "rec/", true}}).has_value());
  EXPECT_TRUE(find_path_clash(in, {{"--out-map", dir_, true}}).has_value());
  EXPECT_FALSE(find_path_clash(in, {{"--out-map", dir_ / "rec2", true}}).has_value());  // a name that starts alike
}

TEST_F(AtomicFile, AnExistingFileInsideAnInputFolderIsAClashANewOneIsNot) {
  fs::create_directories(dir_ / "cap");
  std::ofstream(dir_ / "cap" / "capture.yaml") << "x";
  const std::vector<NamedPath> in{{"DIR", dir_ / "cap", true}};
  EXPECT_TRUE(find_path_clash(in, {{"--out", dir_ / "cap" / "capture.yaml", false}}).has_value());
  EXPECT_FALSE(find_path_clash(in, {{"--out", dir_ / "cap" / "calibration.yaml", false}}).has_value());
}

TEST_F(AtomicFile, TwoOutputsOnOnePathAreAClash) {
  const auto clash = find_path_clash({}, {{"--out", dir_ / "x.png", false}, {"--profile", dir_ / "./x.png", false}});
  ASSERT_TRUE(clash.has_value());
  EXPECT_NE(clash->find("are the same path"), std::string::npos) << *clash;
}

TEST_F(AtomicFile, OnlyAFolderOfOurOwnFilesMayBeReplaced) {
  const std::set<std::string> ours{"map.simplemap.gz", "grid.png"};
  EXPECT_NO_THROW(projbot::config::check_replaceable_folder(dir_ / "new", ours));
  fs::create_directories(dir_ / "old");
  EXPECT_NO_THROW(projbot::config::check_replaceable_folder(dir_ / "old", ours));  // empty
  std::ofstream(dir_ / "old" / "grid.png") << "x";
  EXPECT_NO_THROW(projbot::config::check_replaceable_folder(dir_ / "old", ours));
  std::ofstream(dir_ / "old" / "notes.txt") << "mine";
  try {
    projbot::config::check_replaceable_folder(dir_ / "old", ours);
    ADD_FAILURE() << "a folder with the user's notes was accepted";
  } catch (const OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 'notes.txt'"), std::string::npos) << e.what();
  }
  EXPECT_THROW(projbot::config::check_replaceable_folder(dir_ / "old" / "notes.txt", ours), OutputError);
}

TEST_F(AtomicFile, InputsAreNamedByKind) {
  ASSERT_EQ(::mkfifo((dir_ / "f").c_str(), 0644), 0);
  EXPECT_EQ(projbot::config::input_file_problem(dir_ / "f"), "is a FIFO, not a regular file");
  EXPECT_EQ(projbot::config::input_file_problem("/dev/zero"), "is a character device, not a regular file");
  EXPECT_EQ(projbot::config::input_file_problem(dir_), "is a folder, not a file");
  EXPECT_EQ(projbot::config::input_file_problem(dir_ / "none"), "does not exist");
  std::ofstream(dir_ / "ok") << "x";
  EXPECT_EQ(projbot::config::input_file_problem(dir_ / "ok"), "");
}

// Issue 71: what the build makes for a shipped scene (the content scene's video) lives in the build tree.
// A shipped scene's relative name finds it there when it is not beside the scene; a file beside the scene,
// a name outside the shipped folder and an absolute name are taken as written.
TEST_F(AtomicFile, AShippedSceneFindsWhatTheBuildMadeForItInTheBuildTree) {
  using projbot::config::beside_scene;
  const fs::path shipped = dir_ / "assets", made = dir_ / "build" / "assets", scenes = shipped / "scenes";
  fs::create_directories(scenes);
  fs::create_directories(made / "videos");
  std::ofstream(made / "videos" / "clip.mp4") << "x";
  std::ofstream(dir_ / "clip.mp4") << "x";
  projbot::config::set_generated_assets(shipped, made);
  EXPECT_EQ(beside_scene("../videos/clip.mp4", scenes), made / "videos" / "clip.mp4");
  EXPECT_EQ(beside_scene("../videos/none.mp4", scenes), scenes / "../videos/none.mp4") << "missing everywhere: as named";
  EXPECT_EQ(beside_scene("../../clip.mp4", scenes), scenes / "../../clip.mp4") << "outside the shipped folder";
  EXPECT_EQ(beside_scene((dir_ / "x.mp4").string(), scenes), dir_ / "x.mp4");
  fs::create_directories(shipped / "videos");
  std::ofstream(shipped / "videos" / "clip.mp4") << "y";
  EXPECT_EQ(beside_scene("../videos/clip.mp4", scenes), scenes / "../videos/clip.mp4") << "beside the scene wins";
  EXPECT_EQ(beside_scene("videos/clip.mp4", dir_ / "elsewhere"), dir_ / "elsewhere" / "videos/clip.mp4");
  projbot::config::set_generated_assets({}, {});
  fs::remove(shipped / "videos" / "clip.mp4");
  EXPECT_EQ(beside_scene("../videos/clip.mp4", scenes), scenes / "../videos/clip.mp4") << "unset: beside the scene only";
}

}  // namespace

// Issue 73: a signal without SA_RESTART during a write. Into a FIFO whose reader is slow, open() blocks
// and every write() blocks on the full pipe, so the signals land inside them: each must be tried again,
// and the reader gets every byte in order. The same for a file written atomically and a copy.
TEST_F(AtomicFile, SignalsDuringWritesAreRetriedNotErrors) {
  const fs::path fifo = dir_ / "out.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string data = pattern(4 << 20);
  std::string got;
  SignalStorm storm;
  std::thread reader([&] {
    // The signals are for the writer's calls: a reader interrupted in its own open() gave up, and the
    // writer's open() then waited for a reader forever (seen in a fresh root beside a build).
    sigset_t alarm;
    sigemptyset(&alarm);
    sigaddset(&alarm, SIGALRM);
    pthread_sigmask(SIG_BLOCK, &alarm, nullptr);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the writer's open() waits for this
    std::ifstream in(fifo, std::ios::binary);
    char buf[4096];
    while (in.read(buf, sizeof buf) || in.gcount() > 0) {
      got.append(buf, static_cast<std::size_t>(in.gcount()));
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
  });
  EXPECT_NO_THROW(projbot::config::write_file_atomically(fifo, data));
  reader.join();
  EXPECT_EQ(got.size(), data.size());
  EXPECT_TRUE(got == data) << "the FIFO's reader got other bytes than were written";

  const fs::path file = dir_ / "big.bin", copy = dir_ / "copy.bin";
  EXPECT_NO_THROW(projbot::config::write_file_atomically(file, data));
  EXPECT_NO_THROW(projbot::config::copy_file(file, copy));
  EXPECT_TRUE(read(file) == data);
  EXPECT_TRUE(read(copy) == data);
  EXPECT_GT(SignalStorm::count().load(), 100) << "the signals did not land during the writes";
}

TEST_F(AtomicFile, CopyNamesTheFileThatFailed) {
  expect_error([&] { projbot::config::copy_file(dir_ / "none.oni", dir_ / "copy.oni"); }, "none.oni");
  projbot::config::write_file_atomically(dir_ / "a.oni", "abc");
  expect_error([&] { projbot::config::copy_file(dir_ / "a.oni", dir_ / "no" / "copy.oni"); }, "copy.oni");
  expect_error([&] { projbot::config::copy_file(dir_ / "a.oni", "/dev/full"); }, "/dev/full: cannot write the copy");
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0) << "the device named as the copy was removed";
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device named as the copy was replaced";
}
