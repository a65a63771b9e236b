#include "studio_frames.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/takes.hpp"

namespace drape::cli {
namespace {

/// Where two cloth takes disagree about what they simulate, or "".
std::string disagreement(const studio::ClothStart& a, const studio::ClothStart& b) {
  if (a.poses != b.poses || a.poseTake != b.poseTake)
    return fmt::format("take {} of '{}' and take {} of '{}'", a.poseTake, a.poses, b.poseTake, b.poses);
  if (a.character != b.character) return fmt::format("characters '{}' and '{}'", a.character, b.character);
  if (a.start.rate != b.start.rate || a.leadIn_s != b.leadIn_s || a.start.frame != b.start.frame)
    return "different frame rates, lead-ins or time codes";
  return "";
}

}  // namespace

StudioFrames::StudioFrames(studio::Bus& bus, RunSetup& setup, const std::vector<std::string>& cloth,
                           const StudioOptions& options)
    : setup_(setup), sceneGarments_(setup.garments), sceneCharacters_(setup.characters), options_(options), bus_(bus),
      consumer_(consumerName("player", true)) {
  if (setup.characters.empty()) throw Error("drape player: the scene has no avatar the garments are worn by");
  if (cloth.empty()) throw Error("--cloth: name at least one cloth-server");
  for (const std::string& source : cloth) {
    studio::checkSourceName(source, "--cloth");
    if (std::count(cloth.begin(), cloth.end(), source) > 1) throw Error(fmt::format("--cloth: '{}' twice", source));
    Cloth c;
    c.source = source;
    c.stream = std::make_unique<studio::StreamReader>(bus, source, consumer_, options.patience(), options.giveUp());
    c.follower = std::make_unique<studio::ClothFollower>(*c.stream);
    cloth_.push_back(std::move(c));
  }
}

std::size_t StudioFrames::sceneCharacterOf(std::size_t s) const {
  if (sceneCharacters_.size() == 1) return 0;  // a scene of one: whatever its takes call it
  const std::string& character = cloth_[s].follower->start().character;
  for (std::size_t c = 0; c < sceneCharacters_.size(); ++c)
    if (sceneCharacters_[c].name == character) return c;
  std::vector<std::string> names;
  for (const CharacterSetup& c : sceneCharacters_) names.push_back(c.name);
  throw Error(fmt::format("cloth stream '{}' simulates character '{}', which the scene does not have (it has: {}); give "
                          "its anim-server --character NAME",
                          cloth_[s].source, character, fmt::join(names, ", ")));
}

StudioFrames::Poses& StudioFrames::posesFrom(const std::string& source) {
  for (auto& [name, poses] : poses_)
    if (name == source) return *poses;
  Poses& p = *poses_.emplace_back(source, std::make_unique<Poses>()).second;
  p.stream = std::make_unique<studio::StreamReader>(bus_, source, consumer_, options_.patience(), options_.giveUp());
  p.stream->stopOn(stop_);
  p.follower = std::make_unique<studio::PoseFollower>(*p.stream);
  return p;
}

void StudioFrames::followNextTake(const std::string& take) {
  for (Cloth& c : cloth_) {
    const std::string before = c.follower->take();
    c.follower->followNextTake(take, before);
    c.garment.clear();
  }
  // Each stream's character; the streams of one character simulate one pose take, and every
  // character's take runs at the scene's rate, with the same lead-in and time code.
  std::vector<std::size_t> characterOf(cloth_.size());
  std::vector<std::optional<std::size_t>> firstOf(sceneCharacters_.size());
  for (std::size_t s = 0; s < cloth_.size(); ++s) {
    characterOf[s] = sceneCharacterOf(s);
    std::optional<std::size_t>& first = firstOf[characterOf[s]];
    if (!first) first = s;
    const Cloth& a = cloth_[*first];
    if (const std::string bad = disagreement(a.follower->start(), cloth_[s].follower->start()); !bad.empty())
      throw Error(fmt::format("--cloth: '{}' and '{}' simulate {}: a player collates the cloth of one pose take per "
                              "character",
                              a.source, cloth_[s].source, bad));
  }
  const studio::ClothStart& first = cloth_.front().follower->start();
  for (const Cloth& c : cloth_) {
    const studio::ClothStart& other = c.follower->start();
    if (other.start.rate != first.start.rate || other.leadIn_s != first.leadIn_s || other.start.frame != first.start.frame)
      throw Error(fmt::format("--cloth: '{}' and '{}' simulate takes of different frame rates, lead-ins or time codes "
                              "({} and {}): give the anim-servers the same --timecode",
                              cloth_.front().source, c.source, first.start.smpte(), other.start.smpte()));
  }
  if (first.start.rate != setup_.settings.frameRate_hz)
    throw Error(fmt::format("cloth take {} runs at {:g} frames per second, the scene at {:g}: give the player the "
                            "cloth-servers' scene",
                            cloth_.front().follower->take(), first.start.rate, setup_.settings.frameRate_hz));

  // The garments the streams send, in the scene's order, each of the character its stream's
  // take simulates.
  std::vector<std::string> names;
  for (const GarmentSetup& g : sceneGarments_) names.push_back(g.name);
  std::vector<int> from(sceneGarments_.size(), -1);  // the stream sending each scene garment
  for (std::size_t s = 0; s < cloth_.size(); ++s)
    for (const studio::GarmentInfo& g : cloth_[s].follower->start().garments) {
      const auto it = std::find(names.begin(), names.end(), g.name);
      if (it == names.end())
        throw Error(fmt::format("cloth stream '{}' sends garment '{}', which the scene does not have (it has: {})",
                                cloth_[s].source, g.name, fmt::join(names, ", ")));
      const auto i = static_cast<std::size_t>(it - names.begin());
      if (from[i] >= 0)
        throw Error(fmt::format("garment '{}' comes from both '{}' and '{}'", g.name, cloth_[static_cast<std::size_t>(from[i])].source,
                                cloth_[s].source));
      if (g.vertices != sceneGarments_[i].mesh.vertexCount())
        throw Error(fmt::format("cloth stream '{}' sends garment '{}' with {} vertices, the scene's has {}",
                                cloth_[s].source, g.name, g.vertices, sceneGarments_[i].mesh.vertexCount()));
      const std::vector<std::size_t>& worn = sceneCharacters_[characterOf[s]].garments;
      if (std::find(worn.begin(), worn.end(), i) == worn.end())
        throw Error(fmt::format("cloth stream '{}' sends garment '{}' on {}, which the scene does not dress in it",
                                cloth_[s].source, g.name, sceneCharacters_[characterOf[s]].name));
      from[i] = static_cast<int>(s);
    }
  std::vector<std::string> missing;
  std::vector<std::size_t> keptIndex(sceneGarments_.size(), 0);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < sceneGarments_.size(); ++i) {
    if (from[i] < 0) {
      missing.push_back(names[i]);
      continue;
    }
    keptIndex[i] = kept++;
  }
  if (!missing.empty()) spdlog::info("no cloth stream sends {}; the player shows the rest", fmt::join(missing, ", "));
  for (Cloth& c : cloth_)
    for (const studio::GarmentInfo& g : c.follower->start().garments)
      c.garment.push_back(keptIndex[static_cast<std::size_t>(std::find(names.begin(), names.end(), g.name) - names.begin())]);
  // The setup shows the garments sent, in the scene's order (keptIndex's), on the
  // characters that wear them.
  setup_.garments = sceneGarments_;
  setup_.characters = sceneCharacters_;
  keepGarmentsWhere(setup_, [&](std::size_t g) { return from[g] >= 0; });

  // Each character's poses from where its stream is: a take's poses come before its cloth.
  bodies_.clear();
  for (std::size_t c = 0; c < sceneCharacters_.size(); ++c) {
    if (!firstOf[c]) continue;  // no stream sends its garments: it is not in the setup
    const std::size_t s = *firstOf[c];
    const studio::ClothStart& start = cloth_[s].follower->start();
    Body& body = bodies_.emplace_back();
    body.firstCloth = s;
    body.poses = &posesFrom(start.poses);
    const scene::Avatar& avatar = *sceneCharacters_[c].avatar;
    body.poses->follower->followNextTake(avatar, setup_.settings.frameRate_hz, start.poseTake);
    if (!body.poses->follower->waitForFrames(1))
      throw Error(fmt::format("pose take {} ended without a frame", start.poseTake));
    body.avatarPoses = std::make_unique<sim::AvatarPoses>(avatar, &body.poses->follower->animation(), start.leadIn_s);
  }
}

StudioFrames::~StudioFrames() = default;

void StudioFrames::stopOn(const std::atomic<bool>* flag) {
  stop_ = flag;
  for (Cloth& c : cloth_) c.stream->stopOn(flag);
  for (auto& [name, poses] : poses_) poses->stream->stopOn(flag);
}

std::vector<std::vector<RigidTransform>> StudioFrames::jointsAtStart() const {
  std::vector<std::vector<RigidTransform>> joints(bodies_.size());
  for (std::size_t c = 0; c < bodies_.size(); ++c) {
    joints[c].resize(setup_.characters[c].avatar->joints.size());
    bodies_[c].avatarPoses->evaluate(0.0, joints[c]);
  }
  return joints;
}

bool StudioFrames::next(long frame, FrameTaken& out) {
  out.frame = frame;
  out.positions.resize(setup_.garments.size());
  out.states.resize(setup_.garments.size());
  out.joints.resize(bodies_.size());
  for (std::size_t c = 0; c < bodies_.size(); ++c) out.joints[c].resize(setup_.characters[c].avatar->joints.size());
  out.stageMs = {};
  bool ended = false;
  for (Cloth& c : cloth_) {
    if (!c.follower->waitForFrame(frame)) {
      ended = true;
      continue;
    }
    for (std::uint32_t g = 0; g < c.garment.size(); ++g) {
      const studio::ClothFrame& f = c.follower->garment(g);
      out.positions[c.garment[g]] = f.positions;
      out.states[c.garment[g]] = f.states;
      if (f.states.empty()) out.states[c.garment[g]].assign(f.positions.size(), 0);  // a sender that keeps none
    }
  }
  if (ended) return false;
  for (std::size_t c = 0; c < bodies_.size(); ++c) {
    const studio::ClothStart& s = cloth_[bodies_[c].firstCloth].follower->start();
    (void)bodies_[c].poses->follower->waitForFrames(
        studio::motionFramesNeeded(frame, s.start.rate, s.leadIn_s, s.start.rate));
    // The time as the cloth-servers' world computes a frame's (CharacterWorld::frameTime).
    bodies_[c].avatarPoses->evaluate(static_cast<double>(frame) / setup_.settings.frameRate_hz, out.joints[c]);
  }
  return true;
}

long StudioFrames::seek(const std::string& from) {
  const studio::ClothStart& s = start();
  const TimeCode first = s.start;
  std::int64_t newest = std::numeric_limits<std::int64_t>::max();
  std::optional<std::int64_t> ended;
  for (Cloth& c : cloth_) {
    const studio::ClothFollower::Held held = c.follower->held();
    newest = std::min(newest, held.newest);
    if (held.ended) ended = std::min(ended.value_or(*held.ended), *held.ended);
  }
  std::int64_t frame = 0;
  if (from == "now") {
    frame = std::max<std::int64_t>(newest, 0);
  } else {
    const TimeCode at = TimeCode::parseSmpte(from, first.rate);
    frame = at.frame - first.frame;
    if (frame < 0)
      throw Error(fmt::format("--from {}: take {} starts at {}", from, take(), first.smpte()));
    if (ended && frame > *ended)
      throw Error(fmt::format("--from {}: take {} ends at {} (frame {})", from, take(),
                              TimeCode{first.frame + *ended, first.rate}.smpte(), *ended));
  }
  for (Cloth& c : cloth_) c.follower->seek(frame);
  spdlog::info("starting at {} (frame {} of take {})", TimeCode{first.frame + frame, first.rate}.smpte(), frame, take());
  return static_cast<long>(frame);
}

std::vector<std::pair<std::string, std::string>> StudioFrames::stats() const {
  std::vector<std::pair<std::string, std::string>> out;
  for (const Cloth& c : cloth_)
    if (c.follower->end() && !c.follower->end()->stats.empty()) out.emplace_back(c.source, c.follower->end()->stats);
  return out;
}

}  // namespace drape::cli
