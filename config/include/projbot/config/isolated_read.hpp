#pragma once
// Reading files whose third-party reader is not safe on corrupt input, in a child process: a crash there
// is an error message here. MRPT's deserialisers follow lengths and class tags they never check and die
// with SIGSEGV on a few flipped bits; PCL's PLY reader asserts (abort) on a bad face list. Not for use
// while other threads run (fork).

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace projbot::config {

/// How far the child's reader had got, kept in memory shared with the parent: a crash names it.
struct ReadProgress {
  std::uint64_t objects = 0;          ///< objects read whole
  std::uint64_t offset = UINT64_MAX;  ///< the file's byte where the next object starts, where known
};

/// A file the isolated reader could not read; the message names it. Callers pass it on as their own
/// module's error type.
class IsolatedReadError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What is read, for messages: "MRPT rawlog" read by "MRPT's reader".
struct IsolatedReader {
  std::string kind;
  std::string reader;
  std::chrono::milliseconds time_limit{0};  ///< 0: 1 s plus 5 s per MB of the file (reading takes 0.07 s per MB)
};

/// Runs `read` in a forked child and returns the bytes it produced. An exception in `read` comes back
/// as an IsolatedReadError with the same message; a child that dies (signal, out of its memory limit)
/// or spends longer than its time limit (its CPU time plus the time it lies blocked, not the wall time a
/// busy machine stretches) is killed and named with `file`, `what` and the
/// progress. The child's address space is capped at what it has plus 1 GiB plus 64 bytes per byte of
/// `file` (not under AddressSanitizer, which reserves more; the time limit holds there too).
std::string read_isolated(const std::filesystem::path& file, const IsolatedReader& what,
                          const std::function<std::string(ReadProgress&)>& read);

/// Plain values and vectors of them, appended to and taken from a byte string in host order (the bytes
/// never leave the machine: child to parent only).
class Bytes {
 public:
  template <typename T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    data_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <typename T>
  void put_vector(const std::vector<T>& v) {
    put<std::uint64_t>(v.size());
    data_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string take() { return std::move(data_); }

 private:
  std::string data_;
};

class BytesReader {
 public:
  explicit BytesReader(const std::string& data) : data_(data) {}
  bool done() const { return at_ == data_.size(); }
  template <typename T>
  T get() {
    T v{};
    need(sizeof v);
    std::memcpy(&v, data_.data() + at_, sizeof v);
    at_ += sizeof v;
    return v;
  }
  template <typename T>
  std::vector<T> get_vector() {
    const auto n = get<std::uint64_t>();
    if (n > (data_.size() - at_) / sizeof(T)) throw IsolatedReadError("isolated read: truncated result from the child");
    std::vector<T> v(n);
    if (n > 0) std::memcpy(v.data(), data_.data() + at_, n * sizeof(T));
    at_ += n * sizeof(T);
    return v;
  }

 private:
  void need(std::size_t n) const {
    if (data_.size() - at_ < n) throw IsolatedReadError("isolated read: truncated result from the child");
  }
  const std::string& data_;
  std::size_t at_ = 0;
};

}  // namespace projbot::config
