#include "x11_screenshot.hpp"

#include <X11/Xlib.h>
#include <X11/Xutil.h>

namespace projbot::testing {

X11Display::X11Display() : display_(XOpenDisplay(nullptr)) {}
X11Display::~X11Display() {
  if (display_ != nullptr) XCloseDisplay(static_cast<Display*>(display_));
}

assets::Image X11Display::screenshot(std::uint64_t window, int width, int height) {
  auto* display = static_cast<Display*>(display_);
  XSync(display, False);
  XImage* x = XGetImage(display, static_cast<Window>(window), 0, 0, static_cast<unsigned>(width), static_cast<unsigned>(height),
                        AllPlanes, ZPixmap);
  assets::Image out;
  if (x == nullptr) return out;
  out.width = width;
  out.height = height;
  out.rgba.resize(static_cast<std::size_t>(width) * height * 4);
  const auto channel = [](unsigned long pixel, unsigned long mask) {
    int shift = 0;
    while (mask != 0 && (mask & 1UL) == 0) mask >>= 1, ++shift;
    return static_cast<std::uint8_t>((pixel >> shift) & 0xFF);
  };
  for (int y = 0; y < height; ++y)
    for (int xx = 0; xx < width; ++xx) {
      const unsigned long p = XGetPixel(x, xx, y);
      auto* o = out.pixel(xx, y);
      o[0] = channel(p, x->red_mask);
      o[1] = channel(p, x->green_mask);
      o[2] = channel(p, x->blue_mask);
      o[3] = 255;
    }
  XDestroyImage(x);
  return out;
}

std::uint64_t X11Display::root_window() const { return DefaultRootWindow(static_cast<Display*>(display_)); }
int X11Display::screen_width() const {
  return DisplayWidth(static_cast<Display*>(display_), DefaultScreen(static_cast<Display*>(display_)));
}
int X11Display::screen_height() const {
  return DisplayHeight(static_cast<Display*>(display_), DefaultScreen(static_cast<Display*>(display_)));
}

void X11Display::resize(std::uint64_t window, int width, int height) {
  auto* display = static_cast<Display*>(display_);
  XResizeWindow(display, static_cast<Window>(window), static_cast<unsigned>(width), static_cast<unsigned>(height));
  XSync(display, False);
}

}  // namespace projbot::testing
