// The portable build (tools/bundle.sh, PROJBOT_PORTABLE) leaves MRPT out: its closure (OpenCV, GDAL, Qt,
// ...) is 350 MiB, more than a folder that travels can hold. Everything MRPT does here (the occupancy grid
// and its simulated scans, localisation and mapping, rawlogs, the real laser and pan-tilt drivers) then
// throws RobotError saying so; the rest of the robot module (bases, odometry, ROS 2, the emulators) is the
// same code as in the full build.
#include "projbot/robot/localization.hpp"
#include "projbot/robot/mrpt_laser.hpp"
#include "projbot/robot/ptu_d46.hpp"

namespace projbot::robot {
namespace {

[[noreturn]] void left_out(const std::string& what) {
  throw RobotError(what + " needs MRPT, which this portable build leaves out (tools/bundle.sh): use the full build");
}

}  // namespace

bool built_with_mrpt() { return false; }

struct OccupancyMap::Impl {};
OccupancyMap::OccupancyMap(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OccupancyMap::OccupancyMap(const OccupancyMap& other) : impl_(std::make_unique<Impl>(*other.impl_)) {}
OccupancyMap& OccupancyMap::operator=(const OccupancyMap& other) {
  if (this != &other) impl_ = std::make_unique<Impl>(*other.impl_);
  return *this;
}
OccupancyMap::~OccupancyMap() = default;
OccupancyMap OccupancyMap::from_room(const config::Room&) { left_out("the room's occupancy grid (the simulated laser)"); }
void OccupancyMap::save_png(const std::filesystem::path&) const { left_out("an occupancy grid"); }
bool OccupancyMap::is_free(double, double) const { left_out("an occupancy grid"); }
LaserScan OccupancyMap::simulate_scan(const Pose2D&, const LaserConfig&, std::mt19937_64&) const {
  left_out("the simulated laser");
}

struct Localizer::Impl {};
Localizer::Localizer(const std::vector<std::pair<Pose2D, LaserScan>>&, const LocalizerConfig&) { left_out("laser localisation"); }
Localizer::Localizer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Localizer Localizer::load(const std::filesystem::path& map_dir, const LocalizerConfig&) {
  left_out("the map " + map_dir.string() + " (laser localisation)");
}
Localizer::Localizer(Localizer&&) noexcept = default;
Localizer& Localizer::operator=(Localizer&&) noexcept = default;
Localizer::~Localizer() = default;
void Localizer::reset(const Pose2D&) { left_out("laser localisation"); }
void Localizer::predict(const Pose2D&) { left_out("laser localisation"); }
LocalizationUpdate Localizer::correct(const LaserScan&) { left_out("laser localisation"); }
const Pose2D& Localizer::pose() const { left_out("laser localisation"); }
std::size_t Localizer::map_points() const { left_out("laser localisation"); }

std::vector<RawlogStep> read_rawlog(const std::filesystem::path& path) { left_out("the rawlog " + path.string()); }
void write_rawlog(const std::filesystem::path& path, const std::vector<RawlogStep>&) { left_out("the rawlog " + path.string()); }
std::vector<std::string> check_icp_slam_config(const std::filesystem::path& ini) {
  left_out("the icp-slam configuration " + ini.string());
}
SlamResult build_map(const std::vector<RawlogStep>&, const std::optional<std::filesystem::path>&, const std::filesystem::path&,
                     const std::function<bool()>&, bool, const Pose2D&) {
  left_out("mapping (ICP-SLAM)");
}

struct MrptLaser::Impl {};
MrptLaser::MrptLaser(const std::string& class_name, const std::map<std::string, std::string>&) {
  left_out("the laser driver " + class_name);
}
MrptLaser::~MrptLaser() = default;
LaserScan MrptLaser::next(double) { left_out("the laser driver"); }

struct PtuD46::Impl {};
PtuD46::PtuD46(const std::string& port) { left_out("the PTU-D46 driver (" + port + ")"); }
PtuD46::~PtuD46() = default;
PanTiltStatus PtuD46::move_to(const PanTiltAngles&) { left_out("the PTU-D46 driver"); }
PanTiltStatus PtuD46::position(PanTiltAngles&) { left_out("the PTU-D46 driver"); }
double PtuD46::pan_step_rad() const { left_out("the PTU-D46 driver"); }
double PtuD46::tilt_step_rad() const { left_out("the PTU-D46 driver"); }

}  // namespace projbot::robot
