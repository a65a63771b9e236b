#pragma once
// Garments worn over garments (a jacket over a shirt): which garment lies over which, the
// order they step in, and the collider that keeps each off the ones below it (beyond the
// paper). One way: a garment below steps first, each frame, and does not feel the one over
// it; the one over it collides with it as it moved through that frame (cloth::LayerCollider).

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "drape/cloth/layer_collider.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

/// Per garment, the indices of the garments it is worn over (its `over` names). Throws
/// drape::Error on a name that is no garment of `garments`, on a garment over itself, and on
/// names that go round (a over b over a).
[[nodiscard]] std::vector<std::vector<std::size_t>> garmentsBelow(const std::vector<GarmentSpec>& garments);

/// Per garment, its layer (garmentsBelow's lists, which do not go round): the scene's.
using scene::layersOf;

/// The avatar's segments named in `segments` at rest, as points in the world: their
/// vertices, and with `spacing_m` > 0 points on their triangles no farther apart than that
/// too: the body a garment colliding with them is worn on (cloth::LayerCollider::setBody),
/// whose nearest point must lie under a garment's vertex, not off to its side, where a
/// robot's parts are boxes of a few large triangles.
[[nodiscard]] std::vector<Vec3> restBodyPoints(const scene::Avatar& avatar, const std::vector<std::string>& segments,
                                               double spacing_m = 0.0);

/// The layer collider garment `g` of `garments` needs: its own layers kept apart
/// (selfCollision_m) and the garments it is worn over (`below`, garmentsBelow's list for
/// it) kept overGap_m under it; null when it needs neither. `fixed`: its vertices a fixture
/// moves; `solver(i)`: garment i's solver, whose state the collider reads each frame (it
/// must outlive the collider); frame_s: the frames' length; `avatar`: who wears it (null:
/// none), whose collidable parts at rest (restBodyPoints, two gaps apart: as near as it is
/// worn over the garments below) tell which side of those is over. Initialised at the
/// solvers' states now, with what was modelled under the garments below moved out over
/// them; the caller adds it to g's solver before the body's collider.
[[nodiscard]] std::unique_ptr<cloth::LayerCollider> makeLayerCollider(
    const std::vector<GarmentSpec>& garments, std::size_t g, std::span<const std::size_t> below,
    const std::vector<std::uint32_t>& fixed, const std::function<cloth::ClothSolver&(std::size_t)>& solver,
    double frame_s, const scene::Avatar* avatar = nullptr);

}  // namespace drape::sim
