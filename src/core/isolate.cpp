#include "drape/core/isolate.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <exception>

#include <fmt/format.h>

#include "drape/core/error.hpp"

// Address and thread sanitizers reserve terabytes of shadow address space.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define DRAPE_SHADOW_MEMORY 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define DRAPE_SHADOW_MEMORY 1
#endif
#endif

namespace drape {
namespace {

// Child -> parent message: one status byte, then the payload.
constexpr char kOk = 'K';
constexpr char kError = 'E';

bool writeAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

[[noreturn]] void runChild(int fd, const std::function<std::string()>& work,
                           const IsolationLimits& limits) {
#ifndef DRAPE_SHADOW_MEMORY
  // The address-space limit applies to builds without a sanitizer's shadow memory only.
  rlimit mem{limits.memoryBytes, limits.memoryBytes};
  ::setrlimit(RLIMIT_AS, &mem);
#endif
  const auto cpu = static_cast<rlim_t>(limits.seconds + 1.0);
  rlimit cpuLimit{cpu, cpu + 1};
  ::setrlimit(RLIMIT_CPU, &cpuLimit);
  rlimit noCore{0, 0};
  ::setrlimit(RLIMIT_CORE, &noCore);

  std::string message;
  char status = kOk;
  int exitCode = 0;
  try {
    message = work();
  } catch (const Error& e) {
    status = kError;
    message = std::string(1, static_cast<char>(e.code())) + e.what();
  } catch (const std::bad_alloc&) {
    status = kError;
    message = std::string(1, static_cast<char>(ExitCode::BadInput)) + "out of memory";
  } catch (const std::exception& e) {
    status = kError;
    message = std::string(1, static_cast<char>(ExitCode::BadInput)) + e.what();
  }
  const bool ok = writeAll(fd, &status, 1) && writeAll(fd, message.data(), message.size());
  ::close(fd);
  ::_exit(ok ? exitCode : 1);
}

}  // namespace

std::string runIsolated(const std::string& what, const std::string& readerName,
                        const std::function<std::string()>& work, const IsolationLimits& limits) {
  int fds[2];
  if (::pipe(fds) != 0) throw Error(fmt::format("{}: cannot create a pipe: {}", what, std::strerror(errno)), ExitCode::Internal);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw Error(fmt::format("{}: cannot start the {} process: {}", what, readerName, std::strerror(errno)), ExitCode::Internal);
  }
  if (pid == 0) {
    ::close(fds[0]);
    runChild(fds[1], work, limits);
  }
  ::close(fds[1]);

  // Read everything the child writes, until it closes the pipe or the time is up.
  std::string bytes;
  bool timedOut = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(limits.seconds);
  char buffer[1 << 16];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      timedOut = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r == 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (timedOut) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }

  if (timedOut) throw Error(fmt::format("{}: the {} failed (time limit of {:g} s)", what, readerName, limits.seconds));
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGXCPU || sig == SIGKILL) throw Error(fmt::format("{}: the {} failed (time limit)", what, readerName));
    throw Error(fmt::format("{}: the {} failed (signal {})", what, readerName, sig));
  }
  if (bytes.empty()) throw Error(fmt::format("{}: the {} failed (exit status {})", what, readerName, WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  if (bytes[0] == kError) {
    const auto code = bytes.size() > 1 ? static_cast<ExitCode>(bytes[1]) : ExitCode::BadInput;
    throw Error(bytes.size() > 2 ? bytes.substr(2) : std::string("unknown error"), code);
  }
  return bytes.substr(1);
}

}  // namespace drape
