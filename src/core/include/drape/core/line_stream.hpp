#pragma once
// Lines of text as a live source writes them: standard input ("-"), a TCP server
// ("tcp://HOST:PORT", which drape connects to as a client, the way capture programs
// broadcast), or a file or named pipe (a path). For motion that arrives while it is
// captured (the anim-server's --live): a reader waits for each line with a timeout, so it
// can say what it waits for and stop when asked, and a source that closes ends the stream.

#include <chrono>
#include <string>

namespace drape {

class LineStream {
 public:
  /// The longest line taken; a longer one is an error naming its line.
  static constexpr std::size_t kMaxLine = std::size_t{1} << 20;

  /// Opens `source`. Throws drape::Error: "PATH: no such file" (bad input), or for TCP
  /// "tcp://HOST:PORT: cannot connect (why)" with ExitCode::Unavailable, which a caller may
  /// retry.
  [[nodiscard]] static LineStream open(const std::string& source);

  LineStream(LineStream&& other) noexcept;
  LineStream& operator=(LineStream&& other) noexcept;
  LineStream(const LineStream&) = delete;
  LineStream& operator=(const LineStream&) = delete;
  ~LineStream();

  enum class Status { Line, Waiting, Ended };
  /// The next whole line into `line` (without its "\n" or "\r\n"): Line. Waiting when none
  /// came within `timeout`; Ended once the source has closed and every line is taken (a last
  /// line without its newline is still a line). Throws drape::Error at a line longer than
  /// kMaxLine.
  Status next(std::string& line, std::chrono::milliseconds timeout);

  /// "stdin", "tcp://HOST:PORT" or the path: what messages call the source.
  [[nodiscard]] const std::string& name() const { return name_; }
  /// 1-based number of the last line next() returned.
  [[nodiscard]] int lineNumber() const { return line_; }
  /// Why the source ended, when it was not a plain close ("the connection was reset"); empty otherwise.
  [[nodiscard]] const std::string& endReason() const { return endReason_; }

 private:
  LineStream(int fd, bool owned, std::string name) : fd_(fd), owned_(owned), name_(std::move(name)) {}
  bool takeLine(std::string& line);

  int fd_ = -1;
  bool owned_ = false;
  bool closed_ = false;
  bool tcp_ = false;
  std::string name_;
  std::string buffer_;
  std::size_t scanned_ = 0;  ///< bytes of buffer_ known to hold no newline
  int line_ = 0;
  std::string endReason_;
};

}  // namespace drape
