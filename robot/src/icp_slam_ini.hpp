#pragma once
// The icp-slam .ini: MRPT's default settings and a strict check of a user's file (MRPT reads a
// non-numeric value as 0 and ignores a misspelt key).

namespace projbot::robot::detail {

/// MRPT's icp-slam_demo_classic.ini, the settings its demo uses for a 2-D laser in a building.
extern const char* const kDefaultIcpSlamIni;

}  // namespace projbot::robot::detail
