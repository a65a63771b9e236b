// Studio messages <-> FlatBuffers bytes (studio_frames.fbs). The reader verifies the buffer
// before it trusts any offset in it, then checks what verification cannot: that the payload
// is one it knows, that numbers are finite and that sizes agree.

#include "drape/studio/messages.hpp"

#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "studio_frames_generated.h"

namespace drape::studio {
namespace {

namespace fb = flatbuffers;
namespace w = wire;

/// Largest message the reader takes apart (NATS servers allow at most 64 MB).
constexpr std::size_t kLargestMessage = std::size_t{64} << 20;

std::string str(const fb::String* s) { return s == nullptr ? std::string() : s->str(); }

template <typename T>
std::vector<T> vec(const fb::Vector<T>* v) {
  return v == nullptr ? std::vector<T>() : std::vector<T>(v->begin(), v->end());
}

std::vector<fb::Offset<fb::String>> strings(fb::FlatBufferBuilder& b, const std::vector<std::string>& in) {
  std::vector<fb::Offset<fb::String>> out;
  out.reserve(in.size());
  for (const std::string& s : in) out.push_back(b.CreateString(s));
  return out;
}

struct Put {
  fb::FlatBufferBuilder& b;
  Precision precision;

  fb::Offset<void> operator()(const PoseStart& p) const {
    const auto joints = strings(b, p.joints);
    return w::CreatePoseStartDirect(b, p.character.c_str(), &joints, &p.driving, p.start.rate, p.start.frame, p.frames)
        .Union();
  }
  fb::Offset<void> operator()(const PoseFrame& p) const {
    std::vector<w::Transform> joints;
    joints.reserve(p.joints.size());
    for (const RigidTransform& t : p.joints)
      joints.emplace_back(t.rotation.w(), t.rotation.x(), t.rotation.y(), t.rotation.z(), t.translation.x(),
                          t.translation.y(), t.translation.z());
    std::vector<double> wind;
    if (p.wind) wind = {p.wind->x(), p.wind->y(), p.wind->z()};
    return w::CreatePoseFrameDirect(b, p.frame, &joints, p.wind ? &wind : nullptr).Union();
  }
  fb::Offset<void> operator()(const ClothStart& c) const {
    std::vector<fb::Offset<w::GarmentInfo>> garments;
    for (const GarmentInfo& g : c.garments) garments.push_back(w::CreateGarmentInfoDirect(b, g.name.c_str(), g.vertices));
    return w::CreateClothStartDirect(b, c.poses.c_str(), c.poseTake.c_str(), c.character.c_str(), c.start.rate,
                                     c.leadIn_s, c.start.frame, &garments)
        .Union();
  }
  fb::Offset<void> operator()(const ClothFrame& c) const {
    fb::Offset<fb::Vector<double>> doubles;
    fb::Offset<fb::Vector<float>> floats;
    if (precision == Precision::Double) {
      double* out = nullptr;
      doubles = b.CreateUninitializedVector(c.positions.size() * 3, &out);
      for (const Vec3& p : c.positions) out = std::copy(p.data(), p.data() + 3, out);
    } else {
      float* out = nullptr;
      floats = b.CreateUninitializedVector(c.positions.size() * 3, &out);
      for (const Vec3& p : c.positions)
        for (int k = 0; k < 3; ++k) *out++ = static_cast<float>(p[k]);
    }
    const auto states = b.CreateVector(c.states);
    return w::CreateClothFrame(b, c.frame, c.garment, doubles, floats, states).Union();
  }
  fb::Offset<void> operator()(const End& e) const {
    return w::CreateEndDirect(b, e.frames, e.stats.c_str(), e.error.c_str(), e.exitCode).Union();
  }
  fb::Offset<void> operator()(const Inject& i) const {
    return w::CreateInjectDirect(b, i.graph.c_str(), i.baseDir.c_str(), i.event.c_str()).Union();
  }
  fb::Offset<void> operator()(const InjectReply& r) const {
    return w::CreateInjectReplyDirect(b, r.accepted, r.message.c_str()).Union();
  }
};

w::Payload payloadType(const Payload& p) {
  switch (p.index()) {
    case 0: return w::Payload_PoseStart;
    case 1: return w::Payload_PoseFrame;
    case 2: return w::Payload_ClothStart;
    case 3: return w::Payload_ClothFrame;
    case 4: return w::Payload_End;
    case 5: return w::Payload_Inject;
    default: return w::Payload_InjectReply;
  }
}

[[noreturn]] void refuse(const std::string& what) { throw Error("not a drape studio frame: " + what); }

bool finite(const w::Transform& t) {
  return std::isfinite(t.qw()) && std::isfinite(t.qx()) && std::isfinite(t.qy()) && std::isfinite(t.qz()) &&
         std::isfinite(t.tx()) && std::isfinite(t.ty()) && std::isfinite(t.tz());
}

TimeCode timeCode(std::int64_t frame, double rate, const char* table) {
  if (!(rate > 0.0) || !std::isfinite(rate)) refuse(fmt::format("{} has a frame rate of {}", table, rate));
  return TimeCode{frame, rate};
}

PoseStart read(const w::PoseStart& in) {
  PoseStart out;
  out.character = str(in.character());
  if (in.joints() != nullptr)
    for (const fb::String* j : *in.joints()) out.joints.push_back(str(j));
  out.driving = vec(in.driving());
  out.start = timeCode(in.start_frame(), in.rate(), "PoseStart");
  out.frames = in.frames();
  if (out.joints.empty()) refuse("PoseStart lists no joints");
  if (out.driving.size() != out.joints.size())
    refuse(fmt::format("PoseStart has {} joints and {} driving joints", out.joints.size(), out.driving.size()));
  if (out.frames < 0) refuse(fmt::format("PoseStart announces {} frames", out.frames));
  return out;
}

PoseFrame read(const w::PoseFrame& in) {
  PoseFrame out;
  out.frame = in.frame();
  if (out.frame < 0) refuse(fmt::format("PoseFrame {} is numbered before 0", out.frame));
  if (in.joints() == nullptr || in.joints()->size() == 0) refuse(fmt::format("PoseFrame {} has no joints", out.frame));
  out.joints.reserve(in.joints()->size());
  for (const w::Transform* t : *in.joints()) {
    if (!finite(*t)) refuse(fmt::format("PoseFrame {} has a joint transform that is not finite", out.frame));
    const Quat q(t->qw(), t->qx(), t->qy(), t->qz());
    // A rotation, not any four numbers: the simulation interpolates it by SLERP.
    if (std::abs(q.squaredNorm() - 1.0) > 1e-6)
      refuse(fmt::format("PoseFrame {} has a joint rotation of norm {:.6g}, not a unit quaternion", out.frame, q.norm()));
    out.joints.push_back({q, Vec3(t->tx(), t->ty(), t->tz())});
  }
  if (const auto* wind = in.wind(); wind != nullptr && wind->size() > 0) {
    if (wind->size() != 3) refuse(fmt::format("PoseFrame {} has a wind of {} numbers, not 3", out.frame, wind->size()));
    const Vec3 v(wind->Get(0), wind->Get(1), wind->Get(2));
    if (!v.allFinite()) refuse(fmt::format("PoseFrame {} has a wind that is not finite", out.frame));
    out.wind = v;
  }
  return out;
}

ClothStart read(const w::ClothStart& in) {
  ClothStart out;
  out.poses = str(in.poses());
  out.poseTake = str(in.pose_take());
  out.character = str(in.character());
  out.start = timeCode(in.start_frame(), in.rate(), "ClothStart");
  out.leadIn_s = in.lead_in_s();
  if (!(out.leadIn_s >= 0.0) || !std::isfinite(out.leadIn_s)) refuse(fmt::format("ClothStart has a lead-in of {} s", out.leadIn_s));
  if (in.garments() != nullptr)
    for (const w::GarmentInfo* g : *in.garments()) out.garments.push_back({str(g->name()), g->vertices()});
  if (out.garments.empty()) refuse("ClothStart lists no garments");
  return out;
}

ClothFrame read(const w::ClothFrame& in) {
  ClothFrame out;
  out.frame = in.frame();
  out.garment = in.garment();
  if (out.frame < 0) refuse(fmt::format("ClothFrame {} is numbered before 0", out.frame));
  const auto* doubles = in.positions();
  const auto* floats = in.positions_f32();
  if ((doubles == nullptr) == (floats == nullptr))
    refuse(fmt::format("ClothFrame {} of garment {} has {} positions", out.frame, out.garment,
                       doubles == nullptr ? "no" : "two kinds of"));
  const std::size_t values = doubles != nullptr ? doubles->size() : floats->size();
  if (values % 3 != 0)
    refuse(fmt::format("ClothFrame {} of garment {} has {} coordinates, not three per vertex", out.frame, out.garment,
                       values));
  out.positions.resize(values / 3);
  for (std::size_t v = 0; v < out.positions.size(); ++v)
    for (std::size_t k = 0; k < 3; ++k) {
      const double x = doubles != nullptr ? doubles->Get(static_cast<fb::uoffset_t>(3 * v + k))
                                          : static_cast<double>(floats->Get(static_cast<fb::uoffset_t>(3 * v + k)));
      if (!std::isfinite(x))
        refuse(fmt::format("ClothFrame {} of garment {} has a position that is not finite (vertex {})", out.frame,
                           out.garment, v));
      out.positions[v][static_cast<Eigen::Index>(k)] = x;
    }
  out.states = vec(in.states());
  if (!out.states.empty() && out.states.size() != out.positions.size())
    refuse(fmt::format("ClothFrame {} of garment {} has {} vertices and {} states", out.frame, out.garment,
                       out.positions.size(), out.states.size()));
  return out;
}

Inject read(const w::Inject& in) { return {str(in.graph()), str(in.base_dir()), str(in.event())}; }

InjectReply read(const w::InjectReply& in) { return {in.accepted(), str(in.message())}; }

End read(const w::End& in) {
  End out;
  out.frames = in.frames();
  out.stats = str(in.stats());
  out.error = str(in.error());
  out.exitCode = in.exit_code();
  return out;
}

}  // namespace

std::vector<std::uint8_t> encode(const Message& message, Precision precision) {
  fb::FlatBufferBuilder b(1024);
  const fb::Offset<void> payload = std::visit(Put{b, precision}, message.payload);
  const auto source = b.CreateString(message.source);
  const auto take = b.CreateString(message.take);
  b.Finish(w::CreateMessage(b, kWireVersion, source, take, payloadType(message.payload), payload),
           w::MessageIdentifier());
  return {b.GetBufferPointer(), b.GetBufferPointer() + b.GetSize()};
}

Message decode(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < 8) refuse(fmt::format("{} bytes are too few for one", bytes.size()));
  if (!fb::BufferHasIdentifier(bytes.data(), w::MessageIdentifier()))
    refuse(fmt::format("its bytes 4 to 7 are not the identifier \"{}\"", w::MessageIdentifier()));
  if (bytes.size() > kLargestMessage) refuse(fmt::format("{} bytes are over the {} MB a frame may have", bytes.size(), kLargestMessage >> 20));
  fb::Verifier verifier(bytes.data(), bytes.size(), 16, 10'000'000);
  if (!w::VerifyMessageBuffer(verifier)) refuse(fmt::format("its {} bytes fail FlatBuffers' verification (truncated or damaged)", bytes.size()));
  const w::Message* in = w::GetMessage(bytes.data());
  if (in->version() != kWireVersion)
    refuse(fmt::format("it is of wire version {}, this drape reads version {}", in->version(), kWireVersion));
  Message out;
  out.source = str(in->source());
  out.take = str(in->take());
  // A union's table may be absent where its type is set: verification lets that pass.
  const auto known = [&](const auto* table) -> const auto& {
    if (table == nullptr) refuse(fmt::format("its payload of type {} is missing", static_cast<int>(in->payload_type())));
    return *table;
  };
  switch (in->payload_type()) {
    case w::Payload_PoseStart: out.payload = read(known(in->payload_as_PoseStart())); break;
    case w::Payload_PoseFrame: out.payload = read(known(in->payload_as_PoseFrame())); break;
    case w::Payload_ClothStart: out.payload = read(known(in->payload_as_ClothStart())); break;
    case w::Payload_ClothFrame: out.payload = read(known(in->payload_as_ClothFrame())); break;
    case w::Payload_End: out.payload = read(known(in->payload_as_End())); break;
    case w::Payload_Inject: out.payload = read(known(in->payload_as_Inject())); break;
    case w::Payload_InjectReply: out.payload = read(known(in->payload_as_InjectReply())); break;
    default: refuse(fmt::format("its payload is of unknown type {}", static_cast<int>(in->payload_type())));
  }
  return out;
}

std::string describe(const Payload& payload) {
  struct Describe {
    std::string operator()(const PoseStart& p) const { return "PoseStart of " + p.character; }
    std::string operator()(const PoseFrame& p) const { return fmt::format("PoseFrame {}", p.frame); }
    std::string operator()(const ClothStart& c) const { return "ClothStart of " + c.character; }
    std::string operator()(const ClothFrame& c) const { return fmt::format("ClothFrame {} of garment {}", c.frame, c.garment); }
    std::string operator()(const End& e) const { return fmt::format("End after {} frames", e.frames); }
    std::string operator()(const Inject& i) const {
      return i.graph.empty() ? "Inject of event '" + i.event + "'" : "Inject of a graph";
    }
    std::string operator()(const InjectReply& r) const { return r.accepted ? "InjectReply: done" : "InjectReply: refused"; }
  };
  return std::visit(Describe{}, payload);
}

}  // namespace drape::studio
