#pragma once
// The characters' bodies as a window shows them, frame by frame: each one's rigid parts
// posed, its skinned body fitted to its parts and tucked under the garments it wears, and
// its drawn meshes (hair, eyes) skinned as they are
// (`drape play SCENE` and the studio's player; `drape run` writes the same through
// RunWriter).
//
//   ShownBodies bodies(setup, meshes, fields, allowances);   // appends the bodies' meshes
//   bodies.pose(taken.joints, taken.positions, frame.positions);

#include <memory>
#include <optional>
#include <vector>

#include "drape/render/frame.hpp"
#include "drape/sim/body_skin.hpp"
#include "run_setup.hpp"

namespace drape::cli {

class ShownBodies {
 public:
  /// Appends to `meshes` (which holds the setup's garments first, in its order) each
  /// character's segments, skinned body and drawn meshes. `fields[c]` are the part fields character c's
  /// skin is fitted to (null: no skin), `allowance_m[c]` how far out of them it may stand.
  ShownBodies(const RunSetup& setup, std::vector<render::MeshInfo>& meshes,
              const std::vector<const std::vector<sim::PartField>*>& fields, const std::vector<double>& allowance_m);

  /// The bodies at a frame: `joints` per character, `garments` the positions per garment of
  /// the setup; into `out`, one entry per mesh (sized as `meshes`).
  void pose(const std::vector<std::vector<RigidTransform>>& joints, const std::vector<std::vector<Vec3>>& garments,
            std::vector<std::vector<Vec3>>& out);

 private:
  struct Body {
    const CharacterSetup* character = nullptr;
    std::size_t firstSegment = 0;         ///< its first segment's mesh
    std::optional<std::size_t> skinMesh;  ///< its skinned body's mesh
    std::optional<std::size_t> drawnMesh; ///< its drawn meshes' mesh
    std::unique_ptr<sim::BodySkin> skin;
  };
  const RunSetup& setup_;
  std::vector<Body> bodies_;
  std::vector<sim::GarmentSurface> surfaces_;
};

}  // namespace drape::cli
