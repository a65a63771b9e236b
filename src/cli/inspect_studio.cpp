#include "inspect_studio.hpp"

#include <optional>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/messages.hpp"

namespace drape::cli {
namespace {

/// A take as its messages show it, from its first and last.
struct TakeSummary {
  std::string take, what;
  std::optional<TimeCode> start;
  std::int64_t lastFrame = -1;
  std::optional<studio::End> end;
};

std::optional<studio::Message> decoded(studio::Bus& bus, const std::string& source, std::uint64_t sequence) {
  const std::optional<studio::Received> r = bus.get(source, sequence);
  if (!r) return std::nullopt;
  try {
    return studio::decode(r->data);
  } catch (const Error&) {
    return std::nullopt;
  }
}

TakeSummary summarise(studio::Bus& bus, const std::string& source, const studio::StreamRange& range) {
  TakeSummary t;
  if (const auto first = decoded(bus, source, range.first)) {
    t.take = first->take;
    if (const auto* p = std::get_if<studio::PoseStart>(&first->payload)) {
      t.start = p->start;
      t.what = fmt::format("poses of {} ({} joints){}", p->character, p->joints.size(),
                           p->frames > 0 ? fmt::format(", {} frames announced", p->frames) : std::string());
    } else if (const auto* c = std::get_if<studio::ClothStart>(&first->payload)) {
      t.start = c->start;
      std::vector<std::string> garments;
      for (const studio::GarmentInfo& g : c->garments) garments.push_back(fmt::format("{} ({} vertices)", g.name, g.vertices));
      t.what = fmt::format("cloth of {} on {}, simulating take {} of '{}'", fmt::join(garments, ", "), c->character,
                           c->poseTake, c->poses);
    } else {
      t.what = "a take whose start is not the stream's first message";
    }
  }
  // The last frame: the last message, or the one before an End.
  for (std::uint64_t seq = range.last; seq >= range.first && seq + 2 > range.last && seq > 0; --seq) {
    const auto m = decoded(bus, source, seq);
    if (!m) continue;
    if (const auto* e = std::get_if<studio::End>(&m->payload)) t.end = *e;
    if (const auto* p = std::get_if<studio::PoseFrame>(&m->payload)) t.lastFrame = std::max(t.lastFrame, p->frame);
    if (const auto* c = std::get_if<studio::ClothFrame>(&m->payload)) t.lastFrame = std::max(t.lastFrame, c->frame);
  }
  return t;
}

}  // namespace

bool isServerUrl(const std::string& what) { return what.rfind("nats://", 0) == 0; }

void inspectStudio(const std::string& url, std::ostream& out) {
  studio::Bus bus = studio::Bus::connect(url, "drape inspect");
  const std::vector<std::string> sources = bus.broadcasters();
  fmt::print(out, "{}: {} drape stream{}\n", url, sources.size(), sources.size() == 1 ? "" : "s");
  for (const std::string& source : sources) {
    const studio::StreamRange range = bus.range(source);
    fmt::print(out, "  {} ({}, stream {}): {} message{}\n", source, studio::subjectOf(source), studio::streamOf(source),
               range.messages, range.messages == 1 ? "" : "s");
    if (range.messages == 0) continue;
    const TakeSummary t = summarise(bus, source, range);
    fmt::print(out, "    take {}: {}\n", t.take.empty() ? "?" : t.take, t.what);
    if (t.start && t.lastFrame >= 0)
      fmt::print(out, "    frames 0 to {} ({} to {})\n", t.lastFrame, t.start->smpte(),
                 TimeCode{t.start->frame + t.lastFrame, t.start->rate}.smpte());
    if (!t.end) {
      fmt::print(out, "    not ended: under way, or its sender stopped\n");
      continue;
    }
    if (!t.end->error.empty()) {
      fmt::print(out, "    ended early after {} frames: {}\n", t.end->frames, t.end->error);
      continue;
    }
    const nlohmann::json stats = nlohmann::json::parse(t.end->stats, nullptr, false);
    if (stats.is_object() && stats.contains("vertex_substeps_inside_body"))
      fmt::print(out, "    ended; simulated at {:.3g} ms per frame, {} vertex-substeps inside the body, max strain {:.3g}\n",
                 stats.value("ms_per_frame", 0.0), stats.value("vertex_substeps_inside_body", 0L),
                 stats.value("max_strain", 0.0));
    else
      fmt::print(out, "    ended\n");
  }
}

}  // namespace drape::cli
