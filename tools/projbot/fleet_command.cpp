// projbot fleet: the fleet's coordinator (issue 69, item 2). It hears the robots on the DDS domain and
// publishes which of the site's targets each one visits, again whenever a robot joins or is lost.

#include <chrono>
#include <cstdio>
#include <iostream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "projbot/fleet/coordinator.hpp"
#include "scene_setup.hpp"

namespace projbot::tools {

namespace {

int run_fleet(const cli::Args& args) {
  const config::Scene scene = config::load_scene(args.get_or("config", (asset_dir() / "scenes" / "tour.yaml").string()));
  fleet::CoordinatorConfig c;
  c.domain = args.get("domain") ? args.get_int("domain", 0, 0, 232) : scene.fleet ? scene.fleet->domain : 0;
  c.strength = args.get_int("strength", 10, 0, 1000000);
  c.name = args.get_or("name", "");
  const double seconds = args.get_double("seconds", 0.0);
  if (!(seconds >= 0.0) || seconds > 1e6) throw cli::UsageError("--seconds must be 0 (until Ctrl-C) to 1e6");
  catch_interrupts();  // Ctrl-C: the coordinator leaves the bus; a standby's plan is read from then on
  fleet::Coordinator coordinator(scene, c);
  std::cout << "fleet coordinator on DDS domain " << c.domain << ", strength " << c.strength << ": the targets of "
            << scene.source.string() << " to the robots heard (rt/fleet/plan)" << std::endl;
  const auto t0 = std::chrono::steady_clock::now();
  const auto elapsed_s = [t0] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(); };
  coordinator.run([&] { return interrupted() || (seconds > 0.0 && elapsed_s() >= seconds); },
                  [&](const std::string& line) {
                    char at[32];
                    std::snprintf(at, sizeof at, "[%7.2f s] ", elapsed_s());
                    std::cout << at << line << std::endl;
                  });
  std::cout << "coordinator: " << coordinator.plans() << " plan(s) made in " << elapsed_s() << " s" << std::endl;
  return interrupt_exit_code();
}

}  // namespace

const Command kFleet{
    "fleet",
    "the fleet's coordinator: which robot visits which target, over DDS",
    "projbot fleet [--config site.yaml] [--domain D] [--strength N] [--name NAME] [--seconds S]\n\n"
    "Hears every robot on the DDS domain (`projbot run --fleet NAME`: its rt/NAME/state and rt/NAME/pose) and\n"
    "publishes the plan on rt/fleet/plan: each of the site's targets with a stop goes to one robot, the\n"
    "nearest free one (round by round, each robot given the fewest so far takes the nearest target left from\n"
    "where its route ends; path lengths on the room's floor, its obstacles grown by the robot's radius), so\n"
    "every reachable target is visited and the robots share the work. A robot visits its\n"
    "targets in turn and again (one target alone: it stays lit on it); a robot the plan gives nothing waits.\n"
    "When a robot joins or is lost (its liveliness, a 1 s lease) the plan is made again at once. The plan is\n"
    "durable: a robot that starts late reads the newest. Two coordinators may run: the plan read is the\n"
    "stronger one's (DDS exclusive ownership, --strength), and the other's within half a second of it going.\n"
    "Each change is printed with the time since the start. Ctrl-C ends it.\n",
    {{"config", "FILE", "site file: the targets, their stops, the room (default: assets/scenes/tour.yaml)",
      cli::PathRole::input_file},
     {"domain", "D", "the DDS domain, 0..232 (default: the site file's fleet.domain, else 0)"},
     {"strength", "N", "DDS ownership strength, 0..1000000: the strongest live coordinator's plan is read (default 10)"},
     {"name", "NAME", "said in the plan (default: host:pid)"},
     {"seconds", "S", "stop after S seconds (default 0: until Ctrl-C)"}},
    run_fleet};

}  // namespace projbot::tools
