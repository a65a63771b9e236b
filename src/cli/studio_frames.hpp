#pragma once
// What `drape player` collates (docs/STUDIO.md): the cloth takes of one or more
// cloth-servers and the pose takes they simulated (one per character of the scene), frame by
// frame as drape run's outputs see them: every garment's positions and vertex states, and
// each character's joints at the frame's time, from the same poses its cloth-servers played
// (the lead-in included).

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/sim/character_world.hpp"
#include "drape/studio/bus.hpp"
#include "drape/studio/cloth_follower.hpp"
#include "drape/studio/pose_follower.hpp"
#include "frames_ahead.hpp"
#include "run_setup.hpp"
#include "studio_options.hpp"

namespace drape::cli {

class StudioFrames {
 public:
  /// Reads the cloth streams of `cloth` (each from its first message) for the scene of
  /// `setup`, following no take yet. Throws drape::Error (BadInput) for a bad or repeated
  /// stream name or a scene without an avatar.
  StudioFrames(studio::Bus& bus, RunSetup& setup, const std::vector<std::string>& cloth, const StudioOptions& options);
  ~StudioFrames();

  /// Follows the next take of each cloth stream (the take `take`, if given; never the one
  /// followed before, which a stream may still hold) and the pose takes they simulated,
  /// reading on from where the streams are. Keeps of the scene's garments and characters in
  /// `setup` the ones the streams send, in the scene's order; throws drape::Error (BadInput)
  /// when a stream sends a garment the scene does not have or has otherwise, or another
  /// character's, or two streams send the same one, or streams of one character follow
  /// different poses, or the characters' takes run at different rates, lead-ins or times.
  void followNextTake(const std::string& take = "");

  /// Frame `frame` (the next after the last, from 0) of the take followed into `out`
  /// (sized here); false when the takes ended before it. Throws what a cloth-server's take
  /// ended with (a garment that went unstable) after the frames before it, and
  /// studio::NewTake when a stream started another take before this one ended.
  bool next(long frame, FrameTaken& out);

  /// Where `from` says a player starts: "now" (the newest frame every stream holds
  /// whole: a live take joined where it is) or a time code HH:MM:SS:FF of the take. Jumps
  /// there without reading the cloth before it and returns the frame, for next(). Throws
  /// drape::Error (BadInput) for a time code before the take or past its end.
  long seek(const std::string& from);

  /// A flag that ends every wait of the streams (studio::Stopped) once set.
  void stopOn(const std::atomic<bool>* flag);

  /// Each character's joints at frame 0 (the rest pose, where the lead-in starts).
  [[nodiscard]] std::vector<std::vector<RigidTransform>> jointsAtStart() const;
  [[nodiscard]] const studio::ClothStart& start() const { return cloth_.front().follower->start(); }
  [[nodiscard]] const std::string& take() const { return cloth_.front().follower->take(); }
  /// The cloth-servers' stats, by stream (after next() returned false).
  [[nodiscard]] std::vector<std::pair<std::string, std::string>> stats() const;

 private:
  struct Cloth {
    std::string source;
    std::unique_ptr<studio::StreamReader> stream;
    std::unique_ptr<studio::ClothFollower> follower;
    std::vector<std::size_t> garment;  ///< per garment of the stream, its index in the setup
  };
  RunSetup& setup_;
  const std::vector<GarmentSetup> sceneGarments_;
  const std::vector<CharacterSetup> sceneCharacters_;
  const StudioOptions options_;
  studio::Bus& bus_;
  std::string consumer_;
  /// A pose stream and its take, read since the stream was first followed.
  struct Poses {
    std::unique_ptr<studio::StreamReader> stream;
    std::unique_ptr<studio::PoseFollower> follower;
  };
  /// A character of the take: the poses its cloth-servers played, at any time.
  struct Body {
    Poses* poses = nullptr;
    std::unique_ptr<sim::AvatarPoses> avatarPoses;
    std::size_t firstCloth = 0;  ///< a cloth stream of it (its start says the lead-in)
  };
  /// Which character of the scene cloth stream s's take simulates.
  [[nodiscard]] std::size_t sceneCharacterOf(std::size_t s) const;
  Poses& posesFrom(const std::string& source);

  std::vector<Cloth> cloth_;
  std::vector<std::pair<std::string, std::unique_ptr<Poses>>> poses_;  ///< by stream name
  std::vector<Body> bodies_;                          ///< per character of the setup
  const std::atomic<bool>* stop_ = nullptr;
};

}  // namespace drape::cli
