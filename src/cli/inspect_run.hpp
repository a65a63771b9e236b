#pragma once
// `drape inspect RUN_DIR`: what a finished run holds, and where its garments lie against
// the body in the frames it recorded: the garment vertices deepest in the skinned body
// (--deepest N), the edges stretched most (--stretched N), or one vertex frame by frame
// (--vertex V) with the collidable parts it is nearest to, which is what it rests on.
// Everything is measured on the meshes the run wrote (the skin as players draw it, the
// rigid segments the cloth collided with), exactly.

#include <ostream>
#include <string>

namespace drape::cli {

struct RunQuery {
  long vertex = -1;      ///< --vertex: a garment vertex to follow frame by frame; -1: none
  long deepest = 0;      ///< --deepest: how many of the deepest vertices to list; 0: none
  long stretched = 0;    ///< --stretched: how many of the most stretched edges to list; 0: none
  std::string range;     ///< --range: the frames, as `drape render --range` takes them; "": all
  std::string garment;   ///< --garment: which garment (needed for --vertex when there are several)
  [[nodiscard]] bool any() const {
    return vertex >= 0 || deepest > 0 || stretched > 0 || !range.empty() || !garment.empty();
  }
};

/// Prints the run's summary, then what `query` asks. Throws drape::Error on a bad run
/// directory or a query it cannot answer (a vertex, frame or garment the run does not have).
void inspectRun(const std::string& directory, const RunQuery& query, std::ostream& out);

}  // namespace drape::cli
