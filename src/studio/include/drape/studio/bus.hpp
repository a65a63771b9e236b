#pragma once
// The studio's buffer servers (the paper's section 3): NATS JetStream streams, one per
// broadcaster. A broadcaster named NAME publishes its takes on the subject `drape.NAME`
// into the stream `DRAPE_NAME` (file storage: a server restarted on the same store keeps
// them); each reader is a pull consumer of that stream that starts at a sequence of its
// choosing and reads at its own rate, so a reader may join late or replay. The NATS C
// client (libnats) does the protocol: this is ownership, naming and errors that say what
// to do.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace drape::studio {

/// A stream's message as read: its bytes and its place in the stream.
struct Received {
  std::vector<std::uint8_t> data;
  std::uint64_t sequence = 0;
  std::int64_t time_ns = 0;  ///< when the stream stored it: ns since 1970, the server's clock
};

/// First and last sequence of a broadcaster's stream (both 0 when it holds nothing).
struct StreamRange {
  bool exists = false;
  std::uint64_t first = 0;
  std::uint64_t last = 0;
  std::uint64_t messages = 0;
};

/// Throws drape::Error (BadInput) unless `name` can name a broadcaster: 1 to 64 letters,
/// digits, '-' or '_' (it becomes a NATS subject token and a stream name).
void checkSourceName(const std::string& name, const std::string& option);
/// `drape.NAME` and `DRAPE_NAME`.
[[nodiscard]] std::string subjectOf(const std::string& source);
[[nodiscard]] std::string streamOf(const std::string& source);
/// `drape.NAME.inject`: requests to a broadcaster (an anim-server's event graphs), not kept
/// in any stream.
[[nodiscard]] std::string requestSubjectOf(const std::string& source);

/// A request that came to a Listener, to be answered.
struct Request {
  std::vector<std::uint8_t> data;
  std::string replyTo;
};

class Reader;
class Listener;

/// One connection to a NATS server with JetStream. Moves, does not copy; closes on
/// destruction. The connection reconnects by itself when the server goes away and comes
/// back (a restarted server on the same store keeps every stream).
class Bus {
 public:
  /// Connects to `url` (nats://host:port) as `client`. Throws drape::Error (Unavailable)
  /// naming the URL when no server answers within `timeout`.
  [[nodiscard]] static Bus connect(const std::string& url, const std::string& client,
                                   std::chrono::milliseconds timeout = std::chrono::seconds(5));
  Bus(Bus&&) noexcept;
  Bus& operator=(Bus&&) noexcept;
  ~Bus();

  [[nodiscard]] const std::string& url() const;
  /// The largest message the server takes (its max_payload).
  [[nodiscard]] std::size_t maxPayload() const;

  /// Creates `source`'s stream if the server has none (file storage, duplicate window of
  /// two minutes). Throws drape::Error (Unavailable) when the server has no JetStream.
  void ensureStream(const std::string& source);
  /// Empties `source`'s stream (a new take replaces the last one).
  void purge(const std::string& source);
  /// Deletes `source`'s stream, if the server has it.
  void remove(const std::string& source);
  /// Publishes `data` on `source`'s subject and waits for the stream's acknowledgement;
  /// `messageId` lets the stream drop a message published twice. Returns its sequence (0
  /// when the stream dropped it as a duplicate). Throws drape::Error (Unavailable) when no
  /// stream takes it, or (BadInput) when it is over the server's max_payload.
  std::uint64_t publish(const std::string& source, std::span<const std::uint8_t> data, const std::string& messageId);
  [[nodiscard]] StreamRange range(const std::string& source);
  /// The broadcasters whose streams the server holds (streams named DRAPE_NAME), sorted.
  [[nodiscard]] std::vector<std::string> broadcasters();
  /// The message at `sequence` of `source`'s stream, or nothing where it holds none.
  [[nodiscard]] std::optional<Received> get(const std::string& source, std::uint64_t sequence);

  /// A reader of `source`'s stream from `sequence` on, under the durable consumer name
  /// `consumer` (which replaces a consumer of that name: a reader starts where it is told).
  [[nodiscard]] Reader read(const std::string& source, const std::string& consumer, std::uint64_t sequence);

  /// The requests that come on `subject` from now on (core NATS: while nobody listens, a
  /// request finds no responder and its sender is told so).
  [[nodiscard]] Listener listen(const std::string& subject);
  /// Sends a request on `subject` and waits for its answer. Throws drape::Error (Unavailable)
  /// when nobody listens there or no answer came within `timeout`.
  [[nodiscard]] std::vector<std::uint8_t> request(const std::string& subject, std::span<const std::uint8_t> data,
                                                  std::chrono::milliseconds timeout);

  struct Impl;

 private:
  explicit Bus(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

class Listener {
 public:
  Listener(Listener&&) noexcept;
  Listener& operator=(Listener&&) noexcept;
  ~Listener();
  /// The next request, or nothing when none came within `timeout` (0: only one already there).
  [[nodiscard]] std::optional<Request> next(std::chrono::milliseconds timeout);
  /// Answers `request`.
  void answer(const Request& request, std::span<const std::uint8_t> data);

  struct Impl;

 private:
  friend class Bus;
  explicit Listener(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

class Reader {
 public:
  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;
  ~Reader();
  /// The next message, or nothing when none came within `timeout`. Messages come in the
  /// stream's order, each once.
  [[nodiscard]] std::optional<Received> next(std::chrono::milliseconds timeout);

  struct Impl;

 private:
  friend class Bus;
  explicit Reader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::studio
