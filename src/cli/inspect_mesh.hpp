#pragma once
// `drape inspect` of a garment's mesh file: what `drape make-scene --garment` would read.

#include <ostream>
#include <string>

namespace drape::cli {

/// Counts, bounds and boundary loops of a mesh file (an OBJ in its own units; glTF, Collada
/// and FBX in metres, their meshes listed and their vertices welded as the garment readers
/// weld them).
void inspectMeshFile(const std::string& path, std::ostream& out);

}  // namespace drape::cli
