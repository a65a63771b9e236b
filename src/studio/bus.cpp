// NATS JetStream through the NATS C client (libnats): the connection, the broadcasters'
// streams, publishing with acknowledgements, readers as pull consumers.

#include "drape/studio/bus.hpp"

#include <algorithm>
#include <cctype>
#include <deque>
#include <thread>

#include <fmt/format.h>
#include <nats/nats.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"

namespace drape::studio {
namespace {

constexpr std::int64_t kNanosPerMilli = 1'000'000;
/// How long a reader's durable consumer outlives its last reader: long enough for a
/// restarted role to find it, short enough that abandoned ones do not pile up.
constexpr std::int64_t kConsumerInactive_ns = std::int64_t{3600} * 1'000'000'000;
/// Messages a reader takes from the server in one request while a backlog lasts.
constexpr int kFetchBatch = 256;

std::string statusText(natsStatus s, jsErrCode jerr) {
  std::string text = natsStatus_GetText(s);
  const char* last = nats_GetLastError(nullptr);
  if (last != nullptr && *last != '\0' && text != last) text += fmt::format(" ({})", last);
  if (jerr != 0) text += fmt::format(", JetStream error {}", static_cast<int>(jerr));
  return text;
}

/// The server answered nothing on JetStream's API subjects: it runs without JetStream.
bool noJetStream(natsStatus s) { return s == NATS_NO_RESPONDERS; }

}  // namespace

void checkSourceName(const std::string& name, const std::string& option) {
  const bool ok = !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
  if (!ok)
    throw Error(fmt::format("{} '{}': a broadcaster's name is 1 to 64 letters, digits, '-' or '_' (it names a NATS "
                            "subject and stream)",
                            option, name));
}

std::string subjectOf(const std::string& source) { return "drape." + source; }

std::string streamOf(const std::string& source) { return "DRAPE_" + source; }

std::string requestSubjectOf(const std::string& source) { return subjectOf(source) + ".inject"; }

struct Bus::Impl {
  std::string url;
  natsOptions* options = nullptr;
  natsConnection* connection = nullptr;
  jsCtx* js = nullptr;

  ~Impl() {
    if (js != nullptr) jsCtx_Destroy(js);
    if (connection != nullptr) {
      natsConnection_Close(connection);
      natsConnection_Destroy(connection);
    }
    if (options != nullptr) natsOptions_Destroy(options);
  }

  [[noreturn]] void fail(const std::string& what, natsStatus s, jsErrCode jerr = static_cast<jsErrCode>(0)) const {
    if (noJetStream(s))
      throw Error(fmt::format("{}: {}: the server has no JetStream (start it with nats-server -js)", url, what),
                  ExitCode::Unavailable);
    throw Error(fmt::format("{}: {}: {}", url, what, statusText(s, jerr)), ExitCode::Unavailable);
  }
};

Bus::Bus(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Bus::Bus(Bus&&) noexcept = default;
Bus& Bus::operator=(Bus&&) noexcept = default;
Bus::~Bus() = default;

Bus Bus::connect(const std::string& url, const std::string& client, std::chrono::milliseconds timeout) {
  auto impl = std::make_unique<Impl>();
  impl->url = url;
  natsStatus s = natsOptions_Create(&impl->options);
  if (s == NATS_OK) s = natsOptions_SetURL(impl->options, url.c_str());
  if (s == NATS_OK) s = natsOptions_SetName(impl->options, client.c_str());
  if (s == NATS_OK) s = natsOptions_SetTimeout(impl->options, timeout.count());
  // A server that goes away and comes back (restarted on its store) is waited for, for ever:
  // roles are servers too, and a frame is only lost if its stream is.
  if (s == NATS_OK) s = natsOptions_SetMaxReconnect(impl->options, -1);
  if (s == NATS_OK) s = natsOptions_SetReconnectWait(impl->options, 250);
  // Frames are small and each waits for its acknowledgement: send at once, do not batch.
  if (s == NATS_OK) s = natsOptions_SetSendAsap(impl->options, true);
  if (s != NATS_OK) impl->fail("cannot set the connection's options", s);
  s = natsConnection_Connect(&impl->connection, impl->options);
  if (s == NATS_NO_SERVER || s == NATS_TIMEOUT)
    throw Error(fmt::format("{}: no NATS server answers (start one with nats-server -js, or give --server URL)", url),
                ExitCode::Unavailable);
  if (s != NATS_OK) impl->fail("cannot connect", s);
  jsOptions jo;
  jsOptions_Init(&jo);
  jo.Wait = std::max<std::int64_t>(1000, timeout.count());
  s = natsConnection_JetStream(&impl->js, impl->connection, &jo);
  if (s != NATS_OK) impl->fail("cannot open JetStream", s);
  return Bus(std::move(impl));
}

const std::string& Bus::url() const { return impl_->url; }

std::size_t Bus::maxPayload() const {
  return static_cast<std::size_t>(std::max<std::int64_t>(0, natsConnection_GetMaxPayload(impl_->connection)));
}

void Bus::ensureStream(const std::string& source) {
  const std::string stream = streamOf(source);
  jsStreamInfo* info = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  natsStatus s = js_GetStreamInfo(&info, impl_->js, stream.c_str(), nullptr, &jerr);
  if (s == NATS_OK) {
    jsStreamInfo_Destroy(info);
    return;
  }
  if (s != NATS_NOT_FOUND) impl_->fail(fmt::format("cannot look up stream {}", stream), s, jerr);
  jsStreamConfig config;
  jsStreamConfig_Init(&config);
  const std::string subject = subjectOf(source);
  const char* subjects[] = {subject.c_str()};
  config.Name = stream.c_str();
  config.Subjects = subjects;
  config.SubjectsLen = 1;
  config.Storage = js_FileStorage;
  config.Duplicates = std::int64_t{120} * 1'000'000'000;
  s = js_AddStream(&info, impl_->js, &config, nullptr, &jerr);
  if (s != NATS_OK && jerr == JSStreamSubjectOverlapErr)
    throw Error(fmt::format("{}: subject {} belongs to another stream of this server than {}: give this broadcaster "
                            "another --name, or delete that stream",
                            impl_->url, subject, stream),
                ExitCode::Unavailable);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot create stream {} for {}", stream, subject), s, jerr);
  jsStreamInfo_Destroy(info);
}

void Bus::purge(const std::string& source) {
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_PurgeStream(impl_->js, streamOf(source).c_str(), nullptr, &jerr);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot empty stream {}", streamOf(source)), s, jerr);
}

void Bus::remove(const std::string& source) {
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_DeleteStream(impl_->js, streamOf(source).c_str(), nullptr, &jerr);
  if (s != NATS_OK && s != NATS_NOT_FOUND) impl_->fail(fmt::format("cannot delete stream {}", streamOf(source)), s, jerr);
}

std::uint64_t Bus::publish(const std::string& source, std::span<const std::uint8_t> data, const std::string& messageId) {
  const std::size_t most = maxPayload();
  if (most > 0 && data.size() > most)
    throw Error(fmt::format("{}: a frame of {:.2f} MB is over the server's max_payload of {:.2f} MB (raise it in the "
                            "server's configuration, up to 64 MB, or send floats: --positions float)",
                            impl_->url, static_cast<double>(data.size()) / 1048576.0,
                            static_cast<double>(most) / 1048576.0));
  const std::string subject = subjectOf(source);
  jsPubOptions po;
  jsPubOptions_Init(&po);
  po.MsgId = messageId.c_str();
  jsPubAck* ack = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_Publish(&ack, impl_->js, subject.c_str(), data.data(), static_cast<int>(data.size()), &po, &jerr);
  if (noJetStream(s))
    throw Error(fmt::format("{}: no stream takes {} (was {} deleted, or does the server run without JetStream?)",
                            impl_->url, subject, streamOf(source)),
                ExitCode::Unavailable);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot publish on {}", subject), s, jerr);
  const std::uint64_t sequence = ack->Duplicate ? 0 : ack->Sequence;
  jsPubAck_Destroy(ack);
  return sequence;
}

StreamRange Bus::range(const std::string& source) {
  jsStreamInfo* info = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetStreamInfo(&info, impl_->js, streamOf(source).c_str(), nullptr, &jerr);
  if (s == NATS_NOT_FOUND) return {};
  if (s != NATS_OK) impl_->fail(fmt::format("cannot look up stream {}", streamOf(source)), s, jerr);
  StreamRange r{true, info->State.FirstSeq, info->State.LastSeq, info->State.Msgs};
  if (r.messages == 0) r.first = r.last = 0;
  jsStreamInfo_Destroy(info);
  return r;
}

std::vector<std::string> Bus::broadcasters() {
  jsStreamNamesList* list = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_StreamNames(&list, impl_->js, nullptr, &jerr);
  if (s == NATS_NOT_FOUND) return {};
  if (s != NATS_OK) impl_->fail("cannot list the streams", s, jerr);
  std::vector<std::string> out;
  const std::string prefix = streamOf("");
  for (int i = 0; i < list->Count; ++i) {
    const std::string name = list->List[i];
    if (name.rfind(prefix, 0) == 0 && name.size() > prefix.size()) out.push_back(name.substr(prefix.size()));
  }
  jsStreamNamesList_Destroy(list);
  std::sort(out.begin(), out.end());
  return out;
}

std::optional<Received> Bus::get(const std::string& source, std::uint64_t sequence) {
  natsMsg* msg = nullptr;
  jsErrCode jerr = static_cast<jsErrCode>(0);
  const natsStatus s = js_GetMsg(&msg, impl_->js, streamOf(source).c_str(), sequence, nullptr, &jerr);
  if (s == NATS_NOT_FOUND) return std::nullopt;
  if (s != NATS_OK) impl_->fail(fmt::format("cannot read message {} of stream {}", sequence, streamOf(source)), s, jerr);
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(natsMsg_GetData(msg));
  Received r{{bytes, bytes + natsMsg_GetDataLength(msg)}, sequence, natsMsg_GetTime(msg)};
  natsMsg_Destroy(msg);
  return r;
}

struct Reader::Impl {
  Bus::Impl* bus = nullptr;
  std::string consumer;
  natsSubscription* subscription = nullptr;
  std::deque<Received> ready;
  bool outage = false;  ///< the last read failed: said once, until a read works again

  ~Impl() {
    if (subscription == nullptr) return;
    // Unsubscribing deletes the consumer the reader made; one left by a reader that died
    // goes by itself after kConsumerInactive_ns.
    (void)natsSubscription_Unsubscribe(subscription);
    natsSubscription_Destroy(subscription);
  }

  /// Moves what `list` holds into `ready`, in order.
  void take(natsMsgList& list) {
    for (int i = 0; i < list.Count; ++i) {
      natsMsg* msg = list.Msgs[i];
      jsMsgMetaData* meta = nullptr;
      std::uint64_t sequence = 0;
      std::int64_t time = 0;
      if (natsMsg_GetMetaData(&meta, msg) == NATS_OK) {
        sequence = meta->Sequence.Stream;
        time = meta->Timestamp;
        jsMsgMetaData_Destroy(meta);
      }
      const auto* bytes = reinterpret_cast<const std::uint8_t*>(natsMsg_GetData(msg));
      ready.push_back({{bytes, bytes + natsMsg_GetDataLength(msg)}, sequence, time});
    }
    natsMsgList_Destroy(&list);
  }
};

Reader::Reader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;
Reader::~Reader() = default;

Reader Bus::read(const std::string& source, const std::string& consumer, std::uint64_t sequence) {
  const std::string stream = streamOf(source);
  jsErrCode jerr = static_cast<jsErrCode>(0);
  // The reader starts where it is told: a consumer of the same name from an earlier run
  // (which remembers where that one stopped) is replaced.
  const natsStatus gone = js_DeleteConsumer(impl_->js, stream.c_str(), consumer.c_str(), nullptr, &jerr);
  if (gone != NATS_OK && gone != NATS_NOT_FOUND)
    impl_->fail(fmt::format("cannot replace consumer {} of stream {}", consumer, stream), gone, jerr);
  jsSubOptions so;
  jsSubOptions_Init(&so);
  so.Stream = stream.c_str();
  so.Config.DeliverPolicy = sequence > 0 ? js_DeliverByStartSequence : js_DeliverAll;
  so.Config.OptStartSeq = sequence;
  so.Config.AckPolicy = js_AckNone;
  so.Config.InactiveThreshold = kConsumerInactive_ns;
  auto impl = std::make_unique<Reader::Impl>();
  impl->bus = impl_.get();
  impl->consumer = consumer;
  const std::string subject = subjectOf(source);
  const natsStatus s = js_PullSubscribe(&impl->subscription, impl_->js, subject.c_str(), consumer.c_str(), nullptr, &so, &jerr);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot read stream {} as {}", stream, consumer), s, jerr);
  return Reader(std::move(impl));
}

std::optional<Received> Reader::next(std::chrono::milliseconds timeout) {
  Impl& r = *impl_;
  if (r.ready.empty()) {
    // A backlog comes in batches without waiting; with none, wait for the one next message,
    // which then comes as soon as it is published.
    natsMsgList list{};
    jsFetchRequest request;
    jsFetchRequest_Init(&request);
    request.Batch = kFetchBatch;
    request.NoWait = true;
    // The server answers a request that may not wait at once; the client still waits up to
    // its expiry for that answer, so keep it short.
    request.Expires = std::min<std::int64_t>(50, std::max<std::int64_t>(1, timeout.count())) * kNanosPerMilli;
    jsErrCode jerr = static_cast<jsErrCode>(0);
    natsStatus s = natsSubscription_FetchRequest(&list, r.subscription, &request);
    if (s == NATS_OK && list.Count > 0) {
      r.take(list);
    } else {
      if (s == NATS_OK) natsMsgList_Destroy(&list);
      natsMsgList one{};
      if (s == NATS_OK || s == NATS_TIMEOUT || s == NATS_NOT_FOUND)
        s = natsSubscription_Fetch(&one, r.subscription, 1, std::max<std::int64_t>(1, timeout.count()), &jerr);
      if (s == NATS_TIMEOUT || s == NATS_NOT_FOUND) return std::nullopt;
      if (s == NATS_CONNECTION_CLOSED || s == NATS_INVALID_SUBSCRIPTION)
        r.bus->fail(fmt::format("cannot read as {}", r.consumer), s, jerr);
      if (s != NATS_OK) {
        // The server went away (restarting, or a network between): the connection comes
        // back by itself and the consumer, stored with the stream, with it. Until then this
        // is a read that found nothing; the caller says what it waits for.
        if (!r.outage) spdlog::warn("{}: reading as {}: {}; trying again", r.bus->url, r.consumer, statusText(s, jerr));
        r.outage = true;
        std::this_thread::sleep_for(std::min(timeout, std::chrono::milliseconds(250)));
        return std::nullopt;
      }
      r.take(one);
    }
    if (r.outage) spdlog::info("{}: reading as {} again", r.bus->url, r.consumer);
    r.outage = false;
  }
  if (r.ready.empty()) return std::nullopt;
  Received out = std::move(r.ready.front());
  r.ready.pop_front();
  return out;
}

struct Listener::Impl {
  Bus::Impl* bus = nullptr;
  std::string subject;
  natsSubscription* subscription = nullptr;
  ~Impl() {
    if (subscription == nullptr) return;
    (void)natsSubscription_Unsubscribe(subscription);
    natsSubscription_Destroy(subscription);
  }
};

Listener::Listener(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Listener::Listener(Listener&&) noexcept = default;
Listener& Listener::operator=(Listener&&) noexcept = default;
Listener::~Listener() = default;

Listener Bus::listen(const std::string& subject) {
  auto impl = std::make_unique<Listener::Impl>();
  impl->bus = impl_.get();
  impl->subject = subject;
  natsStatus s = natsConnection_SubscribeSync(&impl->subscription, impl_->connection, subject.c_str());
  // The subscription is the server's once the connection has sent it: a request right after
  // this returns finds it.
  if (s == NATS_OK) s = natsConnection_Flush(impl_->connection);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot listen on {}", subject), s);
  return Listener(std::move(impl));
}

std::optional<Request> Listener::next(std::chrono::milliseconds timeout) {
  natsMsg* msg = nullptr;
  const natsStatus s = natsSubscription_NextMsg(&msg, impl_->subscription, std::max<std::int64_t>(0, timeout.count()));
  if (s == NATS_TIMEOUT) return std::nullopt;
  if (s != NATS_OK) {
    // The connection is down (it comes back by itself): nothing to answer now.
    std::this_thread::sleep_for(std::min(timeout, std::chrono::milliseconds(250)));
    return std::nullopt;
  }
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(natsMsg_GetData(msg));
  Request r{{bytes, bytes + natsMsg_GetDataLength(msg)}, natsMsg_GetReply(msg) ? natsMsg_GetReply(msg) : ""};
  natsMsg_Destroy(msg);
  return r;
}

void Listener::answer(const Request& request, std::span<const std::uint8_t> data) {
  if (request.replyTo.empty()) return;  // a message sent without waiting for an answer
  const natsStatus s = natsConnection_Publish(impl_->bus->connection, request.replyTo.c_str(), data.data(),
                                              static_cast<int>(data.size()));
  if (s != NATS_OK) spdlog::warn("{}: could not answer a request on {}: {}", impl_->bus->url, impl_->subject, statusText(s, static_cast<jsErrCode>(0)));
}

std::vector<std::uint8_t> Bus::request(const std::string& subject, std::span<const std::uint8_t> data,
                                       std::chrono::milliseconds timeout) {
  natsMsg* reply = nullptr;
  const natsStatus s = natsConnection_Request(&reply, impl_->connection, subject.c_str(), data.data(),
                                              static_cast<int>(data.size()), timeout.count());
  if (s == NATS_NO_RESPONDERS)
    throw Error(fmt::format("{}: nobody listens on {}", impl_->url, subject), ExitCode::Unavailable);
  if (s == NATS_TIMEOUT)
    throw Error(fmt::format("{}: no answer on {} within {:g} s", impl_->url, subject,
                            static_cast<double>(timeout.count()) / 1000.0),
                ExitCode::Unavailable);
  if (s != NATS_OK) impl_->fail(fmt::format("cannot send a request on {}", subject), s);
  const auto* bytes = reinterpret_cast<const std::uint8_t*>(natsMsg_GetData(reply));
  std::vector<std::uint8_t> out(bytes, bytes + natsMsg_GetDataLength(reply));
  natsMsg_Destroy(reply);
  return out;
}

}  // namespace drape::studio
