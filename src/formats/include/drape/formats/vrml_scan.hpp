#pragma once
// The pre-scan of VRML97 text: drape's own check of a file before Coin3D sees it. Coin's
// reader crashes or hangs on some malformed input (a USE inside its own still-open DEF,
// bytes it takes for another format, very deep nesting), so every VRML97 text is scanned
// first: the `#VRML V2.0 utf8` header, tokens, strings, balanced brackets, DEF before USE,
// no PROTO that contains an instance of itself,
// no USE inside its own DEF, nesting depth, and the field names of drape's own nodes.
// Errors are `file:line:column: what`. The scan does not build a scene graph; Coin does.

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace drape::formats::vrml {

/// The interface of a PROTO or EXTERNPROTO: its field names (all four kinds).
struct ProtoInterface {
  std::string name;
  std::vector<std::string> fields;
  int line = 0;
  bool external = false;
};

/// One written instance of a drape node type (ClothSet, ClothMaterial, Simulation, Avatar),
/// in file order, with where each of its fields was written.
struct NodeSite {
  std::string type;
  std::string def;  ///< DEF name or ""
  int line = 0;
  int column = 0;
  std::map<std::string, int> fieldLines;  ///< field name -> line
};

struct ScanOptions {
  /// PROTOs known before the file (the prelude's): instances of these are checked for
  /// unknown field names; a file may redeclare them.
  std::vector<ProtoInterface> knownProtos;
  /// Node types whose instances are recorded in ScanResult::sites and, while the type is
  /// still the prelude's, tagged with `drapeNodeId N` (N = index into sites) so the Coin
  /// side can tie each node to its source line. Injected on the same line: line numbers
  /// in Coin's messages stay right.
  std::vector<std::string> trackedTypes;
  int maxDepth = 128;  ///< deepest nesting of brackets accepted
};

struct ScanResult {
  std::string text;                      ///< the input, with drapeNodeId tags injected
  std::vector<ProtoInterface> declared;  ///< PROTOs and EXTERNPROTOs the file declares
  std::vector<NodeSite> sites;           ///< instances of tracked types, in file order
};

/// Scans `text` read from `file` (used in messages). Throws drape::Error
/// "file:line:column: what" on the first problem found.
[[nodiscard]] ScanResult scan(std::string_view text, const std::string& file, const ScanOptions& options = {});

}  // namespace drape::formats::vrml
