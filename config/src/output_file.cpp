#include "projbot/config/output_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <string>

#include "projbot/config/write_all.hpp"

namespace projbot::config {

namespace {

std::string reason(int err) { return std::strerror(err); }

std::filesystem::path temporary_beside(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  // Appended piece by piece: GCC 12 at -O3 warns -Wrestrict on `"." + std::string` (its bug 105329).
  std::string name(1, '.');
  name.append(path.filename().string()).append(".tmp-").append(std::to_string(::getpid()));
  name.append("-").append(std::to_string(counter++));
  return path.parent_path() / name;
}

// `in` to its end into `out`, through short reads and writes and EINTR: 0, -errno of a failed read, or
// the errno of a failed write.
int copy_bytes(int in, int out) {
  char buf[1 << 16];
  for (;;) {
    const ssize_t n = read_retrying(in, buf, sizeof buf);
    if (n == 0) return 0;
    if (n < 0) return -errno;
    if (const int err = write_all(out, buf, static_cast<std::size_t>(n)); err != 0) return err;
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t size) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)) {
    if (std::filesystem::is_directory(st)) throw OutputError(path.string() + ": cannot write: it is a folder");
    const int fd = open_retrying(path.c_str(), O_WRONLY | O_CLOEXEC);  // a device or FIFO: in place
    if (fd < 0) throw OutputError(path.string() + ": cannot write: " + reason(errno));
    const int err = write_all(fd, data, size);
    const int close_err = ::close(fd) == 0 ? 0 : errno;
    if (err != 0 || close_err != 0) throw OutputError(path.string() + ": cannot write: " + reason(err != 0 ? err : close_err));
    return;
  }
  const std::filesystem::path tmp = temporary_beside(path);
  const int fd = open_retrying(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0)
    throw OutputError(path.string() + ": cannot write: " + reason(errno) + " (does the folder exist and is it writable?)");
  int err = write_all(fd, data, size);
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && std::rename(tmp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    throw OutputError(path.string() + ": cannot write: " + reason(err) + " (the previous file, if any, is unchanged)");
  }
}

void copy_file(const std::filesystem::path& from, const std::filesystem::path& to) {
  // Only a regular file (or none) is replaced, and only what this call wrote is removed on failure:
  // a device named as the copy (/dev/full) is refused, never unlinked.
  std::error_code ec;
  const auto st = std::filesystem::symlink_status(to, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw OutputError(to.string() + ": cannot write the copy of " + from.string() + " there: it is not a regular file");
  const int in = open_retrying(from.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) throw OutputError(from.string() + ": cannot copy it: " + reason(errno));
  const int out = open_retrying(to.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (out < 0) {
    const int err = errno;
    ::close(in);
    throw OutputError(to.string() + ": cannot write the copy of " + from.string() + ": " + reason(err));
  }
  const int err = copy_bytes(in, out);
  ::close(in);
  const int close_err = ::close(out) == 0 ? 0 : errno;
  if (err == 0 && close_err == 0) return;
  ::unlink(to.c_str());
  throw OutputError(err < 0 ? from.string() + ": cannot copy it: " + reason(-err)
                            : to.string() + ": cannot write the copy of " + from.string() + ": " +
                                  reason(err != 0 ? err : close_err));
}

void check_folder_writable(const std::filesystem::path& folder) {
  // access(W_OK) says yes to root everywhere, /proc included: only creating a file there tells.
  const std::filesystem::path probe = folder / (".projbot-probe-" + std::to_string(::getpid()));
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    // /proc and /sys answer "No such file or directory" for a new name in a folder that exists.
    const int err = errno;
    std::error_code ec;
    const std::string why = err == ENOENT && std::filesystem::is_directory(folder, ec) ? "it takes no new files" : reason(err);
    throw OutputError("the folder " + folder.string() + " is not writable (" + why + ")");
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

void check_writable(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw OutputError(path.string() + ": is a folder, not a file to write");
  // A device or FIFO (/dev/stdout) is written in place, not beside.
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) return;
  const std::filesystem::path folder = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  if (!std::filesystem::is_directory(folder, ec))
    throw OutputError(path.string() + ": the folder " + folder.string() + " does not exist");
  try {
    check_folder_writable(folder);
  } catch (const OutputError& e) {
    throw OutputError(path.string() + ": " + e.what());
  }
}

std::string file_stem(std::string name) {
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  return name;
}

}  // namespace projbot::config
