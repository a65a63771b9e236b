#pragma once
// Garments fitted to an avatar's rest pose: the skirt of the paper's walking scenario.

#include <string>
#include <vector>

#include "drape/mesh/generators.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

struct SkirtFit {
  std::string waistSegment = "LowerBack";  ///< the waist is at this segment's joint
  std::vector<std::string> hipSegments = {"Hips"};  ///< also cleared, also collidable
  std::vector<std::string> legSegments = {"LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"};
  double length_m = 0.0;       ///< waist to hem; 0: down to just above the knees' lower third
  double clearance_m = 0.02;   ///< gap between the body's outline and the skirt at rest
  double flare = 0.12;         ///< extra hem radius per metre of length (an A-line)
  int segments = 24;           ///< vertices around
  int rings = 10;              ///< bands from waist to hem (segments x rings x 2 triangles)
  /// The vertices of garments the skirt is worn over (m, world, at rest), and how far it
  /// keeps outside them: twice this below the waist, this at the waist (their waistbands lie
  /// at half their clearance too). Each ring clears them as well as the body's outline.
  std::vector<Vec3> wornOver;
  double wornOverGap_m = 0.0;
};

/// Fits a skirt to the avatar at rest: the waist ring wraps the waist segment at its
/// joint's height with half the clearance (the constraint mask binds it there), every lower ring clears the outline of the hips and legs at its
/// height (growing monotonically: cloth hangs, it does not hug), plus the flare. Throws
/// drape::Error naming the avatar if it has no such segments.
[[nodiscard]] mesh::Skirt fitSkirt(const Avatar& avatar, const SkirtFit& fit = {});

}  // namespace drape::scene

namespace drape::scene {

/// A MakeHuman garment refitted to the MakeHuman body drape builds (the hm08 base mesh as
/// the avatar's .mhskel finds it): each vertex placed by its .mhclo weights on the base mesh
/// plus its offset, scaled per axis as MakeHuman does. `modelled` is the garment's own OBJ
/// (its shape on whichever body it was exported on), `fitted` the same mesh on drape's body.
struct MakeHumanGarment {
  mesh::TriMesh modelled;  ///< m, as in the OBJ
  mesh::TriMesh fitted;    ///< m, on the avatar's rest pose
};

/// Reads MHCLO and its OBJ (the .mhclo's obj_file beside it, else the .obj of the same
/// name) and fits it to the base mesh next to `mhskelPath`. Throws drape::Error naming the
/// file when the two do not belong together (vertex counts, indices beyond the base mesh).
[[nodiscard]] MakeHumanGarment fitMakeHumanGarment(const std::string& mhcloPath, const std::string& mhskelPath);

}  // namespace drape::scene
