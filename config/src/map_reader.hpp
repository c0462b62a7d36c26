#pragma once
// Internal to config: reading one YAML mapping with file:line errors that name the key path, and
// rejecting keys nobody asked for. Used by the scene and recording readers.

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "projbot/config/paths.hpp"
#include "projbot/config/scene.hpp"

namespace projbot::config {

// A YAML mapping being read: knows its key path for errors and rejects keys nobody asked for.
class MapReader {
 public:
  MapReader(YAML::Node node, std::string path, const std::string& file) : node_(node), path_(std::move(path)), file_(file) {
    if (!node_.IsMap()) fail(node_, path_, "expected a mapping");
  }

  [[noreturn]] void fail(const YAML::Node& at, const std::string& key_path, const std::string& why) const {
    const YAML::Mark mark = at.Mark();
    std::ostringstream msg;
    msg << file_;
    if (mark.line >= 0) msg << ':' << mark.line + 1;
    msg << ": ";
    if (!key_path.empty()) msg << key_path << ": ";  // empty: `why` names what it is about
    msg << why;
    throw ConfigError(msg.str());
  }

  std::string key_path(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  bool has(const std::string& key) const { return static_cast<bool>(node_[key]); }

  YAML::Node child(const std::string& key, bool required) {
    used_.insert(key);
    YAML::Node n = node_[key];
    if (!n && required) fail(node_, key_path(key), "missing required key");
    return n;
  }

  template <typename T>
  T get(const std::string& key, const T& fallback, bool required = false) {
    YAML::Node n = child(key, required);
    if (!n) return fallback;
    if (!n.IsScalar()) fail(n, key_path(key), "expected a " + type_name<T>());
    try {
      T value = n.as<T>();
      if constexpr (std::is_floating_point_v<T>) {
        if (!std::isfinite(value)) fail(n, key_path(key), "must be finite");
      }
      return value;
    } catch (const YAML::Exception&) {
      fail(n, key_path(key), "expected a " + type_name<T>() + ", got '" + n.Scalar() + "'");
    }
  }

  std::vector<double> numbers(const YAML::Node& n, const std::string& key_path, std::size_t count) const {
    if (!n.IsSequence() || n.size() != count) fail(n, key_path, "expected a list of " + std::to_string(count) + " numbers");
    std::vector<double> out;
    for (const auto& item : n) {
      double v = 0.0;
      if (!item.IsScalar() || !YAML::convert<double>::decode(item, v) || !std::isfinite(v))
        fail(item, key_path, "'" + (item.IsScalar() ? item.Scalar() : std::string("<non-scalar>")) + "' is not a finite number");
      out.push_back(v);
    }
    return out;
  }

  Eigen::Vector3d vector3(const YAML::Node& n, const std::string& key_path) const {
    const auto v = numbers(n, key_path, 3);
    return {v[0], v[1], v[2]};
  }

  // Call once every known key was read: any other key is a typo the user must hear about.
  void reject_unknown() const {
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail(kv.first, path_, "a key must be a plain name, not a list or map");
      const auto key = kv.first.as<std::string>();
      if (!used_.contains(key)) fail(kv.first, key_path(key), "unknown key");
    }
  }

  const std::string& file() const { return file_; }

 private:
  template <typename T>
  static std::string type_name() {
    if constexpr (std::is_same_v<T, bool>)
      return "boolean";
    else if constexpr (std::is_integral_v<T>)
      return "integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "number";
    else
      return "string";
  }

  YAML::Node node_;
  std::string path_;
  const std::string& file_;
  std::set<std::string> used_;
};

}  // namespace projbot::config
