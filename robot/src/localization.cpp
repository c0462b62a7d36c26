// Rawlogs, ICP-SLAM and scan-to-map localisation: mrpt::slam, one translation unit.
#include "projbot/robot/localization.hpp"

#include <mrpt/config/CConfigFile.h>
#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/maps/CSimpleMap.h>
#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CActionRobotMovement2D.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/poses/CPose3DPDF.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>
#include <mrpt/slam/CICP.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "icp_slam_ini.hpp"
#include "mrpt_convert.hpp"
#include "projbot/config/clock.hpp"
#include "projbot/config/isolated_read.hpp"
#include "projbot/config/output_file.hpp"
#include "projbot/config/paths.hpp"

namespace projbot::robot {

bool built_with_mrpt() { return true; }

namespace {

using Clock = std::chrono::steady_clock;
using config::ms_since;

mrpt::obs::CActionCollection::Ptr odometry_action(const Pose2D& increment, double timestamp_s) {
  mrpt::obs::CActionRobotMovement2D move;
  move.timestamp = mrpt::Clock::fromDouble(timestamp_s);  // CMetricMapBuilderICP asserts one
  mrpt::obs::CActionRobotMovement2D::TMotionModelOptions model;
  move.computeFromOdometry(detail::to_mrpt(increment), model);
  auto actions = mrpt::obs::CActionCollection::Create();
  actions->insert(move);
  return actions;
}

// MRPT's exception texts open with a "==== MRPT exception ====" banner and carry a call stack; users
// get the first line that says something: not the banner, not a source location.
std::string first_line(const std::exception& e) {
  std::istringstream lines(e.what());
  for (std::string line; std::getline(lines, line);) {
    const auto start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line[start] == '=') continue;
    line = line.substr(start);
    if (line.rfind("Message:", 0) == 0) line = line.substr(line.find_first_not_of(" \t", 8));
    if (line.find(".cpp:") != std::string::npos || line.find(".h:") != std::string::npos || line.rfind("Location", 0) == 0)
      continue;
    if (!line.empty()) return line;
  }
  return "unreadable (MRPT gave no message)";
}

void write_map_files(const std::filesystem::path& out_dir, const mrpt::maps::CSimpleMap& keyframes) {
  if (!keyframes.saveToFile((out_dir / "map.simplemap.gz").string()))
    throw RobotError((out_dir / "map.simplemap.gz").string() + ": cannot write");
  mrpt::maps::COccupancyGridMap2D grid(-10, 10, -10, 10, 0.05f);
  grid.loadFromSimpleMap(keyframes);
  if (!grid.saveAsBitmapFile((out_dir / "grid.png").string()))
    throw RobotError((out_dir / "grid.png").string() + ": cannot write");
  std::ostringstream yaml;
  yaml << "# ROS map_server form: the grid image, its cell size and its lower-left corner in the map frame\n"
       << "image: grid.png\nresolution: " << grid.getResolution() << "\norigin: [" << grid.getXMin() << ", " << grid.getYMin()
       << ", 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n";
  config::write_file_atomically(out_dir / "grid.yaml", yaml.str());
}

void swap_into_place(const std::filesystem::path& work_dir, const std::filesystem::path& final_dir) {
  std::error_code ec;
  const std::filesystem::path old_dir = final_dir.string() + ".old-" + std::to_string(::getpid());
  const bool had_old = std::filesystem::exists(final_dir, ec);
  if (had_old) std::filesystem::rename(final_dir, old_dir, ec);
  if (!ec) std::filesystem::rename(work_dir, final_dir, ec);
  if (ec) {
    const std::string why = ec.message();
    if (had_old && !std::filesystem::exists(final_dir)) std::filesystem::rename(old_dir, final_dir, ec);
    std::filesystem::remove_all(work_dir, ec);
    throw RobotError(final_dir.string() + ": cannot put the new map in place (" + why + "); the old one is unchanged");
  }
  std::filesystem::remove_all(old_dir, ec);
}

}  // namespace

namespace {

bool is_gzip(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[2] = {};
  return in.read(magic, 2) && magic[0] == '\x1f' && magic[1] == '\x8b';
}

// MRPT's reader, object by object (not CRawlog's pair reader, which drops a sensory frame that comes
// before the first action) until the end of the file. Runs in the isolated child.
std::vector<RawlogStep> read_rawlog_objects(const std::filesystem::path& path, config::ReadProgress& progress) {
  std::vector<RawlogStep> steps;
  const bool gzip = is_gzip(path);
  mrpt::io::CFileGZInputStream in(path.string());
  auto archive = mrpt::serialization::archiveFrom(in);
  std::optional<Pose2D> pending_odometry;             // action-observation format
  std::optional<mrpt::poses::CPose2D> last_absolute;  // observation-only format
  for (;; ++progress.objects) {
    if (!gzip) progress.offset = in.getPosition();
    mrpt::serialization::CSerializable::Ptr object;
    try {
      object = archive.ReadObject();
    } catch (const mrpt::serialization::CExceptionEOF&) {
      break;
    }
    mrpt::obs::CObservation2DRangeScan::Ptr scan;
    if (auto actions = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(object)) {
      if (auto move = actions->getBestMovementEstimation()) pending_odometry = detail::from_mrpt(move->poseChange->getMeanVal());
    } else if (auto frame = std::dynamic_pointer_cast<mrpt::obs::CSensoryFrame>(object)) {
      scan = frame->getObservationByClass<mrpt::obs::CObservation2DRangeScan>();
    } else if (auto odo = std::dynamic_pointer_cast<mrpt::obs::CObservationOdometry>(object)) {
      if (last_absolute) {
        const Pose2D inc = detail::from_mrpt(odo->odometry - *last_absolute);
        pending_odometry = pending_odometry ? compose(*pending_odometry, inc) : inc;
      }
      last_absolute = odo->odometry;
    } else {
      scan = std::dynamic_pointer_cast<mrpt::obs::CObservation2DRangeScan>(object);
    }
    if (!scan) continue;
    RawlogStep step;
    step.scan = detail::from_mrpt(*scan);
    step.timestamp_s = step.scan.timestamp_s;
    step.odometry_increment = pending_odometry;
    pending_odometry.reset();
    steps.push_back(std::move(step));
  }
  return steps;
}

void put_scan(config::Bytes& out, const LaserScan& s) {
  out.put(s.timestamp_s);
  out.put(s.sensor_on_base);
  out.put(s.aperture_rad);
  out.put(s.max_range_m);
  out.put_vector(s.ranges_m);
  out.put_vector(s.valid);
}

LaserScan get_scan(config::BytesReader& in) {
  LaserScan s;
  s.timestamp_s = in.get<double>();
  s.sensor_on_base = in.get<Pose2D>();
  s.aperture_rad = in.get<double>();
  s.max_range_m = in.get<double>();
  s.ranges_m = in.get_vector<float>();
  s.valid = in.get_vector<std::uint8_t>();
  if (s.valid.size() != s.ranges_m.size()) throw RobotError("isolated read: scan with mismatched sizes");
  return s;
}

// config::read_isolated, its errors as the robot module's.
std::string read_isolated(const std::filesystem::path& file, const config::IsolatedReader& what,
                          const std::function<std::string(config::ReadProgress&)>& read) {
  try {
    return config::read_isolated(file, what, read);
  } catch (const config::IsolatedReadError& e) {
    throw RobotError(e.what());
  }
}

// What a laser and odometry can report; a step outside it is corruption, named by its number.
void check_step(const std::filesystem::path& path, std::size_t index, const RawlogStep& step) {
  const auto& s = step.scan;
  const Pose2D odo = step.odometry_increment.value_or(Pose2D{});
  std::string wrong;
  if (!std::isfinite(step.timestamp_s) || step.timestamp_s < 0)
    wrong = "timestamp";
  else if (!std::isfinite(odo.x_m + odo.y_m + odo.theta_rad) || std::hypot(odo.x_m, odo.y_m) > 1e3)
    wrong = "odometry";
  else if (!(s.aperture_rad > 0 && s.aperture_rad <= 2 * M_PI + 1e-3))
    wrong = "aperture";
  else if (!(s.max_range_m > 0 && s.max_range_m <= 1e3))
    wrong = "maximum range";
  else if (s.ranges_m.empty() || s.ranges_m.size() > 100000)
    wrong = "number of rays";
  else if (!std::isfinite(s.sensor_on_base.x_m + s.sensor_on_base.y_m + s.sensor_on_base.theta_rad))
    wrong = "sensor pose";
  for (std::size_t i = 0; wrong.empty() && i < s.ranges_m.size(); ++i)
    if (s.valid[i] != 0 && !(std::isfinite(s.ranges_m[i]) && s.ranges_m[i] >= 0)) wrong = "range of ray " + std::to_string(i);
  if (!wrong.empty())
    throw RobotError(path.string() + ": corrupt MRPT rawlog: scan " + std::to_string(index + 1) + " has an impossible " + wrong);
}

}  // namespace

std::vector<RawlogStep> read_rawlog(const std::filesystem::path& path) {
  if (const std::string kind = config::input_file_problem(path); !kind.empty())
    throw RobotError(path.string() + (kind == "does not exist" ? std::string(": no such rawlog file") : ": " + kind));
  // MRPT's deserialiser crashes on corrupt archives (flipped bits): it reads in a child process.
  const std::string bytes = read_isolated(path, {"MRPT rawlog", "MRPT's reader"}, [&](config::ReadProgress& progress) {
    config::Bytes out;
    try {
      for (const RawlogStep& step : read_rawlog_objects(path, progress)) {
        out.put(step.timestamp_s);
        out.put<std::uint8_t>(step.odometry_increment ? 1 : 0);
        out.put(step.odometry_increment.value_or(Pose2D{}));
        put_scan(out, step.scan);
      }
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      throw RobotError(path.string() + ": not a readable MRPT rawlog (" + first_line(e) + ")");
    }
    return out.take();
  });
  std::vector<RawlogStep> steps;
  config::BytesReader in(bytes);
  while (!in.done()) {
    RawlogStep step;
    step.timestamp_s = in.get<double>();
    const bool has_odometry = in.get<std::uint8_t>() != 0;
    const auto odometry = in.get<Pose2D>();
    if (has_odometry) step.odometry_increment = odometry;
    step.scan = get_scan(in);
    check_step(path, steps.size(), step);
    steps.push_back(std::move(step));
  }
  if (steps.empty()) throw RobotError(path.string() + ": the rawlog holds no 2-D laser scans");
  return steps;
}

void write_rawlog(const std::filesystem::path& path, const std::vector<RawlogStep>& steps) {
  mrpt::io::CFileGZOutputStream out;
  if (!out.open(path.string())) throw RobotError(path.string() + ": cannot write the rawlog");
  auto archive = mrpt::serialization::archiveFrom(out);
  for (const RawlogStep& step : steps) {
    archive << *odometry_action(step.odometry_increment.value_or(Pose2D{}), step.timestamp_s);
    mrpt::obs::CSensoryFrame frame;
    frame.insert(detail::to_mrpt(step.scan));
    archive << frame;
  }
}

SlamResult build_map(const std::vector<RawlogStep>& steps, const std::optional<std::filesystem::path>& ini,
                     const std::filesystem::path& out_dir, const std::function<bool()>& stop_requested, bool verbose,
                     const Pose2D& start) {
  const auto t0 = Clock::now();
  std::filesystem::path final_dir = out_dir.lexically_normal();
  if (!final_dir.has_filename()) final_dir = final_dir.parent_path();  // "map/" names the folder "map"
  try {
    config::check_replaceable_folder(final_dir, map_folder_files());
  } catch (const config::OutputError& e) {
    throw RobotError(e.what());
  }
  mrpt::slam::CMetricMapBuilderICP builder;
  // MRPT logs to stdout, where our results go: its lines go to stderr, and only with --verbose.
  builder.logging_enable_console_output = false;
  builder.setVerbosityLevel(verbose ? mrpt::system::LVL_INFO : mrpt::system::LVL_ERROR);
  if (verbose)
    builder.logRegisterCallback([](std::string_view msg, mrpt::system::VerbosityLevel, std::string_view logger, auto) {
      std::cerr << "[MRPT " << logger << "] " << msg << (msg.empty() || msg.back() != '\n' ? "\n" : "");
    });
  try {
    if (ini) {
      check_icp_slam_config(*ini);
      mrpt::config::CConfigFile file(ini->string());
      builder.ICP_options.loadFromConfigFile(file, "MappingApplication");
      builder.ICP_params.loadFromConfigFile(file, "ICP");
    } else {
      mrpt::config::CConfigFileMemory file(detail::kDefaultIcpSlamIni);
      builder.ICP_options.loadFromConfigFile(file, "MappingApplication");
      builder.ICP_params.loadFromConfigFile(file, "ICP");
    }
  } catch (const RobotError&) {
    throw;
  } catch (const std::exception& e) {
    throw RobotError((ini ? ini->string() : std::string("default icp-slam config")) + ": " + first_line(e));
  }
  // The first pose at the origin, the map moved to `start` afterwards: given an initial pose instead,
  // MRPT 2.5.x's builder stopped following the rawlog's odometry (one keyframe for the whole run).
  builder.initialize();

  SlamResult result;
  try {  // an MRPT exception is one line naming the config, never its banner and call stack
    for (const RawlogStep& step : steps) {
      if (stop_requested && stop_requested()) {
        result.interrupted = true;
        break;
      }
      mrpt::obs::CSensoryFrame frame;
      frame.insert(detail::to_mrpt(step.scan));
      builder.processActionObservation(*odometry_action(step.odometry_increment.value_or(Pose2D{}), step.timestamp_s), frame);
      const Pose2D mapped = detail::from_mrpt(builder.getCurrentPoseEstimation()->getMeanVal());
      result.trajectory.push_back({step.timestamp_s, compose(start, mapped)});
    }
  } catch (const std::exception& e) {
    throw RobotError((ini ? ini->string() : std::string("default icp-slam config")) + ": MRPT's ICP-SLAM failed at scan " +
                     std::to_string(result.trajectory.size() + 1) + ": " + first_line(e));
  }
  mrpt::maps::CSimpleMap keyframes;
  builder.getCurrentlyBuiltMap(keyframes);
  const mrpt::poses::CPose3D T_map_first(detail::to_mrpt(start));  // the map moved to the frame of `start`
  for (std::size_t i = 0; i < keyframes.size(); ++i) {
    mrpt::poses::CPose3DPDF::Ptr pose;
    mrpt::obs::CSensoryFrame::Ptr frame;
    keyframes.get(i, pose, frame);
    pose->changeCoordinatesReference(T_map_first);
  }
  result.keyframes = keyframes.size();

  // The map is written whole into a folder beside out_dir, then swapped in: an old map stays usable
  // until the new one is complete, and a failed write leaves it untouched.
  if (result.trajectory.empty()) return result;  // stopped before the first scan: nothing to write
  const std::filesystem::path work_dir = final_dir.string() + ".tmp-" + std::to_string(::getpid());
  std::error_code ec;
  std::filesystem::remove_all(work_dir, ec);
  std::filesystem::create_directories(work_dir, ec);
  if (ec) throw RobotError(work_dir.string() + ": cannot create the map directory (" + ec.message() + ")");
  write_map_files(work_dir, keyframes);
  swap_into_place(work_dir, final_dir);
  result.seconds = ms_since(t0) / 1000.0;
  return result;
}

struct Localizer::Impl {
  LocalizerConfig config;
  mrpt::maps::CSimplePointsMap map;
  mrpt::slam::CICP icp;
  Pose2D pose;

  explicit Impl(const LocalizerConfig& c) : config(c) {
    map.insertionOptions.minDistBetweenLaserPoints = 0.02f;
    map.insertionOptions.isPlanarMap = true;
    auto& p = icp.options;
    p.ICP_algorithm = mrpt::slam::icpClassic;
    p.maxIterations = c.max_iterations;
    p.thresholdDist = c.icp_threshold_m;
    p.thresholdAng = mrpt::DEG2RAD(5.0);
    p.ALFA = 0.5;
    p.smallestThresholdDist = c.icp_smallest_threshold_m;
    p.onlyUniqueRobust = false;
    p.doRANSAC = false;
  }
};

Localizer::Localizer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Localizer::Localizer(Localizer&&) noexcept = default;
Localizer& Localizer::operator=(Localizer&&) noexcept = default;
Localizer::~Localizer() = default;

Localizer::Localizer(const std::vector<std::pair<Pose2D, LaserScan>>& keyframes, const LocalizerConfig& config)
    : impl_(std::make_unique<Impl>(config)) {
  for (const auto& [pose, scan] : keyframes)
    impl_->map.insertObservation(*detail::to_mrpt(scan), mrpt::poses::CPose3D(detail::to_mrpt(pose)));
  if (impl_->map.size() < 10) throw RobotError("localiser: the map has fewer than 10 points");
}

Localizer Localizer::load(const std::filesystem::path& map_dir, const LocalizerConfig& config) {
  const auto file = map_dir / "map.simplemap.gz";
  if (const std::string kind = config::input_file_problem(file); !kind.empty())
    throw RobotError(file.string() +
                     (kind == "does not exist" ? std::string(": no such map (run projbot slam first)") : ": " + kind));
  // MRPT's deserialiser crashes on corrupt archives: the child reads the keyframes and builds the
  // points map; its points come back.
  const std::string bytes = read_isolated(file, {"MRPT simplemap", "MRPT's reader"}, [&](config::ReadProgress&) {
    mrpt::maps::CSimpleMap keyframes;
    bool ok = false;
    try {
      ok = keyframes.loadFromFile(file.string());
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok || keyframes.empty()) throw RobotError(file.string() + ": not a readable MRPT simplemap");
    Impl built(config);
    built.map.loadFromSimpleMap(keyframes);
    std::vector<float> xyz;
    xyz.reserve(3 * built.map.size());
    for (std::size_t i = 0; i < built.map.size(); ++i) {
      float x, y, z;
      built.map.getPoint(i, x, y, z);
      xyz.insert(xyz.end(), {x, y, z});
    }
    config::Bytes out;
    out.put_vector(xyz);
    return out.take();
  });
  config::BytesReader in(bytes);
  const auto xyz = in.get_vector<float>();
  auto impl = std::make_unique<Impl>(config);
  impl->map.reserve(xyz.size() / 3);
  for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) {
    if (!std::isfinite(xyz[i] + xyz[i + 1] + xyz[i + 2]))
      throw RobotError(file.string() + ": corrupt MRPT simplemap: point " + std::to_string(i / 3 + 1) + " is not finite");
    impl->map.insertPoint(xyz[i], xyz[i + 1], xyz[i + 2]);
  }
  if (impl->map.size() < 10) throw RobotError(file.string() + ": the map has fewer than 10 points");
  return Localizer(std::move(impl));
}

void Localizer::reset(const Pose2D& p) { impl_->pose = p; }
void Localizer::predict(const Pose2D& inc) { impl_->pose = compose(impl_->pose, inc); }
const Pose2D& Localizer::pose() const { return impl_->pose; }
std::size_t Localizer::map_points() const { return impl_->map.size(); }

LocalizationUpdate Localizer::correct(const LaserScan& scan) {
  const auto t0 = Clock::now();
  LocalizationUpdate u;
  u.pose = impl_->pose;
  mrpt::maps::CSimplePointsMap points;
  points.insertionOptions.minDistBetweenLaserPoints = 0.0f;
  points.insertObservation(*detail::to_mrpt(scan));
  if (points.size() < 10) {
    u.time_ms = ms_since(t0);
    return u;
  }
  mrpt::slam::CICP::TReturnInfo info;
  const auto pdf = impl_->icp.Align(&impl_->map, &points, detail::to_mrpt(impl_->pose), info);
  u.goodness = info.goodness;
  u.iterations = info.nIterations;
  const Pose2D found = detail::from_mrpt(pdf->getMeanVal());
  if (info.goodness >= impl_->config.min_goodness && distance_m(found, impl_->pose) <= impl_->config.max_correction_m) {
    impl_->pose = found;
    u.pose = found;
    u.accepted = true;
  }
  u.time_ms = ms_since(t0);
  return u;
}

}  // namespace projbot::robot
