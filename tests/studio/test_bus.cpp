// The buffer servers against a real nats-server: streams per broadcaster, publishing with
// acknowledgements and de-duplication, readers from any sequence, and the errors a user
// meets (no server, a server without JetStream, a frame too large).

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/studio/bus.hpp"
#include "drape/testing/nats_server.hpp"

namespace drape::studio {
namespace {

std::vector<std::uint8_t> bytesOf(const std::string& text) { return {text.begin(), text.end()}; }
std::string textOf(const Received& r) { return {r.data.begin(), r.data.end()}; }

TEST(StudioBus, ReadersGetAStreamInOrderFromAnySequence) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  EXPECT_FALSE(bus.range("anim").exists);
  bus.ensureStream("anim");
  bus.ensureStream("anim");  // idempotent
  for (int i = 0; i < 300; ++i)
    EXPECT_EQ(bus.publish("anim", bytesOf(fmt::format("m{}", i)), fmt::format("id-{}", i)),
              static_cast<std::uint64_t>(i + 1));
  const StreamRange range = bus.range("anim");
  EXPECT_TRUE(range.exists);
  EXPECT_EQ(range.first, 1u);
  EXPECT_EQ(range.last, 300u);
  EXPECT_EQ(range.messages, 300u);
  ASSERT_TRUE(bus.get("anim", 17));
  EXPECT_EQ(textOf(*bus.get("anim", 17)), "m16");
  EXPECT_FALSE(bus.get("anim", 301));

  for (const std::uint64_t from : {0ul, 1ul, 150ul, 300ul}) {
    Reader reader = bus.read("anim", "reader", from);
    for (std::uint64_t seq = std::max<std::uint64_t>(from, 1); seq <= 300; ++seq) {
      const std::optional<Received> r = reader.next(std::chrono::seconds(5));
      ASSERT_TRUE(r) << "from " << from << ", sequence " << seq;
      ASSERT_EQ(r->sequence, seq);
      ASSERT_EQ(textOf(*r), fmt::format("m{}", seq - 1));
    }
    EXPECT_FALSE(reader.next(std::chrono::milliseconds(100))) << "nothing past the end";
  }
}

TEST(StudioBus, AReaderWaitingAtTheEndGetsTheNextMessageWhenItComes) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("cloth");
  Reader reader = bus.read("cloth", "live", 0);
  EXPECT_FALSE(reader.next(std::chrono::milliseconds(50)));
  Bus other = Bus::connect(server.url(), "publisher");
  (void)other.publish("cloth", bytesOf("late"), "late");
  const std::optional<Received> r = reader.next(std::chrono::seconds(5));
  ASSERT_TRUE(r);
  EXPECT_EQ(textOf(*r), "late");
}

TEST(StudioBus, AMessageSentTwiceUnderOneIdIsKeptOnce) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  EXPECT_EQ(bus.publish("anim", bytesOf("a"), "take.pose.0"), 1u);
  EXPECT_EQ(bus.publish("anim", bytesOf("a"), "take.pose.0"), 0u) << "a duplicate";
  EXPECT_EQ(bus.publish("anim", bytesOf("b"), "take.pose.1"), 2u);
  EXPECT_EQ(bus.range("anim").messages, 2u);
  bus.purge("anim");
  const StreamRange empty = bus.range("anim");
  EXPECT_TRUE(empty.exists);
  EXPECT_EQ(empty.messages, 0u);
  EXPECT_EQ(bus.publish("anim", bytesOf("c"), "take2.pose.0"), 3u) << "sequences go on after a purge";
}

TEST(StudioBus, StreamsOutliveARestartOfTheServerOnItsStore) {
  testing::NatsServer server;
  Bus bus = Bus::connect(server.url(), "test");
  bus.ensureStream("anim");
  (void)bus.publish("anim", bytesOf("before"), "1");
  server.stop();
  server.start();
  // The connection comes back by itself; the stream, on file storage, is still there.
  std::uint64_t seq = 0;
  for (int attempt = 0; attempt < 100 && seq == 0; ++attempt) {
    try {
      seq = bus.publish("anim", bytesOf("after"), "2");
    } catch (const Error&) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  EXPECT_EQ(seq, 2u);
  EXPECT_EQ(textOf(*bus.get("anim", 1)), "before");
}

TEST(StudioBus, ErrorsSayWhatToDo) {
  testing::NatsServer plain(false);
  Bus bus = Bus::connect(plain.url(), "test");
  try {
    bus.ensureStream("anim");
    FAIL() << "a server without JetStream took a stream";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unavailable);
    EXPECT_NE(std::string(e.what()).find("the server has no JetStream (start it with nats-server -js)"),
              std::string::npos)
        << e.what();
  }
  const testing::RefusingPort refusing;
  const std::string nowhere = refusing.url();
  try {
    (void)Bus::connect(nowhere, "test", std::chrono::milliseconds(500));
    FAIL() << "connected to no server";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ExitCode::Unavailable);
    EXPECT_NE(std::string(e.what()).find(nowhere + ": no NATS server answers"), std::string::npos) << e.what();
  }

  testing::NatsServer server;
  Bus js = Bus::connect(server.url(), "test");
  js.ensureStream("cloth");
  ASSERT_GT(js.maxPayload(), 0u);
  try {
    (void)js.publish("cloth", std::vector<std::uint8_t>(js.maxPayload() + 1, 0), "big");
    FAIL() << "a frame over max_payload was sent";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("over the server's max_payload"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--positions float"), std::string::npos) << e.what();
  }
  EXPECT_THROW(checkSourceName("my.stream", "--name"), Error);
  EXPECT_THROW(checkSourceName("", "--name"), Error);
  EXPECT_NO_THROW(checkSourceName("cloth-2_b", "--name"));
  EXPECT_EQ(streamOf("cloth-2_b"), "DRAPE_cloth-2_b");
  EXPECT_EQ(subjectOf("cloth-2_b"), "drape.cloth-2_b");
}

}  // namespace
}  // namespace drape::studio
