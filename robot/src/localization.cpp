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
#include <mrpt/poses/CPosePDFGaussian.h>
#include <mrpt/serialization/CArchive.h>
#include <mrpt/serialization/CSerializable.h>
#include <mrpt/slam/CICP.h>
#include <mrpt/slam/CMetricMapBuilderICP.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "mrpt_convert.hpp"
#include "projbot/config/output_file.hpp"

namespace projbot::robot {
namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// MRPT's icp-slam_demo_classic.ini, the settings its demo uses for a 2-D laser in a building.
constexpr const char* kDefaultIcpSlamIni = R"ini(
[MappingApplication]
localizationLinDistance = 0.2
localizationAngDistance = 5
insertionLinDistance = 1.2
insertionAngDistance = 45.0
minICPgoodnessToAccept = 0.40
matchAgainstTheGrid = 0
occupancyGrid_count = 0
gasGrid_count = 0
beaconMap_count = 0
pointsMap_count = 1
likelihoodMapSelection = -1
[MappingApplication_pointsMap_00_insertOpts]
minDistBetweenLaserPoints = 0.05
fuseWithExisting = false
isPlanarMap = 1
[ICP]
maxIterations = 80
minAbsStep_trans = 1e-6
minAbsStep_rot = 1e-6
thresholdDist = 0.3
thresholdAng_DEG = 5
ALFA = 0.8
smallestThresholdDist = 0.05
onlyClosestCorrespondences = true
onlyUniqueRobust = true
ICP_algorithm = icpClassic
corresponding_points_decimation = 5
)ini";

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

std::vector<RawlogStep> read_rawlog(const std::filesystem::path& path) {
  if (!std::filesystem::is_regular_file(path)) throw RobotError(path.string() + ": no such rawlog file");
  std::vector<RawlogStep> steps;
  try {
    mrpt::io::CFileGZInputStream in(path.string());
    auto archive = mrpt::serialization::archiveFrom(in);
    std::optional<Pose2D> pending_odometry;             // action-observation format
    std::optional<mrpt::poses::CPose2D> last_absolute;  // observation-only format
    // Object by object (not CRawlog's pair reader, which drops a sensory frame that comes before
    // the first action) until the end of the file.
    for (;;) {
      mrpt::serialization::CSerializable::Ptr object;
      try {
        object = archive.ReadObject();
      } catch (const mrpt::serialization::CExceptionEOF&) {
        break;
      }
      mrpt::obs::CObservation2DRangeScan::Ptr scan;
      if (auto actions = std::dynamic_pointer_cast<mrpt::obs::CActionCollection>(object)) {
        if (auto move = actions->getBestMovementEstimation())
          pending_odometry = detail::from_mrpt(move->poseChange->getMeanVal());
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
  } catch (const std::exception& e) {
    throw RobotError(path.string() + ": not a readable MRPT rawlog (" + first_line(e) + ")");
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

void write_trajectory(const std::filesystem::path& path, const std::vector<TrajectoryPoint>& trajectory) {
  std::ostringstream out;
  out << std::fixed;
  for (const auto& p : trajectory)
    out << std::setprecision(6) << p.timestamp_s << ' ' << std::setprecision(5) << p.pose.x_m << ' ' << p.pose.y_m << ' '
        << p.pose.theta_rad << '\n';
  config::write_file_atomically(path, out.str());
}

std::vector<TrajectoryPoint> read_trajectory(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw RobotError(path.string() + ": cannot open the trajectory file");
  std::vector<TrajectoryPoint> out;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[line.find_first_not_of(" \t")] == '#') continue;
    std::istringstream fields(line);
    TrajectoryPoint p;
    std::string extra;
    if (!(fields >> p.timestamp_s >> p.pose.x_m >> p.pose.y_m >> p.pose.theta_rad) || (fields >> extra) ||
        !std::isfinite(p.timestamp_s + p.pose.x_m + p.pose.y_m + p.pose.theta_rad))
      throw RobotError(path.string() + ":" + std::to_string(number) + ": expected 'timestamp x y phi' (4 finite numbers)");
    out.push_back(p);
  }
  if (out.empty()) throw RobotError(path.string() + ": no trajectory lines");
  return out;
}

SlamResult build_map(const std::vector<RawlogStep>& steps, const std::optional<std::filesystem::path>& ini,
                     const std::filesystem::path& out_dir, const std::function<bool()>& stop_requested) {
  const auto t0 = Clock::now();
  mrpt::slam::CMetricMapBuilderICP builder;
  builder.setVerbosityLevel(mrpt::system::LVL_ERROR);
  try {
    if (ini) {
      if (!std::filesystem::is_regular_file(*ini)) throw RobotError(ini->string() + ": no such icp-slam config");
      mrpt::config::CConfigFile file(ini->string());
      if (!file.sectionExists("MappingApplication") || !file.sectionExists("ICP"))
        throw RobotError(ini->string() + ": an icp-slam config needs [MappingApplication] and [ICP] sections");
      builder.ICP_options.loadFromConfigFile(file, "MappingApplication");
      builder.ICP_params.loadFromConfigFile(file, "ICP");
    } else {
      mrpt::config::CConfigFileMemory file(kDefaultIcpSlamIni);
      builder.ICP_options.loadFromConfigFile(file, "MappingApplication");
      builder.ICP_params.loadFromConfigFile(file, "ICP");
    }
  } catch (const RobotError&) {
    throw;
  } catch (const std::exception& e) {
    throw RobotError((ini ? ini->string() : std::string("default icp-slam config")) + ": " + first_line(e));
  }
  builder.initialize();

  SlamResult result;
  for (const RawlogStep& step : steps) {
    if (stop_requested && stop_requested()) {
      result.interrupted = true;
      break;
    }
    mrpt::obs::CSensoryFrame frame;
    frame.insert(detail::to_mrpt(step.scan));
    builder.processActionObservation(*odometry_action(step.odometry_increment.value_or(Pose2D{}), step.timestamp_s), frame);
    result.trajectory.push_back({step.timestamp_s, detail::from_mrpt(builder.getCurrentPoseEstimation()->getMeanVal())});
  }
  mrpt::maps::CSimpleMap keyframes;
  builder.getCurrentlyBuiltMap(keyframes);
  result.keyframes = keyframes.size();

  // The map is written whole into a folder beside out_dir, then swapped in: an old map stays usable
  // until the new one is complete, and a failed write leaves it untouched.
  std::filesystem::path final_dir = out_dir.lexically_normal();
  if (!final_dir.has_filename()) final_dir = final_dir.parent_path();  // "map/" names the folder "map"
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
  if (!std::filesystem::is_regular_file(file)) throw RobotError(file.string() + ": no such map (run projbot slam first)");
  mrpt::maps::CSimpleMap keyframes;
  bool ok = false;
  try {
    ok = keyframes.loadFromFile(file.string());
  } catch (const std::exception&) {
    ok = false;
  }
  if (!ok || keyframes.empty()) throw RobotError(file.string() + ": not a readable MRPT simplemap");
  auto impl = std::make_unique<Impl>(config);
  impl->map.loadFromSimpleMap(keyframes);
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
