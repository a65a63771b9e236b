#pragma once
// Reading VRML97 (scenes, H-Anim avatars, Inline targets): drape's pre-scan, then Coin3D
// in a child process with memory and time limits (drape::runIsolated), which hands back a
// vrml::Document. A crash or hang of Coin becomes "FILE: the VRML97 reader failed
// (signal N / time limit)"; drape itself goes on.
//
// The prelude (share/drape/drape-nodes.wrl, compiled in) declares drape's node types
// (ClothSet, ClothMaterial, Simulation, Avatar) and H-Anim 1.1's (Humanoid, Joint,
// Segment, Site, Displacer) before every file; a file may declare them itself.

#include <string>
#include <string_view>

#include "drape/core/isolate.hpp"
#include "drape/formats/vrml_tree.hpp"

namespace drape::formats::vrml {

struct ReadOptions {
  IsolationLimits limits{std::size_t{2} << 30, 60.0};
  bool isolate = true;  ///< false: run Coin in this process (tests only: Coin may crash it)
  /// false: hand the text to Coin without drape's pre-scan. Only for testing that the
  /// child process contains Coin's own crashes and hangs; never for real input.
  bool prescan = true;
};

/// Reads a VRML97 file. Throws drape::Error (exit code 2) with "file:line:column: what"
/// from the pre-scan, "file:line: what" from Coin's reader, a missing Inline or
/// EXTERNPROTO target naming its URL, or the reader's failure.
[[nodiscard]] Document readFile(const std::string& path, const ReadOptions& options = {});

/// Reads VRML97 text that came from elsewhere (a network peer, a fuzzer). `name` is used
/// in messages; relative Inline and EXTERNPROTO URLs are resolved against `baseDir`.
[[nodiscard]] Document readText(std::string_view text, const std::string& name, const std::string& baseDir,
                                const ReadOptions& options = {});

/// The prelude's text (share/drape/drape-nodes.wrl as built into drape).
[[nodiscard]] std::string_view prelude();

/// The node types drape reads as its own (the prelude's first four).
[[nodiscard]] bool isDrapeNodeType(std::string_view type);

}  // namespace drape::formats::vrml
