// The operator's console (issue 70) at the library: its HTTP interface over a ShowControl, asked by a real
// HTTP client (cpp-httplib's) on loopback; who may act (the token, the content type) and what a malformed
// request gets; the show's controls and the state the render thread reports.

#include "projbot/console/console.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <lo/lo.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "projbot/config/clock.hpp"
#include "projbot/console/osc.hpp"
#include "raw_http.hpp"

namespace {

using nlohmann::json;
namespace live = projbot::live;
namespace console = projbot::console;

std::vector<live::SiteTarget> two_targets() {
  return {{"duck", true, std::array<double, 2>{3.0, 3.2}, ""}, {"poster", false, std::nullopt, ""}};
}

const httplib::Headers kNoHeaders{};

httplib::Result post(httplib::Client& c, const std::string& path, const std::string& body, const std::string& token = "") {
  httplib::Headers h;
  if (!token.empty()) h.emplace("Authorization", "Bearer " + token);
  return c.Post(path.c_str(), h, body, "application/json");
}

class ConsoleTest : public ::testing::Test {
 protected:
  live::ShowControl show_{two_targets()};
};

TEST_F(ConsoleTest, ServesThePageAndTheStateAndActsOnLoopbackWithoutAToken) {
  console::Console server(show_, console::parse_listen("127.0.0.1:0", "--console"));
  ASSERT_GT(server.port(), 0);
  httplib::Client c("127.0.0.1", server.port());
  const auto page = c.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<title>Projbot console</title>"), std::string::npos);
  EXPECT_NE(page->body.find("new EventSource(\"/api/events\")"), std::string::npos);

  const auto state = c.Get("/api/state");
  ASSERT_TRUE(state);
  EXPECT_EQ(json::parse(state->body).at("phase"), "starting");

  const auto on = post(c, "/api/blackout", R"({"on": true})");
  ASSERT_TRUE(on);
  EXPECT_EQ(on->status, 200) << on->body;
  EXPECT_TRUE(show_.blackout());
  EXPECT_TRUE(show_.take_blackout_asked().has_value());
  EXPECT_EQ(post(c, "/api/pause", R"({"on": true})")->status, 200);
  EXPECT_TRUE(show_.paused());
  EXPECT_EQ(post(c, "/api/goto", R"({"target": "duck"})")->status, 200);
  EXPECT_EQ(show_.take_go_to(), 0);
  EXPECT_EQ(post(c, "/api/goto", R"({"target": "poster"})")->status, 404);  // no stop: the robot cannot go there
  EXPECT_EQ(post(c, "/api/goto", R"({"target": "../etc"})")->status, 404);
  EXPECT_FALSE(show_.pending_go_to());
  EXPECT_EQ(server.refused(), 2U);
}

TEST_F(ConsoleTest, MalformedRequestsGetA4xxAndChangeNothing) {
  console::ConsoleConfig config = console::parse_listen("127.0.0.1:0", "--console");
  config.max_body_bytes = 1024;
  console::Console server(show_, config);
  httplib::Client c("127.0.0.1", server.port());
  EXPECT_EQ(post(c, "/api/blackout", "{not json")->status, 400);
  EXPECT_EQ(post(c, "/api/blackout", R"({"on": "yes"})")->status, 400);
  EXPECT_EQ(post(c, "/api/blackout", "[true]")->status, 400);
  EXPECT_EQ(c.Post("/api/blackout", R"({"on": true})", "text/plain")->status, 415);  // what a cross-site form sends
  EXPECT_EQ(post(c, "/api/blackout", std::string(4096, ' '))->status, 413);
  EXPECT_EQ(c.Get("/../../etc/passwd")->status, 404);
  EXPECT_EQ(c.Get("/api/nothing")->status, 404);
  EXPECT_FALSE(show_.blackout());
  EXPECT_FALSE(show_.paused());
  EXPECT_EQ(server.refused(), 7U);
  EXPECT_EQ(c.Get("/api/state")->status, 200);  // and it still answers
}

// Hostile clients (issue 70, item 5): a thousand malformed requests, a body claiming 100 MB, 200
// connections held open at once, a path out of the page, a wrong token again and again. Each is refused,
// nothing changes, and the console still answers a proper request at the end.
TEST_F(ConsoleTest, HostileClientsAreRefusedAndTheConsoleGoesOn) {
  console::ConsoleConfig config = console::parse_listen("127.0.0.1:0", "--console");
  config.token = "a-token-of-sixteen-or-more";
  console::Console server(show_, config);
  const int port = server.port();
  const std::vector<std::string> junk = raw_http::junk();
  for (int i = 0; i < 1000; ++i) {
    const std::string answer = raw_http::send(port, junk[static_cast<std::size_t>(i) % junk.size()]);
    if (!answer.empty()) {  // some are closed without a word: also a refusal
      EXPECT_EQ(answer.rfind("HTTP/1.1 4", 0), 0U) << answer.substr(0, 80);
    }
  }
  const std::string huge = raw_http::send(port, raw_http::huge_body());
  // Refused unread: a 413, or (httplib skipping the claimed body, the client gone) the connection closed.
  EXPECT_TRUE(huge.empty() || huge.rfind("HTTP/1.1 413", 0) == 0) << huge.substr(0, 200);
  const std::vector<int> held = raw_http::hold(port, 200);
  EXPECT_EQ(held.size(), 200U);
  httplib::Client c("127.0.0.1", port);
  c.set_read_timeout(30, 0);  // behind the silent ones, each given up on after the read timeout
  for (int i = 0; i < 20; ++i) EXPECT_EQ(post(c, "/api/blackout", R"({"on": true})", "wrong-token-wrong-token")->status, 401);
  EXPECT_EQ(c.Get("/../../../etc/passwd")->status, 404);
  for (const int fd : held) ::close(fd);
  EXPECT_FALSE(show_.blackout());
  const auto ok = post(c, "/api/blackout", R"({"on": true})", config.token);
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  EXPECT_TRUE(show_.blackout());
}

TEST_F(ConsoleTest, OffLoopbackEveryActionNeedsTheToken) {
  EXPECT_THROW({ console::Console open(show_, console::parse_listen("0.0.0.0:0", "--console")); }, console::ConsoleError);
  console::ConsoleConfig config = console::parse_listen("0.0.0.0:0", "--console");
  config.token = "a-token-of-sixteen-or-more";
  console::Console server(show_, config);
  httplib::Client c("127.0.0.1", server.port());
  EXPECT_EQ(post(c, "/api/blackout", R"({"on": true})")->status, 401);
  EXPECT_EQ(post(c, "/api/blackout", R"({"on": true})", "a-token-of-sixteen-or-morX")->status, 401);
  EXPECT_EQ(post(c, "/api/pause", R"({"on": true})", "short")->status, 401);
  EXPECT_FALSE(show_.blackout());
  EXPECT_FALSE(show_.paused());
  EXPECT_EQ(c.Get("/api/state")->status, 200);  // the page is read-only without it
  EXPECT_EQ(post(c, "/api/blackout", R"({"on": true})", config.token)->status, 200);
  EXPECT_TRUE(show_.blackout());
}

TEST_F(ConsoleTest, ActionsBeyondTheRateAreRefused) {
  console::Console server(show_, console::parse_listen("127.0.0.1:0", "--console"));
  httplib::Client c("127.0.0.1", server.port());
  int accepted = 0, limited = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 80; ++i) {
    const int status = post(c, "/api/pause", i % 2 ? R"({"on": true})" : R"({"on": false})")->status;
    accepted += status == 200;
    limited += status == 429;
  }
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // 50 in any second: the first 50 are taken, and no more than 50 for each second begun.
  EXPECT_EQ(accepted + limited, 80);
  EXPECT_GE(accepted, 50);
  EXPECT_LE(accepted, 50 * (1 + static_cast<int>(took_s)));
  if (took_s < 1.0) {
    EXPECT_EQ(limited, 30);
  }
}

TEST_F(ConsoleTest, EventsPushEachNewState) {
  console::Console server(show_, console::parse_listen("127.0.0.1:0", "--console"));
  // Each state is published once the page has seen the one before (up to 10 s): a page that connects late
  // on a loaded machine still sees all three, as a page open all along would.
  std::atomic<int> seen{0};
  std::thread publisher([this, &seen] {
    for (int i = 1; i <= 3; ++i) {
      for (int wait = 0; wait < 1000 && seen.load() < i - 1; ++wait) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      live::ShowState s;
      s.phase = "lit";
      s.visit = i;
      show_.publish(s);
    }
  });
  httplib::Client c("127.0.0.1", server.port());
  std::string received;
  c.Get("/api/events", [&](const char* data, std::size_t n) {
    received.append(data, n);
    for (int i = 3; i > seen.load(); --i)
      if (received.find("\"visit\":" + std::to_string(i)) != std::string::npos) {
        seen = i;
        break;
      }
    return seen.load() < 3;  // stop reading once the third is in
  });
  publisher.join();
  EXPECT_NE(received.find("data: {"), std::string::npos) << received;
  EXPECT_NE(received.find("\"visit\":2"), std::string::npos) << received;
  EXPECT_NE(received.find("\"visit\":3"), std::string::npos) << received;
}

TEST(ConsoleAccess, ListenAddressesAndTokenFilesAreChecked) {
  EXPECT_EQ(console::parse_listen("8080", "--console").host, "127.0.0.1");
  EXPECT_EQ(console::parse_listen("8080", "--console").port, 8080);
  EXPECT_EQ(console::parse_listen("0.0.0.0:1", "--console").host, "0.0.0.0");
  EXPECT_EQ(console::parse_listen("[::1]:9", "--console").host, "::1");
  for (const char* bad : {"", ":80", "localhost:", "x:70000", "x:-1", "x:80a", "80 "})
    EXPECT_THROW(console::parse_listen(bad, "--console"), console::ConsoleError) << bad;
  EXPECT_TRUE(console::is_loopback("127.0.0.1"));
  EXPECT_TRUE(console::is_loopback("::1"));
  EXPECT_FALSE(console::is_loopback("0.0.0.0"));

  const std::filesystem::path file = std::filesystem::path(::testing::TempDir()) / "projbot_console_token";
  std::ofstream(file) << "  a-token-of-sixteen-or-more \n";
  ::chmod(file.c_str(), 0644);
  try {
    console::read_token(file);
    ADD_FAILURE() << "a token file others can read was taken";
  } catch (const console::ConsoleError& e) {
    EXPECT_NE(std::string(e.what()).find("chmod 600"), std::string::npos) << e.what();
  }
  ::chmod(file.c_str(), 0600);
  EXPECT_EQ(console::read_token(file), "a-token-of-sixteen-or-more");
  std::ofstream(file) << "short\n";
  EXPECT_THROW(console::read_token(file), console::ConsoleError);
  std::filesystem::remove(file);
  EXPECT_THROW(console::read_token(file), console::ConsoleError);
}

// OSC show control (liblo on both sides): the same actions as the page's, through the same ShowControl; a
// message of another path or type, or a target the robot cannot go to, is counted and changes nothing.
TEST_F(ConsoleTest, OscTakesTheSameActions) {
  console::OscControl osc(show_, {});
  ASSERT_GT(osc.port(), 0);
  const lo_address desk = lo_address_new("127.0.0.1", std::to_string(osc.port()).c_str());
  lo_send(desk, "/projbot/blackout", "i", 1);
  lo_send(desk, "/projbot/pause", "i", 1);
  lo_send(desk, "/projbot/goto", "s", "duck");
  lo_send(desk, "/projbot/goto", "s", "poster");  // no stop
  lo_send(desk, "/projbot/blackout", "s", "on");  // wrong type
  lo_send(desk, "/projbot/format", "i", 1);       // no such action
  lo_address_free(desk);
  for (int i = 0; i < 200 && osc.taken() + osc.refused() < 6; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(osc.taken(), 3U);
  EXPECT_EQ(osc.refused(), 3U);
  EXPECT_TRUE(show_.blackout());
  EXPECT_TRUE(show_.paused());
  EXPECT_EQ(show_.take_go_to(), 0);
  EXPECT_TRUE(console::osc_sender_allowed("127.0.0.1", {}));
  EXPECT_FALSE(console::osc_sender_allowed("192.168.1.20", {}));
  EXPECT_TRUE(console::osc_sender_allowed("192.168.1.20", {"192.168.1.20"}));
}

// A desk told of each change (--osc-send): /projbot/state when the phase, visit, target, blackout or pause
// changes, not on every state published.
TEST_F(ConsoleTest, OscTellsTheDeskOfEachChange) {
  struct Heard {
    std::mutex mutex;
    std::vector<std::string> states;
  } heard;
  const lo_server_thread desk = lo_server_thread_new(nullptr, nullptr);
  ASSERT_NE(desk, nullptr);
  lo_server_thread_add_method(
      desk, "/projbot/state", "sisii",
      [](const char*, const char*, lo_arg** argv, int, lo_message, void* data) {
        auto& h = *static_cast<Heard*>(data);
        const std::lock_guard lock(h.mutex);
        h.states.push_back(std::string(&argv[0]->s) + " " + std::to_string(argv[1]->i) + " " + &argv[2]->s + " " +
                           std::to_string(argv[3]->i) + std::to_string(argv[4]->i));
        return 0;
      },
      &heard);
  lo_server_thread_start(desk);
  {
    console::OscConfig config;
    config.send_host = "127.0.0.1";
    config.send_port = lo_server_thread_get_port(desk);
    console::OscControl osc(show_, config);
    live::ShowState s;
    s.phase = "driving";
    s.visit = 1;
    for (int i = 0; i < 3; ++i) show_.publish(s);  // the same three times: told once
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    s.phase = "lit";
    s.visiting = "duck";
    s.blackout = true;
    show_.publish(s);
    for (int i = 0; i < 100 && osc.sent() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    EXPECT_EQ(osc.sent(), 2U);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  lo_server_thread_free(desk);
  ASSERT_EQ(heard.states.size(), 2U);
  EXPECT_EQ(heard.states[0], "driving 1  00");
  EXPECT_EQ(heard.states[1], "lit 1 duck 10");
}

// Switching a target's video (issue 70): only a file the content folder lists, by name (no path, no link
// out of it, no hidden file), only on a target that plays a video; the same over HTTP and OSC.
TEST(ShowControlContent, OnlyAFileTheContentFolderListsByName) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("projbot_content_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "videos" / "sub");
  for (const char* f : {"a.mp4", "b.mp4", ".hidden.mp4", "sub/c.mp4"}) std::ofstream(dir / "videos" / f) << "x";
  std::ofstream(dir / "secret.mp4") << "x";
  std::filesystem::create_symlink(dir / "secret.mp4", dir / "videos" / "out.mp4");
  std::filesystem::create_symlink(dir / "videos" / "a.mp4", dir / "videos" / "in.mp4");
  live::ShowControl show({{"duck", true, std::nullopt, "clip.mp4"}, {"poster", false, std::nullopt, ""}}, dir / "videos");
  EXPECT_EQ(show.content_files(), (std::vector<std::string>{"a.mp4", "b.mp4", "in.mp4"}));
  using Answer = live::ShowControl::ContentAnswer;
  EXPECT_EQ(show.content_of(0), "clip.mp4");
  for (const char* bad : {"../secret.mp4", "out.mp4", ".hidden.mp4", "sub/c.mp4", "sub", "", "/etc/passwd"})
    EXPECT_EQ(show.switch_content("duck", bad), Answer::no_file) << bad;
  EXPECT_EQ(show.switch_content("poster", "a.mp4"), Answer::no_video);
  EXPECT_EQ(show.switch_content("nobody", "a.mp4"), Answer::no_target);
  EXPECT_TRUE(show.take_content_switches().empty());

  console::Console server(show, console::parse_listen("127.0.0.1:0", "--console"));
  httplib::Client c("127.0.0.1", server.port());
  EXPECT_EQ(json::parse(c.Get("/api/content")->body).at("files"), json::array({"a.mp4", "b.mp4", "in.mp4"}));
  EXPECT_EQ(post(c, "/api/content", R"({"target": "duck", "file": "b.mp4"})")->status, 200);
  EXPECT_EQ(post(c, "/api/content", R"({"target": "duck", "file": "../secret.mp4"})")->status, 404);
  EXPECT_EQ(post(c, "/api/content", R"({"target": "poster", "file": "a.mp4"})")->status, 409);
  EXPECT_EQ(post(c, "/api/content", R"({"target": "duck"})")->status, 400);
  console::OscControl osc(show, {});
  const lo_address desk = lo_address_new("127.0.0.1", std::to_string(osc.port()).c_str());
  lo_send(desk, "/projbot/content", "ss", "duck", "in.mp4");
  lo_send(desk, "/projbot/content", "ss", "duck", "out.mp4");
  lo_address_free(desk);
  for (int i = 0; i < 200 && osc.taken() + osc.refused() < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(osc.taken(), 1U);
  EXPECT_EQ(osc.refused(), 1U);
  const auto switches = show.take_content_switches();
  ASSERT_EQ(switches.size(), 2U);
  EXPECT_EQ(switches[0], std::make_pair(0, dir / "videos" / "b.mp4"));
  EXPECT_EQ(switches[1], std::make_pair(0, dir / "videos" / "in.mp4"));
  EXPECT_EQ(show.content_of(0), "in.mp4");

  live::ShowControl no_folder({{"duck", true, std::nullopt, "clip.mp4"}}, {});
  EXPECT_EQ(no_folder.switch_content("duck", "a.mp4"), Answer::no_folder);
  EXPECT_TRUE(no_folder.content_files().empty());
  std::filesystem::remove_all(dir);
}

// The render thread's pace between offscreen frames is cut short by a blackout asked for (its first
// black frame starts at once), and only by that.
TEST(ShowControl, ABlackoutAskedForWakesTheRenderThreadsPace) {
  live::ShowControl show(two_targets());
  const double t0 = projbot::config::steady_now_s();
  EXPECT_FALSE(show.sleep_until(t0 + 0.05));  // nothing asked: the whole pace
  EXPECT_GE(projbot::config::steady_now_s(), t0 + 0.05);
  show.set_paused(true);
  EXPECT_FALSE(show.sleep_until(projbot::config::steady_now_s() + 0.02));  // a pause waits for the next frame
  std::thread desk([&show] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    show.set_blackout(true, projbot::config::steady_now_s());
  });
  const double asleep = projbot::config::steady_now_s();
  EXPECT_TRUE(show.sleep_until(asleep + 30.0));
  EXPECT_LT(projbot::config::steady_now_s(), asleep + 30.0);
  desk.join();
  EXPECT_TRUE(show.sleep_until(projbot::config::steady_now_s() + 30.0));  // until its first black frame takes it
  ASSERT_TRUE(show.take_blackout_asked().has_value());
  EXPECT_FALSE(show.sleep_until(projbot::config::steady_now_s() + 0.01));
}

// The tour's table (issue 70): a row per visit, its frames at the stop, those that drew its visited
// target (a blackout's do not), the target's error at display where measured, each frame's counted once.
TEST(ShowReporter, GrowsTheToursTableVisitByVisit) {
  live::ShowControl show(two_targets());
  live::ShowReporter reporter(show, 0.0);
  live::ProjectionFigures figures;
  const auto measured = [&](int target, double error_mm, double clock_s) {
    live::ProjectionRow row;
    row.target = target;
    row.error_mm = error_mm;
    row.clock_s = clock_s;
    figures.rows.push_back(row);
  };
  live::DecidedFrame lit, black;
  lit.drawn.push_back(live::DrawnPose{});
  lit.drawn.back().target = 0;
  black.uniform = true;
  const live::StopView at_duck{{0}, 1, false, {3.0, 1.8, 1.57}, std::nullopt};
  reporter.frame(live::DecidedFrame{}, at_duck, figures, 10.0, 0.0);  // acquiring: nothing drawn
  reporter.frame(lit, at_duck, figures, 10.1, 0.1);
  measured(0, 2.0, 0.1);
  reporter.frame(lit, at_duck, figures, 10.2, 0.2);
  measured(0, 4.0, 0.2);
  reporter.frame(black, at_duck, figures, 10.3, 0.3);
  reporter.frame(black, at_duck, figures, 10.4, 0.4);  // the same newest row: not counted again
  reporter.frame(live::DecidedFrame{}, live::StopView{{}, 2, false, {}, std::nullopt}, figures, 10.5, 0.5);  // driving
  const auto s = show.state();
  ASSERT_EQ(s->tour.size(), 1U);
  EXPECT_EQ(s->tour[0].visit, 1);
  EXPECT_EQ(s->tour[0].target, "duck");
  EXPECT_EQ(s->tour[0].frames, 5U);
  EXPECT_EQ(s->tour[0].lit_frames, 2U);
  EXPECT_EQ(s->tour[0].measured, 2U);
  EXPECT_DOUBLE_EQ(s->tour[0].mean_mm, 3.0);
  EXPECT_DOUBLE_EQ(s->tour[0].worst_mm, 4.0);
  const json j = json::parse(console::state_json(*s));
  EXPECT_EQ(j.at("tour").at(0).at("lit_frames"), 2);
  EXPECT_EQ(j.at("tour").at(0).at("mean_mm"), 3.0);
}

// The render thread's report: the phase and each target's state from the frames it drew, a blackout's
// frames leaving them as the projector would show them without it, five states a second at most.
TEST(ShowReporter, ReportsWhatTheFramesDrew) {
  live::ShowControl show(two_targets());
  live::ShowReporter reporter(show, 0.2);
  live::ProjectionFigures figures;
  live::DecidedFrame lit;
  lit.drawn.push_back(live::DrawnPose{});
  lit.drawn.back().target = 0;
  const live::StopView at_duck{{0}, 1, false, {3.0, 1.8, 1.57}, std::nullopt};
  reporter.frame(lit, at_duck, figures, 10.0, 0.0);
  auto s = show.state();
  EXPECT_EQ(s->phase, "lit");
  EXPECT_EQ(s->visiting, "duck");
  EXPECT_EQ(s->targets.at(0).state, "lit");
  EXPECT_TRUE(s->targets.at(0).visited);
  EXPECT_EQ(s->targets.at(1).state, "idle");
  ASSERT_EQ(s->stops.size(), 1U);
  EXPECT_DOUBLE_EQ(s->stops[0][0], 3.0);

  live::DecidedFrame black;
  black.uniform = true;
  show.set_blackout(true, 10.0);
  reporter.frame(black, at_duck, figures, 10.1, 0.1);  // within 0.2 s: not published
  EXPECT_EQ(show.state()->sequence, s->sequence);
  reporter.frame(black, at_duck, figures, 10.3, 0.3);
  s = show.state();
  EXPECT_TRUE(s->blackout);
  EXPECT_EQ(s->targets.at(0).state, "lit");  // what the projector shows once released
  EXPECT_EQ(s->phase, "lit");
  EXPECT_NEAR(s->frame_rate_hz, 2.0 / 0.3, 1e-9);

  EXPECT_EQ(s->robot, (std::array<double, 3>{3.0, 1.8, 1.57}));  // at the stop: its pose
  reporter.frame(live::DecidedFrame{}, live::StopView{{}, 2, false, {}, std::array<double, 3>{4.0, 2.0, 0.5}}, figures, 10.6,
                 0.6);
  EXPECT_EQ(show.state()->robot, (std::array<double, 3>{4.0, 2.0, 0.5}));  // driving: where it believes it is now
  EXPECT_EQ(show.state()->stops.size(), 1U);
  EXPECT_EQ(show.state()->phase, "driving");
  EXPECT_EQ(show.state()->targets.at(0).state, "idle");
}

// The top half white, the bottom black.
projbot::assets::Image half_white(int width, int height) {
  projbot::assets::Image image{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 4, 0)};
  for (int y = 0; y < height / 2; ++y)
    for (int x = 0; x < width; ++x) std::fill_n(image.pixel(x, y), 4, std::uint8_t{255});
  return image;
}

live::ShowPictures::Png wait_png(live::ShowPictures& pictures, live::ShowPictures::Kind kind) {
  for (int i = 0; i < 500; ++i) {
    if (live::ShowPictures::Png png = pictures.png(kind)) return png;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return nullptr;
}

// A PNG's bytes decoded (through a file: the assets module reads files).
template <typename Bytes>
projbot::assets::Image decoded(const Bytes& png) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("projbot_picture_" + std::to_string(::getpid()) + ".png");
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  projbot::assets::Image image = projbot::assets::read_image(file);
  std::filesystem::remove(file);
  return image;
}
// The pictures (issue 70): taken only while someone asked for them, shrunk for the page, encoded off the
// engine's threads; a kind that can never be given says why.
TEST(ShowPictures, TakesPicturesOnlyWhileWantedAndEncodesThemSmall) {
  live::ShowPictures pictures({.max_width = 320, .period_s = 0.0, .interest_s = 5.0});
  using Kind = live::ShowPictures::Kind;
  EXPECT_FALSE(pictures.due(Kind::frame));  // no one has asked: nothing is copied
  EXPECT_EQ(pictures.png(Kind::frame), nullptr);
  EXPECT_TRUE(pictures.due(Kind::frame));
  EXPECT_FALSE(pictures.due(Kind::camera));

  pictures.offer(Kind::frame, half_white(640, 480));
  const live::ShowPictures::Png png = wait_png(pictures, Kind::frame);
  ASSERT_NE(png, nullptr);
  const projbot::assets::Image small = decoded(*png);
  EXPECT_EQ(small.width, 320);
  EXPECT_EQ(small.height, 240);
  EXPECT_EQ(small.pixel(10, 10)[0], 255);   // the top half white
  EXPECT_EQ(small.pixel(10, 230)[0], 0);    // the bottom black
  EXPECT_EQ(small.pixel(10, 119)[1], 255);  // the edge falls between rows: no row mixes the two
  EXPECT_EQ(small.pixel(10, 120)[1], 0);

  pictures.png(Kind::camera);
  pictures.set_unavailable(Kind::camera, "no camera here");
  EXPECT_FALSE(pictures.due(Kind::camera));
  EXPECT_EQ(pictures.unavailable(Kind::camera), "no camera here");
  EXPECT_EQ(pictures.unavailable(Kind::frame), "");

  live::ShowPictures slow({.max_width = 320, .period_s = 60.0, .interest_s = 5.0});
  slow.png(Kind::frame);
  slow.offer(Kind::frame, half_white(64, 48));
  EXPECT_FALSE(slow.due(Kind::frame));  // one a period
  const live::ShowPictures::Png tiny = wait_png(slow, Kind::frame);
  ASSERT_NE(tiny, nullptr);
  EXPECT_EQ(decoded(*tiny).width, 64);  // already small: as it is
}

TEST_F(ConsoleTest, ServesThePicturesTheEngineOffers) {
  console::Console server(show_, console::parse_listen("127.0.0.1:0", "--console"));
  httplib::Client c("127.0.0.1", server.port());
  const auto none = c.Get("/api/frame.png");
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 404);
  EXPECT_NE(json::parse(none->body).at("error").get<std::string>().find("no picture yet"), std::string::npos);
  using Kind = live::ShowPictures::Kind;
  ASSERT_TRUE(show_.pictures().due(Kind::frame));  // asked for: the engine would offer one now
  show_.pictures().offer(Kind::frame, half_white(640, 480));
  ASSERT_NE(wait_png(show_.pictures(), Kind::frame), nullptr);
  const auto got = c.Get("/api/frame.png");
  ASSERT_TRUE(got);
  EXPECT_EQ(got->status, 200);
  EXPECT_EQ(got->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(decoded(got->body).width, 320);
  show_.pictures().set_unavailable(Kind::camera, "the camera gives no colour");
  const auto camera = c.Get("/api/camera.png");
  EXPECT_EQ(camera->status, 404);
  EXPECT_EQ(json::parse(camera->body).at("error"), "the camera gives no colour");
}

}  // namespace
