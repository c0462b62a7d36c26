#pragma once
// Xlib helpers for the window test, behind plain types: X11's macros must not meet Eigen or GoogleTest.

#include <cstdint>

#include "projbot/assets/image.hpp"

namespace projbot::testing {

class X11Display {
 public:
  X11Display();  ///< connects to $DISPLAY; ok() tells whether it worked
  ~X11Display();
  X11Display(const X11Display&) = delete;
  X11Display& operator=(const X11Display&) = delete;
  bool ok() const { return display_ != nullptr; }
  /// The window's contents as the X server holds them, RGBA (alpha 255). Empty image on failure.
  assets::Image screenshot(std::uint64_t window, int width, int height);
  /// The root window (the whole screen) and its size.
  std::uint64_t root_window() const;
  int screen_width() const;
  int screen_height() const;
  /// Resizes a window from outside, as a window manager would.
  void resize(std::uint64_t window, int width, int height);

 private:
  void* display_ = nullptr;
};

}  // namespace projbot::testing
