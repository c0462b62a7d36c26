// The portable build (PROJBOT_PORTABLE, tools/bundle.sh) has no OpenCV, hence no calibration module: its
// commands stay in the table, so that `projbot calibrate ...` says why it is missing rather than "unknown".
#include "commands.hpp"

namespace projbot::tools {
namespace {

constexpr const char* kNeedsOpenCv = "needs OpenCV (calib3d, aruco, structured_light)";

Command left_out(const char* name) { return {name, "", "projbot " + std::string(name), {}, nullptr, kNeedsOpenCv}; }

}  // namespace

const Command kCalibrateCapture = left_out("calibrate capture");
const Command kCalibrateSimulate = left_out("calibrate simulate");
const Command kCalibrateSolve = left_out("calibrate solve");
const Command kCalibratePhotometric = left_out("calibrate photometric");

}  // namespace projbot::tools
