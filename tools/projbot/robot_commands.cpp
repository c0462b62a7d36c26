// projbot slam / localize / bench localize: the robot's map, its self-localisation, and how well
// localisation holds up over simulated tours.

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <optional>
#include <sstream>

#include "commands.hpp"
#include "interrupt.hpp"
#include "progress.hpp"
#include "projbot/config/angles.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/paths.hpp"
#include "projbot/config/scene.hpp"
#include "projbot/robot/localization.hpp"
#include "projbot/robot/sim_tour.hpp"

namespace projbot::tools {
namespace {

namespace fs = std::filesystem;
using robot::Pose2D;
constexpr double kDeg = config::degrees(1.0);

void print_errors(const std::string& what, const robot::TrajectoryErrors& s) {
  std::cout << std::fixed << std::setprecision(2) << "  " << what << ": mean " << s.mean_m * 100 << " cm / " << s.mean_deg
            << " deg, max " << s.max_m * 100 << " cm / " << s.max_deg << " deg over " << s.n << " poses\n";
}

const fs::path kDefaultGtRawlog = fs::path(PROJBOT_SHARED_DATA) / "mrpt" / "range_030_bearing_015.rawlog";

}  // namespace

Pose2D parse_pose(const std::string& text, const std::string& what) {
  const auto v = cli::spaced_numbers(text, 3, what);
  return {v[0], v[1], v[2]};
}

namespace {

// What a build without MRPT (the portable one) says of the commands that need it.
std::string mrpt_left_out() { return robot::built_with_mrpt() ? "" : "needs MRPT (maps, rawlogs, laser localisation)"; }

}  // namespace

const Command kSlam{
    "slam",
    "build the environment map from a laser rawlog (MRPT ICP-SLAM)",
    "projbot slam --rawlog R [--config icp-slam.ini] --out-map DIR --out-trajectory T.txt [--ground-truth GT.txt]\n"
    "            [--start \"x y phi\"]\n\n"
    "Runs mrpt::slam::CMetricMapBuilderICP over an MRPT rawlog of 2-D laser scans and odometry. DIR receives\n"
    "map.simplemap.gz (keyframes, what `projbot localize` reads), grid.png and grid.yaml (occupancy grid,\n"
    "ROS map_server form). T.txt gets one line per step: timestamp x y phi (s, m, m, rad). Without --config the\n"
    "settings of MRPT's icp-slam_demo_classic.ini apply. With --ground-truth (same line format) it prints the\n"
    "trajectory error; without, the gap between the first and last pose for SLAM and for odometry alone.\n"
    "The map's frame is the one the rawlog's first pose is given in by --start (metres, metres, radians;\n"
    "default 0 0 0, the first pose is the origin). For a mapping run of `projbot record` (a laser configured\n"
    "without a map), pass where it began as record prints it (the scene's robot.start, its heading in\n"
    "radians): the map is then in the scene's frame, where its targets, stops and robot.start are, and\n"
    "`projbot run` localises in it.\n",
    {{"rawlog", "FILE", "MRPT rawlog (.rawlog, plain or gzip)", cli::PathRole::input_file},
     {"config", "FILE", "icp-slam .ini with [MappingApplication] and [ICP] sections", cli::PathRole::input_file},
     {"out-map", "DIR", "directory for the map (created)", cli::PathRole::output_folder},
     {"out-trajectory", "FILE", "where to write the corrected trajectory", cli::PathRole::output_file},
     {"ground-truth", "FILE", "true trajectory to compare with (timestamp x y phi lines)", cli::PathRole::input_file},
     {"verbose", "", "let MRPT's own log lines (its map builder's) through to stderr"},
     {"start", "\"x y phi\"", "where the rawlog's first pose lies in the map (default 0 0 0)"}},
    [](const cli::Args& args) {
      for (const char* required : {"rawlog", "out-map", "out-trajectory"})
        if (!args.get(required)) throw cli::UsageError(std::string("--") + required + " is required");
      try {  // a folder of anything but an earlier map is refused, never emptied
        config::check_replaceable_folder(*args.get("out-map"), robot::map_folder_files());
      } catch (const config::OutputError& e) {
        throw cli::UsageError("--out-map " + std::string(e.what()));
      }
      std::optional<fs::path> ini;
      if (const auto c = args.get("config")) ini = *c;
      if (ini)
        for (const auto& warning : robot::check_icp_slam_config(*ini)) std::cerr << "projbot slam: warning: " << warning << '\n';
      std::optional<std::vector<robot::TrajectoryPoint>> truth;  // read before the work: a bad file costs nothing
      if (const auto gt = args.get("ground-truth")) truth = robot::read_trajectory(*gt);
      const Pose2D start = parse_pose(args.get_or("start", "0 0 0"), "--start");
      catch_interrupts();  // Ctrl-C: map and write the scans done so far, then exit 130
      std::cout << "reading " << *args.get("rawlog") << "..." << std::endl;
      const auto steps = robot::read_rawlog(*args.get("rawlog"));
      if (interrupted()) return nothing_written("while reading the rawlog");
      std::cout << "mapping " << steps.size() << " scans (Ctrl-C stops and keeps the map of the scans done)..." << std::endl;
      Progress progress("scan", static_cast<int>(steps.size()));
      int asked = 0;  // build_map asks before each scan: the scans done so far are one fewer
      const robot::SlamResult r = robot::build_map(
          steps, ini, *args.get("out-map"),
          [&] {
            if (++asked > 1) progress.step(asked - 1);
            return interrupted();
          },
          args.flag("verbose"), start);
      if (r.trajectory.empty()) return nothing_written("before the first scan");
      robot::write_trajectory(*args.get("out-trajectory"), r.trajectory);
      if (r.interrupted) {
        std::cout << "ICP-SLAM interrupted after " << r.trajectory.size() << " of " << steps.size()
                  << " scans; wrote the map of those to " << *args.get("out-map") << " and their trajectory to "
                  << *args.get("out-trajectory") << '\n';
        return interrupt_exit_code();
      }
      std::cout << std::fixed << std::setprecision(2) << "ICP-SLAM: " << steps.size() << " scans, " << r.keyframes
                << " keyframes, " << r.seconds << " s (" << r.seconds * 1000 / static_cast<double>(steps.size())
                << " ms per scan)\n";
      const auto odometry = robot::dead_reckoning(steps, r.trajectory.front().pose);
      if (truth) {
        print_errors("ICP-SLAM vs ground truth", robot::trajectory_errors(r.trajectory, *truth));
        print_errors("odometry vs ground truth", robot::trajectory_errors(odometry, *truth));
      } else {
        const auto gap = [](const std::vector<robot::TrajectoryPoint>& t) {
          return robot::distance_m(t.front().pose, t.back().pose);
        };
        std::cout << "  first-to-last pose gap: ICP-SLAM " << gap(r.trajectory) << " m, odometry alone " << gap(odometry)
                  << " m\n";
      }
      std::cout << "  wrote " << *args.get("out-map") << "/{map.simplemap.gz,grid.png,grid.yaml} and "
                << *args.get("out-trajectory") << '\n';
      return 0;
    },
    mrpt_left_out()};

const Command kLocalize{
    "localize",
    "localise a rawlog against a saved map (scan-to-map ICP with odometry)",
    "projbot localize --map DIR --rawlog R --out-trajectory T.txt [--initial \"x y phi\"] [--ground-truth GT.txt]\n\n"
    "Follows odometry between scans and corrects each scan by ICP (mrpt::slam::CICP) against the map that\n"
    "`projbot slam` wrote to DIR. The robot starts at --initial (metres, metres, radians; default 0 0 0).\n",
    {{"map", "DIR", "map directory written by projbot slam", cli::PathRole::input_folder},
     {"rawlog", "FILE", "MRPT rawlog of 2-D laser scans and odometry", cli::PathRole::input_file},
     {"out-trajectory", "FILE", "where to write the trajectory (timestamp x y phi)", cli::PathRole::output_file},
     {"initial", "\"x y phi\"", "start pose in the map (default 0 0 0)"},
     {"ground-truth", "FILE", "true trajectory to compare with", cli::PathRole::input_file}},
    [](const cli::Args& args) {
      for (const char* required : {"map", "rawlog", "out-trajectory"})
        if (!args.get(required)) throw cli::UsageError(std::string("--") + required + " is required");
      const Pose2D start = parse_pose(args.get_or("initial", "0 0 0"), "--initial");
      std::optional<std::vector<robot::TrajectoryPoint>> truth;  // read before the work
      if (const auto gt = args.get("ground-truth")) truth = robot::read_trajectory(*gt);
      catch_interrupts();  // Ctrl-C: write the trajectory of the scans done, then exit 130
      robot::Localizer loc = robot::Localizer::load(*args.get("map"));
      const auto steps = robot::read_rawlog(*args.get("rawlog"));
      if (interrupted()) return nothing_written("while reading the map and the rawlog");
      std::cout << "localising " << steps.size() << " scans (Ctrl-C stops and keeps the trajectory of the scans done)..."
                << std::endl;
      Progress progress("scan", static_cast<int>(steps.size()));
      const robot::RawlogLocalization r = robot::localize_rawlog(loc, steps, start, [&progress](int done) {
        progress.step(done);
        return !interrupted();
      });
      const std::vector<robot::TrajectoryPoint>& out = r.trajectory;
      if (out.empty()) return nothing_written("before the first scan");
      robot::write_trajectory(*args.get("out-trajectory"), out);
      if (interrupted()) {
        std::cout << "localisation interrupted after " << out.size() << " of " << steps.size()
                  << " scans; their trajectory is in " << *args.get("out-trajectory") << '\n';
        return interrupt_exit_code();
      }
      std::cout << std::fixed << std::setprecision(2) << "localised " << steps.size() << " scans against " << loc.map_points()
                << " map points: " << r.accepted << " accepted, " << r.correct_ms / static_cast<double>(steps.size())
                << " ms per scan\n";
      if (truth) {
        print_errors("localisation vs ground truth", robot::trajectory_errors(out, *truth));
        print_errors("odometry vs ground truth", robot::trajectory_errors(robot::dead_reckoning(steps, start), *truth));
      }
      return 0;
    },
    mrpt_left_out()};

// One row of the simulated-tour table of bench localize.
// Returns false, printing nothing, when the tour was interrupted.
bool print_sim_tour_row(int n, robot::PoseSource source, int seed) {
  robot::SimTourConfig cfg = robot::default_sim_tour();
  cfg.stop_count = n;
  cfg.source = source;
  cfg.errors.seed = static_cast<std::uint64_t>(seed);
  const auto reports = robot::run_sim_tour(cfg, [] { return interrupted(); });
  if (interrupted()) return false;
  // The error of what the robot believes: with odometry alone that is the odometry's drift.
  const robot::SimTourErrors e = robot::tour_errors(reports);
  const bool localized = source == robot::PoseSource::localized;
  std::cout << std::fixed << std::setprecision(2) << "| " << n << " | " << (localized ? "MRPT localisation" : "odometry alone")
            << " | " << e.mean_m * 100 << " | " << e.max_m * 100 << " | " << e.mean_rad * kDeg << " | " << e.max_rad * kDeg
            << " | " << e.last_odometry_m * 100 << " / " << e.last_odometry_rad * kDeg << " | "
            << (localized ? e.correct_ms : 0.0) << " |" << std::endl;
  return true;
}

const Command kBenchLocalize{
    "bench localize",
    "benchmark localisation at the stops of simulated tours, and ICP-SLAM vs ground truth",
    "projbot bench localize [--stops 3,10,30] [--seed K] [--rawlog R --ground-truth GT]\n\n"
    "Drives the simulated youBot (wheel slip, wheel-radius and heading bias) through tours of the built-in\n"
    "8 x 6 m room, once closing the loop on MRPT localisation and once on odometry alone, and prints the\n"
    "pose error at the stops. Then runs ICP-SLAM on a rawlog with ground truth (default: the simulated\n"
    "range_030_bearing_015 dataset in ../shared/data/mrpt) and prints its trajectory error.\n",
    {{"stops", "N,N,...", "tour lengths (default 3,10,30)"},
     {"seed", "K", "random seed of the base's errors and the laser noise (default 1)"},
     {"rawlog", "FILE", "rawlog with ground truth for the ICP-SLAM part", cli::PathRole::input_file},
     {"ground-truth", "FILE", "its true trajectory", cli::PathRole::input_file}},
    [](const cli::Args& args) {
      std::vector<int> counts;
      {
        std::stringstream ss(args.get_or("stops", "3,10,30"));
        std::string item;
        while (std::getline(ss, item, ',')) {
          int n = 0;
          try {
            n = std::stoi(item);
          } catch (const std::exception&) {
            n = 0;
          }
          if (n < 1 || n > 1000) throw cli::UsageError("--stops: each tour length must be 1..1000, got '" + item + "'");
          counts.push_back(n);
        }
      }
      const int seed = args.get_int("seed", 1, 0, 1 << 30);
      // The ICP-SLAM dataset, read before the tours: a file the user named must be there and readable.
      if (args.get("ground-truth") && !args.get("rawlog"))
        throw cli::UsageError("--ground-truth needs --rawlog (the rawlog it is the truth of)");
      const fs::path rawlog = args.get_or("rawlog", kDefaultGtRawlog.string());
      const fs::path gt = args.get_or("ground-truth", rawlog.string() + ".GT.txt");
      std::optional<std::pair<std::vector<robot::RawlogStep>, std::vector<robot::TrajectoryPoint>>> dataset;
      if (args.get("rawlog") || (fs::exists(rawlog) && fs::exists(gt)))
        dataset.emplace(robot::read_rawlog(rawlog), robot::read_trajectory(gt));
      catch_interrupts();  // Ctrl-C: the rows printed so far are whole; exit 130
      std::cout << "Simulated tours (youBot with 2 % slip, 1 % wheel radii, 0.01 rad/m heading bias; UTM-30LX 1 cm noise)\n"
                << "| stops | closes the loop on | mean cm | max cm | mean deg | max deg | odometry drift at last stop cm / deg "
                   "| ms per scan |\n"
                << "|---|---|---|---|---|---|---|---|\n";
      for (const int n : counts)
        for (const auto source : {robot::PoseSource::localized, robot::PoseSource::odometry}) {
          if (!print_sim_tour_row(n, source, seed)) return benchmark_interrupted("during the simulated tours");
        }
      if (!dataset) {
        std::cout << "\nICP-SLAM part skipped: " << rawlog << " or " << gt << " not found\n";
        return 0;
      }
      const auto& [steps, truth] = *dataset;
      const fs::path dir = fs::temp_directory_path() / ("projbot_bench_slam_" + std::to_string(::getpid()));
      const auto r = robot::build_map(steps, std::nullopt, dir, [] { return interrupted(); });
      fs::remove_all(dir);
      if (r.interrupted) return benchmark_interrupted("during ICP-SLAM");
      std::cout << "\nICP-SLAM on " << rawlog.filename() << " (" << steps.size() << " scans, " << r.keyframes << " keyframes, "
                << r.seconds * 1000 / static_cast<double>(steps.size()) << " ms per scan):\n";
      print_errors("ICP-SLAM vs ground truth", robot::trajectory_errors(r.trajectory, truth));
      print_errors("odometry vs ground truth",
                   robot::trajectory_errors(robot::dead_reckoning(steps, r.trajectory.front().pose), truth));
      return 0;
    },
    mrpt_left_out()};

}  // namespace projbot::tools
