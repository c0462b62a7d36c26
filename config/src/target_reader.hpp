#pragma once
// The scene reader's part that reads what a target carries besides its pose and model
// (config/src/target_reader.cpp): its surface, its content and its motion scripts.

#include <optional>

#include "map_reader.hpp"

namespace projbot::config {

/// A target's `surface: {albedo: [r, g, b]}` (linear reflectance, each 0..1); the default where absent.
TargetSurface read_surface(MapReader& target, const std::string& path, const std::filesystem::path& base);
/// A target's `content: {video, material, loop, start, timeline}`; none where absent. Files beside `base`.
std::optional<TargetContent> read_content(MapReader& target, const std::string& path, const std::filesystem::path& base);
/// One of a target's `motions:` (visit, start_s, duration_s, translation, rpy_deg, profile, stays, removed).
TargetMotion read_motion(const YAML::Node& motion, const std::string& path, const std::string& file);

}  // namespace projbot::config
