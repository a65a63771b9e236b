#include "drape/core/line_stream.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape {
namespace {

constexpr std::string_view kTcp = "tcp://";

int connectTcp(const std::string& source) {
  const std::string address(std::string_view(source).substr(kTcp.size()));
  const std::size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == address.size())
    throw Error(fmt::format("{}: expected tcp://HOST:PORT", source));
  std::string host = address.substr(0, colon);
  const std::string port = address.substr(colon + 1);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host.c_str(), port.c_str(), &hints, &found); rc != 0)
    throw Error(fmt::format("{}: cannot find the host ({})", source, ::gai_strerror(rc)), ExitCode::Unavailable);
  std::string why = "no address";
  int fd = -1;
  for (const addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      why = std::strerror(errno);
      continue;
    }
    if (::connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      why = std::strerror(errno);
      ::close(fd);
      fd = -1;
    }
  }
  ::freeaddrinfo(found);
  if (fd < 0) throw Error(fmt::format("{}: cannot connect ({})", source, why), ExitCode::Unavailable);
  return fd;
}

}  // namespace

LineStream LineStream::open(const std::string& source) {
  if (source == "-") return LineStream(STDIN_FILENO, false, "stdin");
  if (source.starts_with(kTcp)) {
    LineStream s(connectTcp(source), true, source);
    s.tcp_ = true;
    return s;
  }
  std::error_code ec;
  if (!std::filesystem::exists(source, ec)) throw Error(fmt::format("{}: no such file", source));
  if (std::filesystem::is_directory(source, ec)) throw Error(fmt::format("{}: is a directory, not a stream", source));
  // Non-blocking open: a named pipe with no writer yet opens at once (its reader then waits
  // in next(), saying so) rather than blocking here.
  const int fd = ::open(source.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw Error(fmt::format("{}: cannot open ({})", source, std::strerror(errno)));
  return LineStream(fd, true, source);
}

LineStream::LineStream(LineStream&& other) noexcept { *this = std::move(other); }

LineStream& LineStream::operator=(LineStream&& other) noexcept {
  if (this == &other) return *this;
  if (owned_ && fd_ >= 0) ::close(fd_);
  fd_ = std::exchange(other.fd_, -1);
  owned_ = std::exchange(other.owned_, false);
  closed_ = other.closed_;
  tcp_ = other.tcp_;
  name_ = std::move(other.name_);
  buffer_ = std::move(other.buffer_);
  scanned_ = other.scanned_;
  line_ = other.line_;
  endReason_ = std::move(other.endReason_);
  return *this;
}

LineStream::~LineStream() {
  if (owned_ && fd_ >= 0) ::close(fd_);
}

bool LineStream::takeLine(std::string& line) {
  const std::size_t end = buffer_.find('\n', scanned_);
  if (end == std::string::npos) {
    scanned_ = buffer_.size();
    if (buffer_.size() > kMaxLine)
      throw Error(fmt::format("{}:{}: a line longer than {} bytes", name_, line_ + 1, kMaxLine));
    if (!closed_ || buffer_.empty()) return false;
    line.assign(buffer_);  // the last line, without its newline
    buffer_.clear();
  } else {
    if (end > kMaxLine) throw Error(fmt::format("{}:{}: a line longer than {} bytes", name_, line_ + 1, kMaxLine));
    line.assign(buffer_, 0, end);
    buffer_.erase(0, end + 1);
  }
  scanned_ = 0;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  ++line_;
  return true;
}

LineStream::Status LineStream::next(std::string& line, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    if (takeLine(line)) return Status::Line;
    if (closed_) return Status::Ended;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd p{fd_, POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(0, left.count())));
    if (ready < 0 && errno != EINTR) {
      endReason_ = std::strerror(errno);
      closed_ = true;
      continue;
    }
    if (ready <= 0) {
      if (std::chrono::steady_clock::now() >= deadline) return Status::Waiting;
      continue;  // a signal: look again
    }
    char chunk[65536];
    const ssize_t got = ::read(fd_, chunk, sizeof chunk);
    if (got > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(got));
      // Acknowledge at once, every time (Linux resets it): a sender that batches small
      // writes (Nagle's algorithm, on unless a program turns it off) waits for the previous
      // write's acknowledgement, which a delayed one holds back up to 40 ms, over a frame.
      if (tcp_) {
        const int on = 1;
        ::setsockopt(fd_, IPPROTO_TCP, TCP_QUICKACK, &on, sizeof on);
      }
    } else if (got == 0) {
      // A named pipe whose writer has not come yet reads as closed too; it has not ended
      // until someone wrote to it, so wait for a writer.
      struct stat st{};
      if (line_ == 0 && buffer_.empty() && ::fstat(fd_, &st) == 0 && S_ISFIFO(st.st_mode) && owned_) {
        if (std::chrono::steady_clock::now() >= deadline) return Status::Waiting;
        ::usleep(20'000);
        continue;
      }
      closed_ = true;
    } else if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      endReason_ = errno == ECONNRESET ? "the connection was reset" : std::strerror(errno);
      closed_ = true;
    }
  }
}

}  // namespace drape
