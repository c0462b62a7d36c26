// projbot run: the live engine. The render thread (this one) draws every frame from the newest accepted
// pose of each target's tracker worker; the robot thread drives the tour, aims, hands each stop's
// initial guess (Eq. 1) to the worker and, in the twin, plays the depth camera at 30 Hz.

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/console/console.hpp"
#include "projbot/console/osc.hpp"
#include "projbot/engine/frame_profiler.hpp"
#include "projbot/fleet/fleet_member.hpp"
#include "projbot/live/run.hpp"
#include "projbot/twin/twin_rig.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {
namespace {

// The error of the frames drawn, against the twin's truth at each frame's display time: the mean distance
// between where the projector's light lands and where the markers truly are then (mm; the tour's
// definition, twin::marker_errors).
void print_display_errors(std::ostream& out, const live::ProjectionFigures& f) {
  double still = 0.0, moving = 0.0;
  for (const double e : f.still_mm) still += e / static_cast<double>(f.still_mm.size());
  for (const double e : f.moving_mm) moving += e / static_cast<double>(f.moving_mm.size());
  out << "error at display (markers drawn vs true, twin): ";
  if (f.moving_mm.empty())
    out << "no frame while a target moved";
  else
    out << "while moving mean " << moving << " mm, p95 " << engine::percentile(f.moving_mm, 0.95) << " mm, max "
        << engine::percentile(f.moving_mm, 1.0) << " mm over " << f.moving_mm.size() << " frames";
  out << "; still mean " << (f.still_mm.empty() ? std::nan("") : still) << " mm over " << f.still_mm.size() << " frames\n";
}

void print_robot(std::ostream& out, const live::RunResult& r, bool configured_camera) {
  out << "robot: " << r.visits << " visit(s); " << (configured_camera ? "the configured" : "the twin's") << " camera delivered "
      << r.handoff_from_capture_ms.size() << " frames (capture to hand-off to the workers p50 "
      << engine::percentile(r.handoff_from_capture_ms, 0.5) << " ms, p95 " << engine::percentile(r.handoff_from_capture_ms, 0.95)
      << " ms" << (configured_camera ? "" : ": the twin's render and Kinect noise")
      << "; of that, from the camera's next() to the hand-off p50 " << std::setprecision(3)
      << engine::percentile(r.handoff_in_session_ms, 0.5) << " ms, p95 " << engine::percentile(r.handoff_in_session_ms, 0.95)
      << " ms); the tracker workers processed " << r.tracked << "\n";
}

// --replay DIR: the recording, read before anything else starts (and the options it rules out refused).
std::optional<config::Recording> replay_of(const cli::Args& args) {
  const auto dir = args.get("replay");
  if (!dir) return std::nullopt;
  if (args.flag("sim")) throw cli::UsageError("--sim does not apply to --replay: the recording serves every device");
  for (const char* k : {"visits", "dwell", "seed", "depth-model"})
    if (args.get(k)) throw cli::UsageError(std::string("--") + k + " does not apply to --replay: it plays the recording's stops");
  return config::load_recording(*dir);
}

// The run's options beyond the scene and the recording: a bad value is a usage error before anything opens.
live::RunOptions run_options(const cli::Args& args, const TourFamilyArgs& family) {
  live::RunOptions o;
  o.visits = family.visits, o.dwell_s = family.dwell_s;
  o.seconds = args.get_double("seconds", 0.0);
  if (!(o.seconds >= 0.0 && o.seconds <= 1e6)) throw cli::UsageError("--seconds must be 0 (until the tour ends) to 1e6");
  o.headless = args.flag("headless");
  present_mode(args.get_or("present-mode", "fifo"));  // a bad mode is an error with --headless too
  args.get_int("monitor", 0, 0, 64);                  // so is a bad monitor
  o.compensate = on_off(args, "compensation", true);
  o.predict = !args.flag("no-predict");
  o.learn_reflectance = args.flag("learn-reflectance");
  if (const auto out = args.get("reflectance-out")) {
    if (!o.learn_reflectance) throw cli::UsageError("--reflectance-out saves what --learn-reflectance learns: give both");
    cli::check_new_folder(*out, "the learnt surfaces need a new folder");
    o.reflectance_out = *out;
  }
  return o;
}

// The projector's output: offscreen at its size with --headless, else a window; on the config's projector
// (its monitor, fullscreen) when `configured`, unless the command line says otherwise.
std::unique_ptr<engine::RenderTarget> open_output(engine::Renderer& renderer, const cli::Args& args, const config::Scene& scene,
                                                  bool headless, bool configured) {
  if (headless) return renderer.make_offscreen(scene.projector.width_px, scene.projector.height_px);
  engine::WindowOptions wo = window_options(args, scene.projector, "projbot run: " + scene.source.filename().string());
  if (configured && scene.devices.projector) {
    wo.fullscreen = args.flag("fullscreen") || scene.devices.projector->fullscreen;
    if (!args.get("monitor")) wo.monitor = scene.devices.projector->monitor;
  }
  return open_window(renderer, wo, scene.projector);
}

void print_frames(std::ostream& out, const live::RunResult& r) {
  const live::ProjectionFigures& f = r.figures;
  out << engine::format_summary(r.summary) << '\n';
  out << std::fixed << std::setprecision(1) << "pose age at display (depth capture to expected display), " << f.ages_ms.size()
      << " frames with a target: p50 " << engine::percentile(f.ages_ms, 0.5) << " ms, p95 " << engine::percentile(f.ages_ms, 0.95)
      << " ms, p99 " << engine::percentile(f.ages_ms, 0.99) << " ms, max " << engine::percentile(f.ages_ms, 1.0) << " ms; "
      << f.blank << " frames blank (driving, acquiring or lost)";
  if (f.with_neighbours > 0) out << "; " << f.with_neighbours << " frames lit a neighbour too";
  if (f.uniform > r.blackout_frames)
    out << "; " << f.uniform - r.blackout_frames << " frames black or grey while " << r.reflectance_measured
        << " target reflectance(s) were measured";
  if (r.blackout_frames > 0) out << "; " << r.blackout_frames << " frames blacked out by the operator";
  if (r.silent_frames > 0)
    out << "; " << r.silent_frames << " frames blanked because the camera had handed over no frame for "
        << std::lround(1000.0 * r.silent_camera_s) << " ms";
  out << "\n";
  if (!r.content.empty())
    out << "content: " << r.content << "; content time less the shown frame's: p50 "
        << engine::percentile(f.content_offsets_ms, 0.5) << " ms, p99 " << engine::percentile(f.content_offsets_ms, 0.99)
        << " ms; upload on the render thread p50 " << std::setprecision(3) << r.summary.upload_p50_ms << " ms, p99 "
        << r.summary.upload_p99_ms << " ms" << std::setprecision(1) << "\n";
}

void print_replay(std::ostream& out, const config::Recording& recording, int visits, std::size_t tracked,
                  const live::PoseCheck& check) {
  out << "replay of " << recording.folder().string() << ": " << visits << " of " << recording.stops.size() << " stops, "
      << tracked << " poses tracked in lockstep (each lit target's, every frame); against the recording's: " << check.compared
      << " compared, largest difference " << std::setprecision(4) << check.max_mm << " mm, " << check.max_deg << " deg; "
      << check.mismatched << " found or lost in one and not the other; " << check.unreached()
      << " recorded rows for frames the replay did not reach\n";
  if (!recording.reflectance.empty()) {
    out << "compensated with the reflectance learnt while recording:";
    for (const auto& [name, learnt] : recording.reflectance) {
      out << ' ' << name << " (";
      if (learnt.texture.empty())
        out << "albedo " << learnt.albedo.x() << " / " << learnt.albedo.y() << " / " << learnt.albedo.z() << ")";
      else
        out << learnt.texture.string() << ")";
    }
    out << '\n';
  }
}

// Per frame: when it started, the capture time of the depth its pose came from and its expected display
// time (empty for a blank frame), all on the frame profiler's clock; then its start on the run's clock (a
// replay: the recording's), the first drawn target's content time, its video frame's presentation time
// and where it was drawn (its origin in the projector's frame, mm).
void write_profile(const std::string& csv, const std::vector<live::ProjectionRow>& rows, const config::Scene& scene) {
  std::ostringstream f;
  f << "frame,start_ms,pose_age_ms,target,capture_ms,display_ms,error_mm,clock_s,content_s,video_pts_s,x_mm,y_mm,z_mm\n";
  const auto opt = [](double v) { return std::isnan(v) ? std::string() : std::to_string(v); };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const live::ProjectionRow& r = rows[i];
    f << i << ',' << r.start_ms << ',' << (r.age_ms >= 0 ? std::to_string(r.age_ms) : std::string()) << ','
      << (r.target >= 0 ? scene.targets[static_cast<std::size_t>(r.target)].name : std::string()) << ',' << opt(r.capture_ms)
      << ',' << opt(r.display_ms) << ',' << opt(r.error_mm) << ',' << opt(r.clock_s) << ',' << opt(r.content_s) << ','
      << opt(r.video_pts_s) << ',' << opt(r.position_mm.x()) << ',' << opt(r.position_mm.y()) << ',' << opt(r.position_mm.z())
      << '\n';
  }
  config::write_file_atomically(csv, f.str());
  std::cout << "per-frame profile written to " << csv << '\n';
}

// The operator's controls (--console, --osc) and the fleet's bus (--fleet): the show's, and the servers
// acting on it or telling it, which go first.
struct Operated {
  std::unique_ptr<live::ShowControl> show;
  std::unique_ptr<console::Console> console;
  std::unique_ptr<console::OscControl> osc;
  std::unique_ptr<fleet::FleetMember> fleet;
};

// --fleet and --fleet-domain, else the site file's `fleet:`.
std::optional<fleet::FleetConfig> fleet_config(const cli::Args& args, const config::Scene& scene) {
  const auto name = args.get("fleet");
  if (!name && args.get("fleet-domain")) throw cli::UsageError("--fleet-domain applies to --fleet");
  if (!name && !scene.fleet) return std::nullopt;
  fleet::FleetConfig c;
  c.name = name ? *name : scene.fleet->name;
  c.domain = args.get("fleet-domain") ? args.get_int("fleet-domain", 0, 0, 232) : scene.fleet ? scene.fleet->domain : 0;
  if (const std::string why = fleet::fleet_name_problem(c.name); !why.empty())
    throw cli::UsageError((name ? "--fleet " : "fleet.name in " + scene.source.string() + ": ") + c.name + ": " + why);
  return c;
}

// --console and --console-token, else the site file's `console:` (its keys named with the file).
std::optional<console::ConsoleConfig> console_config(const cli::Args& args, const config::Scene& scene) {
  const auto listen = args.get("console");
  auto token_file = args.get("console-token");
  std::string listen_name = "--console", token_name = "--console-token FILE";
  if (!listen && token_file) throw cli::UsageError("--console-token applies to --console");
  if (!listen && !scene.console) return std::nullopt;
  if (!listen) {
    listen_name = "console.listen in " + scene.source.string();
    token_name = "console.token_file in " + scene.source.string();
    if (!scene.console->token_file.empty()) token_file = scene.console->token_file.string();
  }
  const std::string address = listen ? *listen : scene.console->listen;
  console::ConsoleConfig c;
  try {
    c = console::parse_listen(address, listen_name);
    if (token_file) c.token = console::read_token(*token_file);
  } catch (const console::ConsoleError& e) {
    throw cli::UsageError(e.what());
  }
  if (c.token.empty() && !console::is_loopback(c.host))
    throw cli::UsageError(listen_name + " " + address + ": a console on an address other than loopback needs a token (" +
                          token_name + ")");
  return c;
}

// --osc, --osc-allow and --osc-send, else the site file's `osc:`.
std::optional<console::OscConfig> osc_config(const cli::Args& args, const config::Scene& scene) {
  auto allow = args.get("osc-allow");
  auto send = args.get("osc-send");
  if (!args.get("osc")) {
    if (allow || send) throw cli::UsageError(std::string(allow ? "--osc-allow" : "--osc-send") + " applies to --osc");
    if (!scene.osc) return std::nullopt;
  }
  console::OscConfig c;
  if (args.get("osc")) {
    c.port = args.get_int("osc", 0, 0, 65535);
  } else {
    c.port = scene.osc->port;
    c.allowed = scene.osc->allow;
    if (!scene.osc->send.empty()) send = scene.osc->send;
  }
  if (send) {
    const std::string send_name = args.get("osc") ? "--osc-send" : "osc.send in " + scene.source.string();
    try {
      const console::ConsoleConfig to = console::parse_listen(*send, send_name);
      c.send_host = to.host, c.send_port = to.port;
    } catch (const console::ConsoleError& e) {
      throw cli::UsageError(e.what());
    }
    if (c.send_port == 0) throw cli::UsageError(send_name + " " + *send + ": a desk's port is from 1 to 65535");
  }
  std::stringstream hosts(allow.value_or(""));
  for (std::string h; std::getline(hosts, h, ',');)
    if (!h.empty()) c.allowed.push_back(h);
  return c;
}

Operated open_controls(const cli::Args& args, const config::Scene& scene, bool replay) {
  if (replay && !args.get("console") && !args.get("osc") && !args.get("fleet")) {  // the live show's only
    if (scene.console || scene.osc || scene.fleet)
      std::cout << "note: the site file's console:, osc: and fleet: are not started for a replay\n";
    return {};
  }
  const std::optional<console::ConsoleConfig> page = console_config(args, scene);
  const std::optional<console::OscConfig> osc = osc_config(args, scene);
  const std::optional<fleet::FleetConfig> bus = fleet_config(args, scene);
  if (!page && !osc && !bus) return {};
  if (replay)
    throw cli::UsageError(
        "--console, --osc and --fleet do not apply to --replay: a replay's frames wait on its robot, which a "
        "pause would stall, and it is no robot on the floor");
  Operated o;
  o.show = std::make_unique<live::ShowControl>(live::site_targets(scene), scene.content_folder);
  if (page) {
    o.console = std::make_unique<console::Console>(*o.show, *page);
    std::cout << "console: " << o.console->url() << (page->token.empty() ? "" : " (actions need the token)") << std::endl;
  }
  if (bus) {
    try {
      o.fleet = std::make_unique<fleet::FleetMember>(*o.show, *bus);
    } catch (const fleet::FleetError& e) {
      throw cli::UsageError(e.what());
    }
    std::cout << "fleet: " << bus->name << " on DDS domain " << bus->domain << " (rt/" << bus->name << "/pose, rt/" << bus->name
              << "/state)" << std::endl;
  }
  if (osc) {
    o.osc = std::make_unique<console::OscControl>(*o.show, *osc);
    std::cout << "osc: UDP port " << o.osc->port() << ", actions from loopback";
    for (const std::string& h : osc->allowed) std::cout << ", " << h;
    if (!osc->send_host.empty()) std::cout << "; the state to " << osc->send_host << ':' << osc->send_port << " on each change";
    std::cout << std::endl;
  }
  return o;
}

void print_controls(std::ostream& out, const live::RunResult& r, const Operated& o) {
  if (o.fleet)
    out << "fleet: " << o.fleet->published() << " states published as " << o.fleet->config().name << ", "
        << o.fleet->plans_heard() << " plan(s) heard for it\n";
  if (!o.console && !o.osc) return;
  out << "console: " << r.blackout_frames << " frames blacked out";
  if (!r.blackout_latency_ms.empty()) {
    out << "; from each blackout's request to its first black frame's display:";
    for (const double ms : r.blackout_latency_ms) out << ' ' << std::fixed << std::setprecision(1) << ms << " ms";
  }
  if (o.console) out << "; " << o.console->refused() << " requests refused";
  if (o.osc)
    out << "; OSC: " << o.osc->taken() << " actions taken, " << o.osc->refused() << " messages refused, " << o.osc->sent()
        << " states sent";
  out << '\n';
}

}  // namespace

const Command kRun{
    "run",
    "the live engine: project onto the tracked targets while the robot tours (the twin with --sim)",
    "projbot run [--config C.yaml] [--sim | --replay DIR] [--fullscreen] [--monitor N] [--headless] [--profile p.csv]\n"
    "            [--seconds S] [--visits N] [--dwell S] [--seed K] [--present-mode fifo|mailbox|immediate]\n"
    "            [--no-predict] [--compensation on|off] [--learn-reflectance [--reflectance-out DIR]]\n"
    "            [--depth-model fitted|kinect] [--console [ADDR:]PORT [--console-token FILE]]\n"
    "            [--osc PORT [--osc-allow HOSTS] [--osc-send [HOST:]PORT]] [--fleet NAME [--fleet-domain D]]\n\n"
    "Opens the projector output and draws, every frame, each target the robot is projecting onto (the\n"
    "visited one and the others it expects in the projector's view at that stop) at the\n"
    "newest pose its tracker worker accepted (Eq. 2, Eq. 3), moved on by its measured motion to the frame's\n"
    "expected display time (one frame period as measured, plus the projector's input_lag_ms); targets not\n"
    "yet found or lost are blanked.\n"
    "The robot thread drives the tour of the config's `tour.visits`, aims the pan-tilt, gives each worker\n"
    "the initial guess (Eq. 1), the target's surveyed footing and the colour taken on arrival, and dwells\n"
    "while the camera streams depth. Per frame it records the pose's\n"
    "age at display (depth capture to the frame's expected display time), the frame time and, in the twin,\n"
    "the error at the markers at that display time (where the projector's light lands against where they\n"
    "truly are, as the tour measures it: markers it cannot light or lights edge-on are left out); it prints\n"
    "percentiles at the end (the error while a target moves and while it stands still, mm).\n"
    "Devices come from the config's `devices:` section (projbot devices --help shows it): each one configured\n"
    "is opened and read once at start, and one that is absent stops the run with a message naming it.\n"
    "A configured camera replaces the twin's (its frames at its own rate, its colour on arrival) and a\n"
    "configured projector sets the window's monitor and fullscreen. A configured base, pan_tilt and camera\n"
    "(together) make the whole robot: the base is driven to each stop over its ROS 2 topics on its odometry\n"
    "(placed in the map at robot.start), the pan-tilt aims, and no twin runs (so no error is measured); a\n"
    "configured laser localises the base against devices.laser.map (projbot slam's map) while it drives and\n"
    "at each stop. Part of a robot, or a laser without a base or a map, stops the run saying so. With none\n"
    "configured, or with --sim, the digital twin serves every device. A live camera that hands over no frame\n"
    "for 100 ms blanks the projection until its frames come back. A device that fails while projecting\n"
    "blanks the projector at once; what was measured until then is printed and written, and the failure is\n"
    "reported (exit 1).\n"
    "With --replay DIR the session runs from a recording (projbot record): the base and pan-tilt answer\n"
    "what they answered then, each stop's frames play at their recorded times and are tracked in lockstep,\n"
    "and every pose is compared with the recording's (the largest difference is printed); no device and\n"
    "no twin is used, so nothing is measured against a truth. A replay runs on the recording's clock: each\n"
    "projector frame is one refresh of it and is drawn once the session has done everything before it\n"
    "(drives take their recorded time, each video frame is waited for), so a replay draws the same frames,\n"
    "poses and content every time (--profile shows them), as fast as the machine tracks and draws. Targets\n"
    "whose reflectance the recording learnt (recording.yaml's `reflectance:`) are compensated with it in place\n"
    "of the scene's `surface:`.\n"
    "With --learn-reflectance, at each stop, once the visited target's pose is accepted, the projector shows\n"
    "black and then mid grey over its whole image, each until the camera has taken a frame under it (three\n"
    "refreshes, the input lag and a camera frame: about 0.1 s each), and the target's reflectance is read\n"
    "from the two colour images at the tracked pose (the light's distance and angle divided out, the room's\n"
    "light subtracted) into a map over its model's texture coordinates, refined over its visits; it\n"
    "replaces the scene's `surface:` in the compensation from then on. The camera's colour must be\n"
    "registered to its depth and sRGB-coded. In the twin its camera sees the projector's black and grey.\n"
    "With --reflectance-out DIR (a new folder), what was learnt is written after each measurement: each map\n"
    "as a PNG and surfaces.yaml, each target's `surface:` line to put into the scene.\n"
    "Targets with `content:` (a video, a timeline) or animated materials play them on each frame's display\n"
    "time; a video, model or texture file that changes on disk is loaded again and swapped in at a later\n"
    "frame (tracking goes on; a model of another shape is not), and one that fails to load leaves the old\n"
    "one and says why.\n"
    "With --console [ADDR:]PORT the operator's console is served while the show runs (docs/console.md): a web\n"
    "page with the map, the phase, each target's state and error, and buttons to black the projector out,\n"
    "pause the tour and send the robot to a target; under it GET /api/state and /api/events (server-sent\n"
    "events) and POST /api/blackout, /api/pause, /api/goto. It listens on 127.0.0.1 unless an address is\n"
    "given; any other address needs --console-token FILE (a file only its owner may read: mode 0600), and\n"
    "every action must then carry `Authorization: Bearer TOKEN`. Port 0 takes a free one (printed).\n"
    "With --osc PORT the same actions come over OSC (UDP): /projbot/blackout i, /projbot/pause i (1 on, 0 off)\n"
    "and /projbot/goto s (a target's name), taken only from loopback senders and the hosts --osc-allow lists;\n"
    "with --osc-send, /projbot/state s i s i i (phase, visit, target, blackout, paused) goes there on each change.\n"
    "Without --config the shipped demo tour runs in the twin.\n",
    {{"config", "FILE", "tour scene (default: assets/scenes/tour.yaml)", cli::PathRole::input_file},
     {"sim", "", "run against the digital twin, whatever `devices:` configures (the default without one)"},
     {"replay", "DIR", "run the session from a recording (projbot record): no device, no twin; its scene unless --config",
      cli::PathRole::input_folder},
     {"fullscreen", "", "fullscreen on --monitor (the projector)"},
     {"monitor", "N", "monitor index for --fullscreen (default 0)"},
     {"headless", "", "draw offscreen at 60 Hz instead of a window (profiling without a display)"},
     {"present-mode", "MODE", "fifo (default, vsync), mailbox or immediate"},
     {"profile", "FILE",
      "write one CSV row per frame: start, pose age, capture and display time, error; the run's clock, content and "
      "video time, where the target was drawn",
      cli::PathRole::output_file},
     {"seconds", "S", "stop after S seconds (default 0: when the tour ends, the window is closed or Ctrl-C)"},
     {"visits", "N", "visits, cycling through the tour (default: the list once)"},
     {"dwell", "S", "seconds the robot projects at each stop (default 4)"},
     {"seed", "K", "seed of the twin's noise (default 1)"},
     depth_model_option(),
     {"no-predict", "", "draw the newest measured pose, not the one predicted for display time"},
     {"compensation", "on|off",
      "radiometric compensation of each target's surface and the room's light (default on; off: the content as stored)"},
     {"learn-reflectance", "",
      "measure each visited target's reflectance at its stop (the projector black, then grey, a moment each) and "
      "compensate with it"},
     {"reflectance-out", "DIR",
      "with --learn-reflectance: save what is learnt (each map as a PNG, surfaces.yaml) in this new folder",
      cli::PathRole::output_folder},
     {"console", "[ADDR:]PORT", "serve the operator's console (web page and API) there; ADDR defaults to 127.0.0.1"},
     {"console-token", "FILE", "the token the console's actions must carry (a file of mode 0600); needed off loopback",
      cli::PathRole::input_file},
     {"osc", "PORT", "take show control over OSC on this UDP port (0: any free one): /projbot/blackout i, pause i, goto s"},
     {"osc-allow", "HOSTS", "with --osc: the senders besides loopback whose actions are taken (IP addresses, comma-separated)"},
     {"osc-send", "[HOST:]PORT", "with --osc: send /projbot/state (phase, visit, target, blackout, paused) there on each change"},
     {"fleet", "NAME",
      "join the fleet's DDS bus as robot NAME: its pose (rt/NAME/pose, geometry_msgs/PoseStamped) and state "
      "(rt/NAME/state) at 5 Hz, its liveliness"},
     {"fleet-domain", "D", "with --fleet: the DDS domain, 0..232 (default: the site file's fleet.domain, else 0)"}},
    [](const cli::Args& args) {
      catch_interrupts();  // Ctrl-C / SIGTERM: leave the frame loop at the next frame, then write what was measured
      if (args.flag("learn-reflectance") && args.get("replay"))
        throw cli::UsageError(
            "--learn-reflectance and --replay: a recording's frames were taken without the projector's "
            "black and grey (record learns in the twin; a replay compensates with what it learnt)");
      const std::optional<config::Recording> recording = replay_of(args);
      const std::string scene_path =
          args.get_or("config", recording ? recording->scene.string() : (asset_dir() / "scenes" / "tour.yaml").string());
      config::Scene scene = config::load_scene(scene_path);
      check_scene_outputs(args, scene, recording ? "the recording's scene" : "the default scene");
      if (recording) config::use_learnt_reflectance(scene, *recording);  // compensated as the session learnt it
      if (scene.visits.empty())
        throw config::ConfigError(scene.source.string() + ": `projbot run` needs a 'tour: {visits: [...]}' section");
      const Operated operated = open_controls(args, scene, recording.has_value());
      std::optional<live::PoseCheck> check;
      if (recording) check.emplace(recording->folder() / "poses.csv");
      live::Devices devices =
          args.flag("sim") || recording ? live::Devices{} : live::open_run_devices(scene, args.flag("headless"), std::cout);
      const TourFamilyArgs family = tour_family_args(args, 4.0);
      const live::RunOptions o = run_options(args, family);

      engine::RendererOptions ro;
      ro.windowing = !o.headless;
      engine::Renderer renderer(ro);
      std::cout << "device: " << renderer.device_info().name << std::endl;  // flushed: a log shows it has started
      if (!devices.base && !recording) note_twin_on_odometry(std::cout);
      const bool configured = !args.flag("sim") && !recording;
      live::RunSources sources;
      sources.devices = &devices;
      sources.open_rig = twin::rig_opener({.seed = family.seed, .depth_model = family.depth_noise});
      sources.replay = recording ? &*recording : nullptr;
      sources.check = check ? &*check : nullptr;
      sources.open_output = [&](engine::Renderer& r) { return open_output(r, args, scene, o.headless, configured); };
      sources.interrupted = [] { return interrupted(); };
      sources.log = &std::cout;
      sources.errors = &std::cerr;
      sources.show = operated.show.get();
      if (operated.fleet) {
        sources.planned_targets = [&fleet = *operated.fleet] { return fleet.planned_targets(); };
        sources.map_poses = [&fleet = *operated.fleet](int target) { return fleet.map_pose(target); };
      }
      const live::RunResult r = live::run(renderer, scene, o, sources);

      print_frames(std::cout, r);
      if (recording) {
        print_replay(std::cout, *recording, r.visits, r.tracked, *check);
      } else {
        if (!r.measured)
          std::cout << "error at display: not measured (the configured robot: no truth to measure against)\n";
        else
          print_display_errors(std::cout, r.figures);
        print_robot(std::cout, r, devices.camera != nullptr);
      }
      if (operated.show) print_controls(std::cout, r, operated);
      if (const auto csv = args.get("profile")) write_profile(*csv, r.figures.rows, scene);
      if (!r.failure.empty()) {
        std::cerr << "projbot run: " << r.failure << " (the projection was blanked; what was measured until then is above)\n";
        return 1;
      }
      return interrupt_exit_code();  // 0, or 130 / 143 after Ctrl-C / SIGTERM
    }};

}  // namespace projbot::tools
