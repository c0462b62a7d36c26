// The operator's console through the executable (issue 70): `projbot run --sim --headless --console`
// serves the page and its API while the twin tours; the projector's frame and the camera's view as small
// pictures; a blackout asked over HTTP blacks the projector out (counted in the run's closing lines, with
// the time from the request to its first black frame), a pause holds the robot at its stop, a go-to sends
// it to the target asked for, and bad options are refused before anything opens.

// clang-format off
#include "cli_fixture.hpp"  // before httplib.h: it brings resolv.h, whose _res macro breaks Eigen's headers after it
#include <httplib.h>
// clang-format on
#include <gtest/gtest.h>
#include <lo/lo.h>
#include <sys/stat.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "projbot/assets/image.hpp"
#include "raw_http.hpp"

using namespace cli_fixture;

namespace {

using nlohmann::json;

int console_port(const std::string& output) {
  const std::string key = "console: http://127.0.0.1:";
  const auto at = output.find(key);
  return at == std::string::npos ? -1 : std::stoi(output.substr(at + key.size()));
}

// Polls the state until `done` says so or `limit_s` pass; the last state read.
json wait_state(httplib::Client& c, const std::function<bool(const json&)>& done, double limit_s) {
  json last;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  while (std::chrono::steady_clock::now() < end) {
    if (const auto r = c.Get("/api/state"); r && r->status == 200) {
      last = json::parse(r->body);
      if (done(last)) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return last;
}

// The newest picture of `kind` ("frame", "camera") that satisfies `done`, asked for twice a second as the
// page asks, within `limit_s`; an empty image when none came.
projbot::assets::Image wait_picture(httplib::Client& c, const std::string& kind, const fs::path& dir,
                                    const std::function<bool(const projbot::assets::Image&)>& done, double limit_s) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_s);
  const fs::path file = dir / (kind + ".png");
  while (std::chrono::steady_clock::now() < end) {
    if (const auto r = c.Get("/api/" + kind + ".png"); r && r->status == 200) {
      std::ofstream(file, std::ios::binary) << r->body;
      projbot::assets::Image image = projbot::assets::read_image(file);
      if (done(image)) return image;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  return {};
}

httplib::Result post(httplib::Client& c, const std::string& path, const json& body) {
  return c.Post(path.c_str(), body.dump(), "application/json");
}

TEST_F(CliTest, RunServesTheConsoleItsBlackoutAndGoTo) {
  cli_fixture::Background run({"run", "--sim", "--headless", "--depth-model", "kinect", "--visits", "2", "--dwell", "6",
                               "--console", "127.0.0.1:0", "--osc", "0"},
                              dir_ / "run.log");
  ASSERT_TRUE(run.wait_for_output("console: http://", std::chrono::seconds(60))) << run.output();
  const int port = console_port(run.output());
  ASSERT_GT(port, 0) << run.output();
  ASSERT_TRUE(run.wait_for_output("osc: UDP port ", std::chrono::seconds(10))) << run.output();
  const std::string osc_port = std::to_string(std::stoi(run.output().substr(run.output().find("osc: UDP port ") + 14)));
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(5, 0);

  json s = wait_state(
      c, [](const json& j) { return j.at("phase") == "lit"; }, 90.0);
  ASSERT_EQ(s.at("phase"), "lit") << s.dump();
  EXPECT_EQ(s.at("visiting"), "duck");
  EXPECT_GT(s.at("frame_rate_hz").get<double>(), 10.0);

  // Held at the duck (the dwell does not end while paused) for what follows.
  ASSERT_EQ(post(c, "/api/pause", {{"on", true}})->status, 200);
  // The pictures: the projector's frame with the duck's light in it, the camera's view, both small.
  const auto lit_frame = [](const projbot::assets::Image& i) { return i.lit_pixels() > 100; };
  const projbot::assets::Image frame = wait_picture(c, "frame", dir_, lit_frame, 10.0);
  EXPECT_EQ(frame.width, 320);
  EXPECT_GT(frame.lit_pixels(), 100U);
  const projbot::assets::Image camera = wait_picture(c, "camera", dir_, lit_frame, 10.0);
  EXPECT_EQ(camera.width, 320);
  EXPECT_EQ(camera.height, 240);

  ASSERT_EQ(post(c, "/api/blackout", {{"on", true}})->status, 200);
  s = wait_state(
      c, [](const json& j) { return j.at("blackout") == true; }, 5.0);
  EXPECT_TRUE(s.at("blackout").get<bool>()) << s.dump();
  // The projector's picture goes black with it.
  const projbot::assets::Image dark = wait_picture(
      c, "frame", dir_, [](const projbot::assets::Image& i) { return i.width > 0 && i.lit_pixels() == 0; }, 5.0);
  EXPECT_EQ(dark.width, 320) << "no black picture of the projector's frame during the blackout";
  ASSERT_EQ(post(c, "/api/blackout", {{"on", false}})->status, 200);
  // The tour would go to the box next: ask for the duck again, over OSC, and see the robot leave for it.
  const lo_address desk = lo_address_new("127.0.0.1", osc_port.c_str());
  EXPECT_GT(lo_send(desk, "/projbot/goto", "s", "duck"), 0);  // bytes sent
  lo_address_free(desk);
  ASSERT_EQ(post(c, "/api/pause", {{"on", false}})->status, 200);
  s = wait_state(
      c, [](const json& j) { return j.at("visit").get<int>() >= 2 && j.at("visiting") == "duck"; }, 90.0);
  EXPECT_EQ(s.at("visit"), 2) << s.dump();
  EXPECT_EQ(s.at("visiting"), "duck") << s.dump();
  EXPECT_EQ(post(c, "/api/goto", {{"target", "nowhere"}})->status, 404);

  const auto [code, after_s] = run.signal_and_wait(SIGINT, std::chrono::seconds(60));
  EXPECT_EQ(code, 130) << run.output();
  const std::string out = run.output();
  EXPECT_NE(out.find("visit 2: duck"), std::string::npos) << out;  // the go-to, not the tour's box
  const auto line = out.rfind("console: ");                        // the closing line: "console: N frames blacked out; ..."
  ASSERT_NE(out.find("frames blacked out;", line), std::string::npos) << out;
  const int black = std::stoi(out.substr(line + 9));
  EXPECT_GE(black, 5) << out;  // half a second at 60 Hz, paced on a loaded machine
  const auto ms_at = out.find("first black frame's display: ");
  ASSERT_NE(ms_at, std::string::npos) << out;
  const double latency_ms = std::stod(out.substr(ms_at + 29));
  // The goal (one frame + 5 ms) is a measured figure; here, that it took effect within a few frames.
  EXPECT_GT(latency_ms, 0.0) << out;
  EXPECT_LT(latency_ms, 250.0) << out;
  EXPECT_NE(out.find("1 requests refused; OSC: 1 actions taken, 0 messages refused, 0 states sent"), std::string::npos) << out;
}

// The site file starts the controls (issue 70: `console: {listen, token_file}` and `osc: {port, allow, send}`):
// the tour scene with both sections serves the page and listens for OSC without an option given; a console
// off loopback needs the site's token file (mode 0600), refused naming the site file's key otherwise.
TEST_F(CliTest, RunStartsTheControlsTheSiteFileNames) {
  const std::string tour = shipped_scene("tour.yaml");
  const fs::path site = write("site.yaml", tour + "console: {listen: \"127.0.0.1:0\"}\nosc: {port: 49555, allow: [10.0.0.7]}\n");
  const CliRun r = run_projbot("run --sim --headless --seconds 2 --config " + site.string());
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_GT(console_port(r.output), 0) << r.output;
  EXPECT_NE(r.output.find("osc: UDP port 49555, actions from loopback, 10.0.0.7"), std::string::npos) << r.output;

  const fs::path open = write("open.yaml", tour + "console: {listen: \"0.0.0.0:0\"}\n");
  const CliRun refused = run_projbot("run --sim --headless --seconds 1 --config " + open.string());
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_NE(refused.output.find("console.listen in " + open.string() +
                                " 0.0.0.0:0: a console on an address other than "
                                "loopback needs a token (console.token_file in " +
                                open.string() + ")"),
            std::string::npos)
      << refused.output;
  const fs::path token = write("token", "a-token-of-sixteen-or-more\n");
  ::chmod(token.c_str(), 0600);
  const fs::path with_token = write("token.yaml", tour + "console: {listen: \"0.0.0.0:0\", token_file: token}\n");
  const CliRun served = run_projbot("run --sim --headless --seconds 1 --config " + with_token.string());
  EXPECT_EQ(served.code, 0) << served.output;
  EXPECT_NE(served.output.find("(actions need the token)"), std::string::npos) << served.output;
  const CliRun bad =
      run_projbot("run --sim --headless --seconds 1 --config " + write("bad.yaml", tour + "osc: {port: 0}\n").string());
  EXPECT_EQ(bad.code, 1) << bad.output;
  EXPECT_NE(bad.output.find("osc.port"), std::string::npos) << bad.output;
}

TEST_F(CliTest, RunRefusesAConsoleItCannotServeSafely) {
  const CliRun open = run_projbot("run --sim --headless --seconds 1 --console 0.0.0.0:0");
  EXPECT_EQ(open.code, 2) << open.output;
  EXPECT_NE(open.output.find("needs a token"), std::string::npos) << open.output;
  const fs::path token = write("token", "a-token-of-sixteen-or-more\n");
  ::chmod(token.c_str(), 0644);
  const CliRun readable = run_projbot("run --sim --headless --seconds 1 --console 0.0.0.0:0 --console-token " + token.string());
  EXPECT_EQ(readable.code, 2) << readable.output;
  EXPECT_NE(readable.output.find("chmod 600"), std::string::npos) << readable.output;
  const CliRun port = run_projbot("run --sim --headless --seconds 1 --console 127.0.0.1:99999");
  EXPECT_EQ(port.code, 2) << port.output;
  EXPECT_NE(port.output.find("--console '127.0.0.1:99999'"), std::string::npos) << port.output;
  const CliRun alone = run_projbot("run --sim --headless --seconds 1 --console-token " + token.string());
  EXPECT_EQ(alone.code, 2) << alone.output;
  EXPECT_NE(alone.output.find("--console-token applies to --console"), std::string::npos) << alone.output;
}

// Switching a target's video from the console (issue 70): the content scene with the site's
// `content_folder:`, a video in it switched to on the duck over HTTP, said in run's output as it comes in;
// a folder that is not there refused naming the key.
TEST_F(CliTest, RunSwitchesATargetsVideoFromTheContentFolder) {
  std::string scene = shipped_scene("content.yaml");
  for (std::size_t at = 0; (at = scene.find("../videos/", at)) != std::string::npos;)
    scene.replace(at, 3, std::string(PROJBOT_GENERATED_ASSET_DIR) + "/");
  fs::create_directories(dir_ / "videos");
  fs::copy_file(fs::path(PROJBOT_GENERATED_ASSET_DIR) / "videos" / "countdown.mp4", dir_ / "videos" / "second.mp4");
  const fs::path site = write("content_site.yaml", scene + "content_folder: videos\n");
  cli_fixture::Background run({"run", "--sim", "--headless", "--depth-model", "kinect", "--visits", "1", "--dwell", "30",
                               "--config", site.string(), "--console", "127.0.0.1:0"},
                              dir_ / "content_run.log");
  ASSERT_TRUE(run.wait_for_output("console: http://", std::chrono::seconds(60))) << run.output();
  httplib::Client c("127.0.0.1", console_port(run.output()));
  c.set_read_timeout(5, 0);
  EXPECT_EQ(json::parse(c.Get("/api/content")->body).at("files"), json::array({"second.mp4"}));
  ASSERT_EQ(wait_state(
                c, [](const json& j) { return j.at("phase") == "lit"; }, 90.0)
                .at("phase"),
            "lit");
  EXPECT_EQ(post(c, "/api/content", {{"target", "duck"}, {"file", "../content_site.yaml"}})->status, 404);
  ASSERT_EQ(post(c, "/api/content", {{"target", "duck"}, {"file", "second.mp4"}})->status, 200);
  EXPECT_TRUE(run.wait_for_output("second.mp4: now plays on 'duck', from its start", std::chrono::seconds(20))) << run.output();
  const json s = wait_state(
      c, [](const json& j) { return j.at("targets").at(0).at("content") == "second.mp4"; }, 5.0);
  EXPECT_EQ(s.at("targets").at(0).at("content"), "second.mp4") << s.dump();
  EXPECT_EQ(s.at("targets").at(1).at("content"), "countdown.mp4") << s.dump();  // the box goes on with its own
  const auto [code, after_s] = run.signal_and_wait(SIGINT, std::chrono::seconds(60));
  EXPECT_EQ(code, 130) << run.output();

  const fs::path nowhere = write("nowhere.yaml", scene + "content_folder: nowhere\n");
  const CliRun refused = run_projbot("run --sim --headless --seconds 1 --config " + nowhere.string());
  EXPECT_EQ(refused.code, 1) << refused.output;  // a scene file's error, as every other
  EXPECT_NE(refused.output.find("content_folder"), std::string::npos) << refused.output;
  EXPECT_NE(refused.output.find("nowhere is not a folder"), std::string::npos) << refused.output;
}

// The hostile run (issue 70, item 5) through the executable: a twin run with a token on its console takes
// a thousand malformed requests, a body claiming 100 MB, 200 silent connections, a wrong token twenty
// times, paths out of the page and a content name out of its folder. Every one is refused, nothing is
// acted on, and the show goes on: its state keeps coming at the projector's rate, the run ends on Ctrl-C
// as always, having drawn its frames.
TEST_F(CliTest, RunGoesOnUnderHostileConsoleClients) {
  const fs::path token = dir_ / "hostile_token";
  std::ofstream(token) << "a-token-of-sixteen-or-more\n";
  fs::permissions(token, fs::perms::owner_read | fs::perms::owner_write);
  std::set<std::string> before;
  for (const auto& e : fs::directory_iterator(dir_)) before.insert(e.path().filename().string());
  cli_fixture::Background run({"run", "--sim", "--headless", "--depth-model", "kinect", "--visits", "2", "--dwell", "20",
                               "--console", "127.0.0.1:0", "--console-token", token.string()},
                              dir_ / "hostile_run.log");
  ASSERT_TRUE(run.wait_for_output("console: http://", std::chrono::seconds(60))) << run.output();
  const int port = console_port(run.output());
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(30, 0);  // behind the silent connections, each given up on after the read timeout
  ASSERT_EQ(wait_state(
                c, [](const json& j) { return j.at("phase") == "lit"; }, 90.0)
                .at("phase"),
            "lit");
  const std::vector<std::string> junk = raw_http::junk();
  std::size_t answered_otherwise = 0;
  for (int i = 0; i < 1000; ++i) {
    const std::string answer = raw_http::send(port, junk[static_cast<std::size_t>(i) % junk.size()]);
    answered_otherwise += !answer.empty() && answer.rfind("HTTP/1.1 4", 0) != 0 ? 1 : 0;  // closed unanswered: refused too
  }
  EXPECT_EQ(answered_otherwise, 0U);
  const std::string huge = raw_http::send(port, raw_http::huge_body());
  EXPECT_TRUE(huge.empty() || huge.rfind("HTTP/1.1 413", 0) == 0) << huge.substr(0, 200);
  const std::vector<int> held = raw_http::hold(port, 200);
  EXPECT_EQ(held.size(), 200U);
  httplib::Headers wrong{{"Authorization", "Bearer wrong-token-wrong-token"}};
  for (int i = 0; i < 20; ++i) EXPECT_EQ(c.Post("/api/blackout", wrong, R"({"on": true})", "application/json")->status, 401);
  EXPECT_EQ(c.Get("/../../../etc/passwd")->status, 404);
  EXPECT_EQ(c.Post("/api/content", wrong, R"({"target": "duck", "file": "../../etc/passwd"})", "application/json")->status, 401);
  for (const int fd : held) ::close(fd);
  const json s = wait_state(
      c, [](const json& j) { return j.at("frame_rate_hz").get<double>() > 30.0; }, 10.0);
  EXPECT_GT(s.at("frame_rate_hz").get<double>(), 30.0) << s.dump();  // the projector's loop went on (60 Hz paced)
  EXPECT_FALSE(s.at("blackout").get<bool>());
  const auto [code, after_s] = run.signal_and_wait(SIGINT, std::chrono::seconds(60));
  EXPECT_EQ(code, 130) << run.output();
  const std::string out = run.output();
  const auto line = out.rfind("requests refused");
  ASSERT_NE(line, std::string::npos) << out;
  const auto start = out.rfind("; ", line) + 2;
  EXPECT_GE(std::stoi(out.substr(start)), 22) << out.substr(start, 80);  // at least the wrong tokens and the paths
  EXPECT_EQ(out.find("0 frames blacked out"), out.rfind("console: ") + 9) << out;
  std::set<std::string> after;
  for (const auto& e : fs::directory_iterator(dir_)) after.insert(e.path().filename().string());
  before.insert("hostile_run.log");
  EXPECT_EQ(after, before);  // nothing written but the run's own log
}

}  // namespace
