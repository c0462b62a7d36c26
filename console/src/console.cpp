#include "projbot/console/console.hpp"

#include <httplib.h>

#include <atomic>
#include <charconv>
#include <deque>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "projbot/config/clock.hpp"

namespace projbot::console {

// The page (console/page/index.html), embedded by the build: nothing is fetched at run time.
extern const char* const kPage;

namespace {

using nlohmann::json;

// Actions a console takes in any one second: a script or a stuck key cannot flood the show.
constexpr int kActionsPerSecond = 50;

void reply(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void refuse(httplib::Response& res, int status, const std::string& why) { reply(res, status, {{"error", why}}); }

// Compares without stopping at the first difference: a token is not guessed a character at a time.
bool same(const std::string& given, const std::string& token) {
  if (given.size() != token.size() || token.empty()) return false;  // its length is not the secret
  unsigned diff = 0;
  for (std::size_t i = 0; i < token.size(); ++i) diff |= static_cast<unsigned char>(given[i] ^ token[i]);
  return diff == 0;
}

}  // namespace

struct Console::Impl {
  Impl(live::ShowControl& s, ConsoleConfig c) : show(s), config(std::move(c)) {}
  bool authorised(const httplib::Request& req, httplib::Response& res);
  bool within_rate(httplib::Response& res);
  bool json_body(const httplib::Request& req, httplib::Response& res, json& out);
  void routes();
  void actions();
  void events(httplib::Response& res);
  void picture(live::ShowPictures::Kind kind, httplib::Response& res);
  /// A picture asked for before the engine took one: not a request refused.
  static bool picture_not_yet(const httplib::Request& req, const httplib::Response& res) {
    return res.status == 404 && (req.path == "/api/frame.png" || req.path == "/api/camera.png");
  }

  live::ShowControl& show;
  ConsoleConfig config;
  httplib::Server server;
  std::thread thread;
  int port = 0;
  std::atomic<bool> stopping{false};
  std::atomic<int> viewers{0};
  std::atomic<std::size_t> refused{0};
  std::mutex rate_mutex;
  std::deque<double> actions_s;  // the actions taken in the last second
};

bool Console::Impl::authorised(const httplib::Request& req, httplib::Response& res) {
  if (config.token.empty()) return true;  // loopback only (checked at start)
  const std::string header = req.get_header_value("Authorization");
  if (header.rfind("Bearer ", 0) == 0 && same(header.substr(7), config.token)) return true;
  res.set_header("WWW-Authenticate", "Bearer");
  refuse(res, 401, "this action needs the console's token (Authorization: Bearer TOKEN)");
  return false;
}

bool Console::Impl::within_rate(httplib::Response& res) {
  const double now = config::steady_now_s();
  const std::lock_guard lock(rate_mutex);
  while (!actions_s.empty() && actions_s.front() < now - 1.0) actions_s.pop_front();
  if (static_cast<int>(actions_s.size()) >= kActionsPerSecond) {
    refuse(res, 429, "more than " + std::to_string(kActionsPerSecond) + " actions in a second");
    return false;
  }
  actions_s.push_back(now);
  return true;
}

// An action's body: JSON, sent as application/json (a cross-site form cannot send that, and a cross-site
// script must ask first, which nothing here answers).
bool Console::Impl::json_body(const httplib::Request& req, httplib::Response& res, json& out) {
  if (req.get_header_value("Content-Type").rfind("application/json", 0) != 0) {
    refuse(res, 415, "an action's body is JSON, sent as Content-Type: application/json");
    return false;
  }
  out = json::parse(req.body, nullptr, false);
  if (out.is_discarded() || !out.is_object()) {
    refuse(res, 400, "the body is not a JSON object");
    return false;
  }
  return true;
}

void Console::Impl::events(httplib::Response& res) {
  if (viewers.fetch_add(1) >= config.max_viewers) {
    viewers.fetch_sub(1);
    refuse(res, 503, "already " + std::to_string(config.max_viewers) + " pages open");
    return;
  }
  res.set_header("Cache-Control", "no-store");
  res.set_chunked_content_provider(
      "text/event-stream",
      [this, sequence = std::uint64_t{0}](std::size_t, httplib::DataSink& sink) mutable {
        const std::shared_ptr<const live::ShowState> state = show.wait_newer(sequence, 1000);
        if (stopping) return false;
        std::string event = ": still here\n\n";  // a comment: keeps the connection, tells a dead one
        if (state->sequence > sequence) {
          sequence = state->sequence;
          event = "data: " + state_json(*state) + "\n\n";
        }
        return sink.write(event.data(), event.size());
      },
      [this](bool) { viewers.fetch_sub(1); });
}

// The newest picture of `kind` (asking for it is what makes the engine take the next): 404 saying why
// while there is none, which a page asking twice a second soon gets past.
void Console::Impl::picture(live::ShowPictures::Kind kind, httplib::Response& res) {
  live::ShowPictures& pictures = show.pictures();
  const live::ShowPictures::Png png = pictures.png(kind);
  res.set_header("Cache-Control", "no-store");
  if (!png) {
    const std::string why = pictures.unavailable(kind);
    return refuse(res, 404, why.empty() ? "no picture yet: the engine takes one within a second of being asked" : why);
  }
  res.set_content(reinterpret_cast<const char*>(png->data()), png->size(), "image/png");
}

void Console::Impl::routes() {
  server.Get("/", [](const httplib::Request&, httplib::Response& res) { res.set_content(kPage, "text/html; charset=utf-8"); });
  server.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    res.set_content(state_json(*show.state()), "application/json");
  });
  server.Get("/api/events", [this](const httplib::Request&, httplib::Response& res) { events(res); });
  server.Get("/api/frame.png",
             [this](const httplib::Request&, httplib::Response& res) { picture(live::ShowPictures::Kind::frame, res); });
  server.Get("/api/camera.png",
             [this](const httplib::Request&, httplib::Response& res) { picture(live::ShowPictures::Kind::camera, res); });
  server.Get("/api/content", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-store");
    reply(res, 200, {{"files", show.content_files()}});
  });
  actions();
}

// What an operator does (each asks for the token, a JSON body and a place within the rate).
void Console::Impl::actions() {
  const auto on_off = [this](const std::string& key, auto act) {
    return [this, key, act](const httplib::Request& req, httplib::Response& res) {
      json body;
      if (!authorised(req, res) || !json_body(req, res, body) || !within_rate(res)) return;
      if (!body.contains("on") || !body["on"].is_boolean()) return refuse(res, 400, "expected {\"on\": true|false}");
      act(body["on"].get<bool>());
      reply(res, 200, {{key, body["on"]}});
    };
  };
  server.Post("/api/blackout", on_off("blackout", [this](bool on) { show.set_blackout(on, config::steady_now_s()); }));
  server.Post("/api/pause", on_off("paused", [this](bool on) { show.set_paused(on); }));
  server.Post("/api/content", [this](const httplib::Request& req, httplib::Response& res) {
    json body;
    if (!authorised(req, res) || !json_body(req, res, body) || !within_rate(res)) return;
    if (!body.contains("target") || !body["target"].is_string() || !body.contains("file") || !body["file"].is_string())
      return refuse(res, 400, "expected {\"target\": NAME, \"file\": NAME}");
    const std::string target = body["target"].get<std::string>(), file = body["file"].get<std::string>();
    using Answer = live::ShowControl::ContentAnswer;
    const Answer a = show.switch_content(target, file);
    if (a != Answer::switched)
      return refuse(res, a == Answer::no_target || a == Answer::no_file ? 404 : 409, show.said(a, target, file));
    reply(res, 200, {{"target", target}, {"content", file}});
  });
  server.Post("/api/goto", [this](const httplib::Request& req, httplib::Response& res) {
    json body;
    if (!authorised(req, res) || !json_body(req, res, body) || !within_rate(res)) return;
    if (!body.contains("target") || !body["target"].is_string()) return refuse(res, 400, "expected {\"target\": NAME}");
    const std::string target = body["target"].get<std::string>();
    if (!show.go_to(target)) return refuse(res, 404, "no target '" + target + "' the robot can go to");
    reply(res, 200, {{"go_to", target}});
  });
}

Console::Console(live::ShowControl& show, ConsoleConfig config) : impl_(std::make_unique<Impl>(show, std::move(config))) {
  Impl& i = *impl_;
  if (i.config.token.empty() && !is_loopback(i.config.host))
    throw ConsoleError("--console " + i.config.host +
                       ": a console on an address other than loopback needs a token (--console-token FILE)");
  const int threads = i.config.max_viewers + 8;  // every open page holds one while it is pushed to
  i.server.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<std::size_t>(threads)); };
  i.server.set_payload_max_length(i.config.max_body_bytes);
  // A connection that says nothing holds a thread only this long: 200 silent ones cost the page seconds.
  i.server.set_keep_alive_timeout(1);
  i.server.set_read_timeout(2, 0);
  i.server.set_write_timeout(5, 0);
  // Every answer of 400 or more passes here before it is written (a logger runs after: a client could
  // read the answer before the count).
  i.server.set_error_handler([&i](const httplib::Request& req, httplib::Response& res) {
    if (!i.picture_not_yet(req, res)) i.refused.fetch_add(1);
    if (res.body.empty()) refuse(res, res.status, "HTTP " + std::to_string(res.status) + " (see GET / for the page, /api/state)");
  });
  i.server.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
    refuse(res, 500, "the console failed on this request; the show goes on");
  });
  i.routes();
  i.port = i.config.port == 0 ? i.server.bind_to_any_port(i.config.host) : i.config.port;
  if (i.port < 0 || (i.config.port != 0 && !i.server.bind_to_port(i.config.host, i.config.port)))
    throw ConsoleError("--console " + i.config.host + ":" + std::to_string(i.config.port) + ": cannot listen there");
  i.thread = std::thread([&i] { i.server.listen_after_bind(); });
}

Console::~Console() {
  impl_->stopping = true;
  impl_->server.stop();
  if (impl_->thread.joinable()) impl_->thread.join();
}

int Console::port() const { return impl_->port; }

std::string Console::url() const {
  const std::string& h = impl_->config.host;
  return "http://" + (h.find(':') != std::string::npos ? "[" + h + "]" : h) + ":" + std::to_string(impl_->port) + "/";
}

std::size_t Console::refused() const { return impl_->refused.load(); }

}  // namespace projbot::console
