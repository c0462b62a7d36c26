#pragma once
// The calibration files' YAML, read as every reader of the project reads YAML (config::load_yaml_file), its
// refusals as this module's error (calibrate-internal).

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "projbot/calibrate/calibrate.hpp"
#include "projbot/config/error.hpp"
#include "projbot/config/yaml_keys.hpp"

namespace projbot::calibrate::detail {

/// config::load_yaml_file at 1 MB, throwing CalibrationError.
inline YAML::Node load_yaml(const std::filesystem::path& path, const std::string& kind) {
  try {
    return config::load_yaml_file(path, std::uintmax_t{1} << 20, kind);
  } catch (const config::ConfigError& e) {
    throw CalibrationError(e.what());
  }
}

}  // namespace projbot::calibrate::detail
