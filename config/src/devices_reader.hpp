#pragma once
// The scene reader's part that reads a `devices:` section (config/src/devices.cpp).

#include "map_reader.hpp"
#include "projbot/config/devices.hpp"

namespace projbot::config {

/// The `devices:` section under `root`, each device's keys checked (errors name file, line and key);
/// none configured where the section is absent or empty.
DevicesConfig read_devices(MapReader& root);

}  // namespace projbot::config
