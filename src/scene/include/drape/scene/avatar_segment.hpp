#pragma once
// Segmenting a skinned character (paper section 4.2, done by hand there): each joint's
// segment is the set of triangles whose dominant skin weight is that joint; each
// segment's openings are capped so it is closed, and its vertices are moved into the
// joint's frame (unit scale, axes of the rest frame).

#include <cstdint>
#include <string>
#include <vector>

#include "drape/mesh/trimesh.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

/// For each triangle, the joint with the largest summed weight over its three vertices
/// (ties go to the lower joint index).
[[nodiscard]] std::vector<int> dominantJointPerTriangle(const SkinnedMesh& skin, std::size_t jointCount);

/// Closes every opening of `mesh`: each connected run of boundary edges gets a centre
/// vertex (the mean of its vertices) and one triangle per boundary edge, wound against
/// the edge's face. Returns the number of caps added.
std::size_t capOpenings(mesh::TriMesh& mesh);

/// Number of edges used by exactly one triangle.
[[nodiscard]] std::size_t countBoundaryEdges(const mesh::TriMesh& mesh);

/// Builds avatar.segments from avatar.skin (replacing any): one closed segment per joint
/// that dominates at least one triangle, named after the joint, in the joint's frame.
/// Returns, for each triangle of the skin, the index of the segment it went to.
///
/// `cutAtJoints` names joints whose segments are cut across their joint: a triangle the
/// joint dominates whose centroid lies behind the plane through the joint's centre, normal
/// to its bone (towards the mean of its children), goes to the parent joint's segment
/// instead. A rigid segment that reaches behind its joint (an upper arm's, over the top of
/// the shoulder) swings that part the other way as the joint turns, out through the skin of
/// its neighbour, where the skin itself, blended between the two bones, stays; so cut, the
/// parent carries it. `cutTriangles`, when given, receives how many triangles went to a
/// parent. Throws drape::Error naming the joint when one is not the avatar's, is the root
/// or has no children, and when the avatar has no skinned mesh to cut.
std::vector<int> segmentSkinnedAvatar(Avatar& avatar, const std::vector<std::string>& cutAtJoints = {},
                                      std::size_t* cutTriangles = nullptr);

}  // namespace drape::scene
