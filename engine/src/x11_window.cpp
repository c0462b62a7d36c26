// The only translation unit that sees X11 headers: their macros (Success, None, Bool) break Eigen.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#define GLFW_EXPOSE_NATIVE_X11
#include <GLFW/glfw3native.h>

#include <cstdint>

namespace projbot::engine::detail {

std::uint64_t x11_window_of(GLFWwindow* window) { return static_cast<std::uint64_t>(glfwGetX11Window(window)); }

}  // namespace projbot::engine::detail
