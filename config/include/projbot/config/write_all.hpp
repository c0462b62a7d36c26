#pragma once
// Writing a whole buffer to a file descriptor, through short writes and signals (EINTR): for the
// atomic outputs, the isolated reader's reply to its parent and the fuzz harnesses' inputs. A handler installed without
// SA_RESTART (a library's timer, a test harness's) makes open() of a FIFO and every blocking write or
// read fail with EINTR: each is tried again.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>

namespace projbot::config {

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

/// open(2), tried again while a signal interrupts it (a FIFO's open blocks until its other end opens).
inline int open_retrying(const char* path, int flags, mode_t mode = 0) {
  int fd;
  do fd = ::open(path, flags, mode);
  while (fd < 0 && errno == EINTR);
  return fd;
}

/// read(2), tried again while a signal interrupts it.
inline ssize_t read_retrying(int fd, void* buf, std::size_t size) {
  ssize_t n;
  do n = ::read(fd, buf, size);
  while (n < 0 && errno == EINTR);
  return n;
}

}  // namespace projbot::config
