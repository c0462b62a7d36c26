#pragma once
// The one error type of the config module, apart from the scene's types so that a reader of any file can
// throw it without the scene's header.

#include <stdexcept>

namespace projbot::config {

/// A bad scene or value: the message names the file, line and key path ("scene.yaml:7: projector.fx: ...").
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace projbot::config
