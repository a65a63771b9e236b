#pragma once
// The scene model (paper section 4.1): avatars, garments, cloth materials and simulation
// settings as plain domain objects, built from a VRML97 scene file. Units are SI: positions
// in metres (file coordinates times the scene's unitScale), material and simulation values
// as written (they are SI in the file already). Nothing here knows Coin3D or the cloth
// solver: sim/ maps these onto cloth/'s parameters.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

/// Physical properties of a cloth (the ClothMaterial node). Defaults: a light cotton.
struct ClothMaterial {
  std::string name;              ///< DEF name or `name`, for messages
  double density = 300.0;        ///< kg/m^3 of the cloth itself
  double thickness = 0.0005;     ///< m
  double youngsModulus = 5.0e5;  ///< Pa, in-plane stiffness of the membrane
  double poissonRatio = 0.3;     ///< in [0, 0.5)
  /// N m; < 0 means "derive from E t^3 / (12 (1 - nu^2))" (bendingStiffnessOrDerived()).
  double bendingStiffness = -1.0;
  double damping = 0.0;           ///< s, stiffness-proportional (Rayleigh) damping time (>= 0)
  double staticFriction = 0.5;    ///< coefficient against body surfaces
  double dynamicFriction = 0.3;   ///< coefficient against body surfaces (<= static)
  double compressionScale = 0.1;  ///< stiffness under compression relative to tension, in [0, 1]
  SourcePos source;               ///< where the node was written

  /// kg/m^2: density x thickness, the mass per unit area of cloth.
  [[nodiscard]] double arealDensity() const { return density * thickness; }
  /// N m: the bending stiffness given, or the plate formula E t^3 / (12 (1 - nu^2)).
  [[nodiscard]] double bendingStiffnessOrDerived() const;
};

/// Environment and solver settings (the Simulation node).
struct SimulationSettings {
  Vec3 gravity{0.0, -9.81, 0.0};  ///< m/s^2
  double frameRate = 30.0;        ///< frames per second of output and motion
  int stepsPerFrame = 33;         ///< explicit substeps per frame
  double airViscosity = 0.02;     ///< N s/m^2 per unit area: drag on velocity relative to wind
  Vec3 wind{0.0, 0.0, 0.0};       ///< m/s
  /// m: the collision offset surfaces T0 < T1 < T2 < T3 of paper section 4.3.3, where the
  /// node writes them; else each garment's follow the voxel size (1, 2, 3 and 6 voxels, the
  /// paper's proportions), as without a Simulation node.
  std::optional<std::array<double, 4>> offsets;
  double voxelSize = 0.01;                      ///< m, edge of a distance-field voxel
  std::string integrator = "symplectic-euler";  ///< name the cloth solver resolves
  int collisionEvery = 1;                       ///< collide every N substeps
  int bendEvery = 1;                            ///< bending forces every N substeps, as an impulse
  double maxAddedMass = 0.0;                    ///< mass scaling allowed, fraction of a garment's mass
  /// A frame that goes unstable is computed again with up to this many times the substeps.
  int maxRefinement = 8;
  /// Largest stretch of an edge beyond its rest length, held from the first frame; 0: none.
  double strainLimit = 0.0;
  /// The same, from a frame no refinement keeps stable on, for the rest of the run; 0: such a
  /// frame stops the run. Without effect while strainLimit is on.
  double rescueStrainLimit = 0.5;
  /// Backward Euler's linear solves stop at this residual, a fraction of the right-hand
  /// side's (cloth::StepSettings::implicitTolerance).
  double implicitTolerance = 1e-3;
  double unitScale = 1.0;                       ///< metres per file unit (applied to all geometry on load)
  /// Body parts whose motion is corrected to keep them out of the collidable parts they go
  /// into (a forearm swung through the back; sim/keep_apart.hpp).
  std::vector<std::string> keepApart;
  SourcePos source;                             ///< where the node was written; empty when defaulted
};

/// A garment (a ClothSet): its mesh in world metres, the constraint mask matched onto it,
/// the material and the avatar it is worn by.
struct Garment {
  std::string name;
  mesh::TriMesh mesh;                       ///< m, world, rest shape as modelled
  int material = -1;                        ///< index into Scene::materials
  std::vector<std::uint32_t> maskVertices;  ///< garment vertices matched by the mask, sorted
  double maskTolerance = 0.001;             ///< m
  double bindThreshold = 0.02;              ///< m, farthest a mask vertex binds to a body part
  std::vector<std::string> collidesWith;    ///< segment names; empty: every segment
  std::vector<std::string> faceSamplesWith;  ///< of those, where triangle centroids collide too
  /// m: how far apart the garment's own layers keep (cloth::LayerCollider); 0: they pass
  /// through one another, as in the paper.
  double selfCollision = 0.0;
  /// Names of the garments it is worn over (a jacket over a shirt): kept overGap above them,
  /// one way (they do not feel it; cloth::LayerCollider). The same character's, never itself
  /// nor, through others, over itself.
  std::vector<std::string> over;
  double overGap = 0.004;                   ///< m, above the garments it is worn over
  /// m: its own offset surfaces T0..T3, instead of the Simulation node's; none: those.
  std::optional<std::array<double, 4>> offsets;
  /// Pairs of cloth vertices sewn together (a closure the mesh leaves open): each pair is
  /// drawn to one point and held there. Indices into `mesh`, two different ones, in range.
  std::vector<std::array<std::uint32_t, 2>> stitches;
  /// The diffuse colour (sRGB, 0 to 1) of the Material of its first cloth Shape that has
  /// one; none: the players' own cloth colour.
  std::optional<Vec3> colour;
  int avatar = -1;                          ///< index into Scene::avatars (a Humanoid), or -1
  int externalAvatar = -1;                  ///< index into Scene::externalAvatars, or -1
  SourcePos source;
};

/// An Avatar node: a character in another format, loaded by the characters code.
struct ExternalAvatar {
  std::string name;
  std::vector<std::string> urls;      ///< resolved against the scene's directory
  std::vector<std::string> jointMap;  ///< URL(s) of a joint-name map, or empty
  /// Joints whose rigid parts are cut across the joint, what lies behind it going to the
  /// parent's part (scene::segmentSkinnedAvatar); empty: parts by dominant weight alone.
  std::vector<std::string> cutAtJoints;
  /// The file's skinned meshes that make the body, by node or mesh name (a character file
  /// that also holds its clothes or hair); empty: every mesh of its skin.
  std::vector<std::string> meshes;
  /// Skinned meshes of the same file drawn with the body but not collided with (hair, eyes,
  /// accessories), by node or mesh name; empty: none.
  std::vector<std::string> drawnMeshes;
  /// URL(s) of the motion it plays when a command gives it none (a BVH, AMC, or animated
  /// avatar file), relative to the scene; the first that exists is played. Empty: none.
  std::vector<std::string> motion;
  RigidTransform placement;           ///< m, world placement of the character's root
  double scale = 1.0;                 ///< the node's scale times unitScale
  SourcePos source;
};

/// Geometry that is neither avatar nor garment (the set, props): world metres.
struct Scenery {
  std::string name;
  mesh::TriMesh mesh;
};

struct Scene {
  std::string source;           ///< the scene file
  std::vector<Avatar> avatars;  ///< H-Anim humanoids, in file order
  std::vector<ExternalAvatar> externalAvatars;
  std::vector<Garment> garments;
  std::vector<ClothMaterial> materials;  ///< each ClothMaterial node once (DEF/USE shares)
  SimulationSettings simulation;
  bool hasSimulationNode = false;
  std::vector<Scenery> scenery;
  std::vector<std::string> warnings;  ///< "file:line: what"
};

/// Reads a VRML97 scene (through formats' isolated reader) and builds the scene. Throws
/// drape::Error (exit code 2) naming file and line for anything wrong: bad syntax, unknown
/// nodes or fields, missing Inline/EXTERNPROTO targets, a ClothSet without cloth,
/// impossible material values, a mask vertex matching no cloth vertex.
[[nodiscard]] Scene loadScene(const std::string& path);

/// Checks a material; throws "file:line: ClothMaterial NAME: what" for impossible values.
void validate(const ClothMaterial& material);
/// Checks simulation settings the same way.
void validate(const SimulationSettings& settings);
/// What is wrong with offset surfaces T0..T3 (m: finite, non-negative, non-decreasing), as
/// "offsets: ..."; "" when nothing is (a Simulation node's, a ClothSet's).
[[nodiscard]] std::string offsetsProblem(const std::array<double, 4>& offsets);

/// Per garment, its layer, given the garments each is worn over (indices, its `over`): 0
/// when it is worn over nothing, else one more than the highest layer of those; -1 where the
/// names go round (a over b over a), and for the garments worn over those. Garments step
/// layer by layer.
[[nodiscard]] std::vector<int> layersOf(const std::vector<std::vector<std::size_t>>& below);
/// A round in the `over` names, when layersOf left a garment at -1: garments each worn over
/// the next, the last the first again; empty when there is none.
[[nodiscard]] std::vector<std::size_t> roundOfLayers(const std::vector<std::vector<std::size_t>>& below,
                                                     const std::vector<int>& layers);

}  // namespace drape::scene
