#include "projbot/config/isolated_read.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <new>
#include <optional>
#include <string>

#include "projbot/config/paths.hpp"
#include "projbot/config/stop_request.hpp"
#include "projbot/config/write_all.hpp"

// A fuzzer's or sanitizer's report-and-exit hook, present only in such builds.
extern "C" __attribute__((weak)) void __sanitizer_set_death_callback(void (*callback)());

namespace projbot::config {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

// The child's CPU time so far (user and system, all its threads); nothing where the system cannot tell.
std::optional<std::chrono::milliseconds> cpu_time(pid_t pid) {
  clockid_t clock{};
  timespec t{};
  if (::clock_getcpuclockid(pid, &clock) != 0 || ::clock_gettime(clock, &t) != 0) return std::nullopt;
  return std::chrono::milliseconds(static_cast<long long>(t.tv_sec) * 1000 + t.tv_nsec / 1000000);
}

// Whether the child's main thread is waiting to run or running (state R in /proc), as opposed to asleep
// or blocked; false where /proc cannot tell.
bool runnable(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return false;
  const auto name_end = line.rfind(')');  // the command name may hold spaces and parentheses
  return name_end != std::string::npos && name_end + 2 < line.size() && line[name_end + 2] == 'R';
}

// How long the child has spent on its read: its CPU time, plus the time it lay blocked, using none (a
// reader waiting forever). Not the wall time, which a busy machine stretches: a right file must not be
// called corrupt because other work held the core. Where the CPU time cannot be read, the wall time.
class ReadClock {
 public:
  explicit ReadClock(pid_t pid) : pid_(pid), last_wall_(std::chrono::steady_clock::now()), last_cpu_(cpu_time(pid)) {}

  std::chrono::milliseconds spent() {
    using namespace std::chrono;
    const auto wall = steady_clock::now();
    const auto cpu = cpu_time(pid_);
    const auto slice = duration_cast<milliseconds>(wall - last_wall_);
    const bool unknown = !cpu || !last_cpu_, idle = !unknown && *cpu - *last_cpu_ < milliseconds(1) && !runnable(pid_);
    if (unknown || idle) blocked_ += slice;  // the wall time counts where the CPU time cannot say
    last_wall_ = wall;
    if (cpu) last_cpu_ = cpu;
    return blocked_ + (last_cpu_ ? *last_cpu_ : milliseconds(0));
  }

 private:
  pid_t pid_;
  std::chrono::steady_clock::time_point last_wall_;
  std::optional<std::chrono::milliseconds> last_cpu_;
  std::chrono::milliseconds blocked_{0};
};

enum class ReadEnd { whole, late, stopped };

// Everything the child writes, until it closes the pipe, it has spent `limit` on the read (late) or a stop
// is asked of the process (stopped).
ReadEnd read_all(int fd, pid_t pid, std::chrono::milliseconds limit, std::string& out) {
  constexpr int kSliceMs = 50;  // how often the child's clock and the stop request are looked at
  ReadClock clock(pid);
  char buf[65536];
  for (;;) {
    if (clock.spent() >= limit) return ReadEnd::late;
    if (stop_requested()) return ReadEnd::stopped;
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, kSliceMs);
    if (ready < 0 && errno == EINTR) continue;
    if (ready == 0) continue;
    if (ready < 0) return ReadEnd::whole;
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return ReadEnd::whole;
    out.append(buf, static_cast<std::size_t>(n));
  }
}

// The child's memory: what it has now (the program, its libraries) plus what reading `file` may fairly
// need. A corrupt length that asks for gigabytes fails there as bad_alloc.
void limit_memory(const std::filesystem::path& file) {
  if (kAddressSanitizer) return;
  std::ifstream statm("/proc/self/statm");
  unsigned long long pages = 0;
  if (!(statm >> pages)) return;
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  const rlim_t limit = pages * static_cast<unsigned long long>(::sysconf(_SC_PAGESIZE)) + (1ULL << 30) + (ec ? 0 : 64 * size);
  const rlimit r{limit, limit};
  ::setrlimit(RLIMIT_AS, &r);
}

// The default action for `sig`, set with the system call itself: a sanitizer's sigaction interceptor may
// keep its own handler in place.
void default_action(int sig) {
  struct {
    void (*handler)(int);
    unsigned long flags;
    void (*restorer)();
    unsigned long mask;
  } action{SIG_DFL, 0, nullptr, 0};
  ::syscall(SYS_rt_sigaction, sig, &action, nullptr, sizeof(unsigned long));
}

// Child: 'R' + result, or 'E' + the message of what it threw; then _exit (no atexit handlers, no
// flushing of the parent's buffered output a second time).
[[noreturn]] void run_child(int fd, const std::filesystem::path& file, ReadProgress& progress,
                            const std::function<std::string(ReadProgress&)>& read) {
  // A fault here ends this child plainly, for the parent to report: not through a crash handler
  // inherited from the parent (a sanitizer's or a fuzzer's would report it as the parent's own).
  for (const int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) default_action(sig);
  if (&__sanitizer_set_death_callback != nullptr) __sanitizer_set_death_callback(nullptr);
  // The reader's own complaints (PCL's failed assertion, MRPT's banner) would only confuse: the parent
  // says what happened, naming the file.
  if (const int null = ::open("/dev/null", O_WRONLY); null >= 0) {
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::close(null);
  }
  limit_memory(file);
  std::string reply;
  try {
    reply = "R" + read(progress);
  } catch (const std::bad_alloc&) {
    reply = "M";
  } catch (const std::exception& e) {
    reply = std::string("E") + e.what();
  } catch (...) {
    reply = "Eunknown error";
  }
  _exit(write_all(fd, reply.data(), reply.size()) == 0 ? 0 : 3);
}

// ", after N objects, at byte B", or "" where the reader kept no count.
std::string where(const ReadProgress& p) {
  if (p.objects == 0 && p.offset == UINT64_MAX) return "";
  std::string s = ", after " + std::to_string(p.objects) + (p.objects == 1 ? " object" : " objects");
  if (p.offset != UINT64_MAX) s += ", at byte " + std::to_string(p.offset);
  return s;
}

std::string seconds(std::chrono::milliseconds t) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f", std::chrono::duration<double>(t).count());
  return text;
}

std::string how_it_died(int status) {
  if (WIFSIGNALED(status)) {
    const char* name = ::strsignal(WTERMSIG(status));
    return "signal " + std::to_string(WTERMSIG(status)) + (name != nullptr ? std::string(", ") + name : "");
  }
  return "exit " + std::to_string(WEXITSTATUS(status));
}

}  // namespace

std::string read_isolated(const std::filesystem::path& file, const IsolatedReader& what,
                          const std::function<std::string(ReadProgress&)>& read) {
  const std::string name = file.string();
  // Not opened unless a regular file: a FIFO blocks open(), /dev/zero reads to the memory cap.
  if (const std::string problem = input_file_problem(file); !problem.empty()) throw IsolatedReadError(name + ": " + problem);
  void* shared = ::mmap(nullptr, sizeof(ReadProgress), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (shared == MAP_FAILED) throw IsolatedReadError(name + ": cannot set up the isolated reader (mmap)");
  auto* progress = new (shared) ReadProgress{};
  int fds[2];
  if (::pipe(fds) != 0) {
    ::munmap(shared, sizeof(ReadProgress));
    throw IsolatedReadError(name + ": cannot set up the isolated reader (pipe)");
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  const std::chrono::milliseconds limit = what.time_limit.count() > 0
                                              ? what.time_limit
                                              : std::chrono::milliseconds(1000 + (ec ? 0 : static_cast<long long>(size / 200)));
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], file, *progress, read);
  }
  ::close(fds[1]);
  std::string reply;
  const ReadEnd end = pid < 0 ? ReadEnd::whole : read_all(fds[0], pid, limit, reply);
  const bool in_time = end == ReadEnd::whole;
  ::close(fds[0]);
  if (!in_time) ::kill(pid, SIGKILL);
  int status = 0;
  while (pid > 0 && ::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const ReadProgress at = *progress;
  ::munmap(shared, sizeof(ReadProgress));
  if (pid < 0) throw IsolatedReadError(name + ": cannot set up the isolated reader (fork)");
  if (end == ReadEnd::stopped) throw StopRequested("stopped while reading " + name);
  if (!in_time)
    throw IsolatedReadError(name + ": " + what.reader + " took longer than " + seconds(limit) + " s on it (a corrupt " +
                            what.kind + "?" + where(at) + ")");
  if (!reply.empty() && reply[0] == 'R' && WIFEXITED(status) && WEXITSTATUS(status) == 0) return reply.substr(1);
  if (!reply.empty() && reply[0] == 'E') throw IsolatedReadError(reply.substr(1));
  if (!reply.empty() && reply[0] == 'M')
    throw IsolatedReadError(name + ": out of memory reading it (a corrupt " + what.kind + "?" + where(at) + ")");
  throw IsolatedReadError(name + ": corrupt " + what.kind + ": " + what.reader + " crashed on it (" + how_it_died(status) +
                          where(at) + ")");
}

}  // namespace projbot::config
