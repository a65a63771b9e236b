// LineStream over the real things a live source is: a pipe written in pieces, a TCP server
// that drape connects to, a named pipe whose writer comes late; lines split across writes,
// CRLF endings, a last line without its newline, a line too long, a source that is not there.

#include <gtest/gtest.h>

#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/core/line_stream.hpp"
#include "drape/testing/errors.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape {
namespace {

using namespace std::chrono_literals;

void writeAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    ASSERT_GT(n, 0);
    done += static_cast<std::size_t>(n);
  }
}

std::vector<std::string> readAll(LineStream& s) {
  std::vector<std::string> lines;
  std::string line;
  for (int waits = 0; waits < 200;) {
    const LineStream::Status status = s.next(line, 50ms);
    if (status == LineStream::Status::Ended) break;
    if (status == LineStream::Status::Waiting) {
      ++waits;
      continue;
    }
    lines.push_back(line);
  }
  return lines;
}

// The pieces of `text` written one by one with pauses, so lines arrive split.
void writeInPieces(int fd, const std::string& text, std::size_t piece) {
  for (std::size_t at = 0; at < text.size(); at += piece) {
    writeAll(fd, text.substr(at, piece));
    std::this_thread::sleep_for(2ms);
  }
  ::close(fd);
}

const std::string kText = "HIERARCHY\r\nROOT Hips\n\nFrame Time: 0.01\n1 2 3\n4 5 6";
const std::vector<std::string> kLines = {"HIERARCHY", "ROOT Hips", "", "Frame Time: 0.01", "1 2 3", "4 5 6"};

TEST(LineStream, ReadsAPipeWrittenInPiecesLineByLine) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const int saved = ::dup(STDIN_FILENO);
  ASSERT_EQ(::dup2(fds[0], STDIN_FILENO), STDIN_FILENO);
  ::close(fds[0]);
  std::thread writer(writeInPieces, fds[1], kText, 3);
  LineStream s = LineStream::open("-");
  EXPECT_EQ(s.name(), "stdin");
  EXPECT_EQ(readAll(s), kLines);
  EXPECT_EQ(s.lineNumber(), 6);
  EXPECT_TRUE(s.endReason().empty());
  writer.join();
  ::dup2(saved, STDIN_FILENO);
  ::close(saved);
}

TEST(LineStream, SaysItWaitsWhileASourceIsSilent) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const int saved = ::dup(STDIN_FILENO);
  ::dup2(fds[0], STDIN_FILENO);
  ::close(fds[0]);
  LineStream s = LineStream::open("-");
  std::string line;
  writeAll(fds[1], "half a li");
  EXPECT_EQ(s.next(line, 30ms), LineStream::Status::Waiting);
  writeAll(fds[1], "ne\n");
  EXPECT_EQ(s.next(line, 1000ms), LineStream::Status::Line);
  EXPECT_EQ(line, "half a line");
  ::close(fds[1]);
  EXPECT_EQ(s.next(line, 1000ms), LineStream::Status::Ended);
  ::dup2(saved, STDIN_FILENO);
  ::close(saved);
}

TEST(LineStream, ConnectsToATcpServerAndReadsWhatItSends) {
  const int listener = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(listener, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  socklen_t length = sizeof address;
  ASSERT_EQ(::getsockname(listener, reinterpret_cast<sockaddr*>(&address), &length), 0);
  ASSERT_EQ(::listen(listener, 1), 0);
  const std::string url = "tcp://127.0.0.1:" + std::to_string(ntohs(address.sin_port));
  std::thread server([&] {
    const int peer = ::accept(listener, nullptr, nullptr);
    writeInPieces(peer, kText, 7);
  });
  LineStream s = LineStream::open(url);
  EXPECT_EQ(s.name(), url);
  EXPECT_EQ(readAll(s), kLines);
  server.join();
  ::close(listener);
  // Nobody listens there now: an error a caller may try again.
  try {
    (void)LineStream::open(url);
    ADD_FAILURE() << "connected to a closed port";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unavailable);
    EXPECT_EQ(std::string(e.what()), url + ": cannot connect (Connection refused)");
  }
}

TEST(LineStream, ReadsANamedPipeWhoseWriterComesLater) {
  const std::string fifo = (testing::processTempDir("line-stream-fifo") / "capture").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  LineStream s = LineStream::open(fifo);  // no writer yet: opens at once
  std::string line;
  EXPECT_EQ(s.next(line, 50ms), LineStream::Status::Waiting);
  std::thread writer([&] { writeInPieces(::open(fifo.c_str(), O_WRONLY), kText, 5); });
  EXPECT_EQ(readAll(s), kLines);
  writer.join();
}

TEST(LineStream, RefusesALineTooLongAndASourceThatIsNotThere) {
  const std::string file = (testing::processTempDir("line-stream-long") / "long.bvh").string();
  {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT, 0600);
    writeAll(fd, "short\n" + std::string(LineStream::kMaxLine + 10, '7') + "\n");
    ::close(fd);
  }
  LineStream s = LineStream::open(file);
  std::string line;
  EXPECT_EQ(s.next(line, 1000ms), LineStream::Status::Line);
  EXPECT_EQ(testing::errorOf([&] { (void)s.next(line, 1000ms); }), file + ":2: a line longer than 1048576 bytes");
  EXPECT_EQ(testing::errorOf([] { (void)LineStream::open("/nonexistent/capture"); }), "/nonexistent/capture: no such file");
  EXPECT_EQ(testing::errorOf([] { (void)LineStream::open("tcp://nohost"); }), "tcp://nohost: expected tcp://HOST:PORT");
}

}  // namespace
}  // namespace drape
