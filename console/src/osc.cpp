#include "projbot/console/osc.hpp"

#include <lo/lo.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <tuple>

#include "projbot/config/clock.hpp"
#include "projbot/console/console.hpp"

namespace projbot::console {

bool osc_sender_allowed(const std::string& host, const std::vector<std::string>& allowed) {
  return is_loopback(host) || host == "::ffff:127.0.0.1" || std::find(allowed.begin(), allowed.end(), host) != allowed.end();
}

struct OscControl::Impl {
  live::ShowControl& show;
  OscConfig config;
  lo_server_thread server = nullptr;
  std::atomic<std::size_t> taken{0}, refused{0}, sent{0};
  std::jthread teller;  // sends the state to the desk on each change

  // Whether the message's sender may act; counted as refused when not.
  bool allowed(lo_message message) {
    const lo_address from = lo_message_get_source(message);
    const char* host = from ? lo_address_get_hostname(from) : nullptr;
    if (host && osc_sender_allowed(host, config.allowed)) return true;
    refused.fetch_add(1);
    return false;
  }
  void act(bool ok) { (ok ? taken : refused).fetch_add(1); }
  void tell(const std::stop_token& stop);
};

// What the desk hears: the state's parts an operator acts on, sent when any of them changes.
void OscControl::Impl::tell(const std::stop_token& stop) {
  const lo_address desk = lo_address_new(config.send_host.c_str(), std::to_string(config.send_port).c_str());
  std::uint64_t sequence = 0;
  std::tuple<std::string, int, std::string, bool, bool> last{"", -1, "", false, false};
  while (!stop.stop_requested()) {
    const std::shared_ptr<const live::ShowState> s = show.wait_newer(sequence, 200);
    if (s->sequence == sequence) continue;
    sequence = s->sequence;
    const auto now = std::make_tuple(s->phase, s->visit, s->visiting, s->blackout, s->paused);
    if (now == last) continue;
    last = now;
    if (lo_send(desk, "/projbot/state", "sisii", s->phase.c_str(), s->visit, s->visiting.c_str(), s->blackout ? 1 : 0,
                s->paused ? 1 : 0) >= 0)
      sent.fetch_add(1);
  }
  lo_address_free(desk);
}

namespace {

using Impl = OscControl::Impl;

int on_blackout(const char*, const char*, lo_arg** argv, int, lo_message message, void* data) {
  auto& i = *static_cast<Impl*>(data);
  if (i.allowed(message)) {
    i.show.set_blackout(argv[0]->i != 0, config::steady_now_s());
    i.act(true);
  }
  return 0;
}

int on_pause(const char*, const char*, lo_arg** argv, int, lo_message message, void* data) {
  auto& i = *static_cast<Impl*>(data);
  if (i.allowed(message)) {
    i.show.set_paused(argv[0]->i != 0);
    i.act(true);
  }
  return 0;
}

int on_goto(const char*, const char*, lo_arg** argv, int, lo_message message, void* data) {
  auto& i = *static_cast<Impl*>(data);
  if (i.allowed(message)) i.act(i.show.go_to(&argv[0]->s));
  return 0;
}

int on_content(const char*, const char*, lo_arg** argv, int, lo_message message, void* data) {
  auto& i = *static_cast<Impl*>(data);
  if (i.allowed(message)) i.act(i.show.switch_content(&argv[0]->s, &argv[1]->s) == live::ShowControl::ContentAnswer::switched);
  return 0;
}

// Anything else sent to the port: counted, and dropped.
int on_other(const char*, const char*, lo_arg**, int, lo_message, void* data) {
  static_cast<Impl*>(data)->refused.fetch_add(1);
  return 0;
}

void on_error(int, const char*, const char*) {}  // a bad packet: liblo drops it; the show goes on

}  // namespace

OscControl::OscControl(live::ShowControl& show, OscConfig config) : impl_(std::make_unique<Impl>(show, std::move(config))) {
  const std::string port = impl_->config.port == 0 ? std::string() : std::to_string(impl_->config.port);
  impl_->server = lo_server_thread_new(port.empty() ? nullptr : port.c_str(), on_error);
  if (!impl_->server) throw ConsoleError("--osc " + std::to_string(impl_->config.port) + ": cannot listen on that UDP port");
  lo_server_thread_add_method(impl_->server, "/projbot/blackout", "i", on_blackout, impl_.get());
  lo_server_thread_add_method(impl_->server, "/projbot/pause", "i", on_pause, impl_.get());
  lo_server_thread_add_method(impl_->server, "/projbot/goto", "s", on_goto, impl_.get());
  lo_server_thread_add_method(impl_->server, "/projbot/content", "ss", on_content, impl_.get());
  lo_server_thread_add_method(impl_->server, nullptr, nullptr, on_other, impl_.get());
  lo_server_thread_start(impl_->server);
  if (!impl_->config.send_host.empty()) impl_->teller = std::jthread([i = impl_.get()](std::stop_token stop) { i->tell(stop); });
}

OscControl::~OscControl() {
  if (impl_->teller.joinable()) {
    impl_->teller.request_stop();
    impl_->teller.join();
  }
  lo_server_thread_free(impl_->server);
}

int OscControl::port() const { return lo_server_thread_get_port(impl_->server); }
std::size_t OscControl::taken() const { return impl_->taken.load(); }
std::size_t OscControl::refused() const { return impl_->refused.load(); }
std::size_t OscControl::sent() const { return impl_->sent.load(); }

}  // namespace projbot::console
