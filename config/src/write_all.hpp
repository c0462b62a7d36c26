#pragma once
// Writing a whole buffer to a file descriptor, through short writes and signals (EINTR): for the
// atomic outputs and for the isolated reader's reply to its parent.
#include <unistd.h>

#include <cerrno>
#include <cstddef>

namespace projbot::config::detail {

/// Writes all `size` bytes to `fd`; returns 0, or the errno of the first failure.
inline int write_all(int fd, const void* data, std::size_t size) {
  const auto* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return 0;
}

}  // namespace projbot::config::detail
