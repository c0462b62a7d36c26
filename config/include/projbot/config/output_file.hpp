#pragma once
// Outputs that never lie (every module writes through here): a file is written to a temporary beside it, checked, and renamed
// over the target, so a failed write (full disk, file size limit, missing folder) throws and leaves any previous file as it was.
// Targets that are not regular files (/dev/stdout, a FIFO) are written in place.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace projbot::config {

/// An output that could not be written: the message names the file and the reason.
class OutputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Writes `size` bytes to `path` atomically. Throws OutputError naming the file and the reason.
void write_file_atomically(const std::filesystem::path& path, const void* data, std::size_t size);
inline void write_file_atomically(const std::filesystem::path& path, std::string_view text) {
  write_file_atomically(path, text.data(), text.size());
}

/// Copies the regular file `from` to `to` (a new file or a regular one replaced, not atomically: for
/// temporary copies; anything else at `to` is refused and left alone),
/// through short reads and writes and signals (EINTR), unlike std::filesystem::copy_file. Throws
/// OutputError naming the file that failed; a partial copy is removed.
void copy_file(const std::filesystem::path& from, const std::filesystem::path& to);

/// Checks before long work that `path` can be written later: its folder exists and is writable, and it
/// is not a folder itself. Throws OutputError naming the file and what is wrong.
void check_writable(const std::filesystem::path& path);
/// Checks that files can be created in `folder` (by creating and removing one). Throws OutputError.
void check_folder_writable(const std::filesystem::path& folder);

/// A name (a target's) as part of a file's name: its characters other than letters, digits, - and _ made _.
std::string file_stem(std::string name);

}  // namespace projbot::config
