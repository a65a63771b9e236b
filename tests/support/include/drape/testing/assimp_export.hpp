#pragma once
// Shared by the test modules: a mesh file as another tool writes it. Assimp imports an OBJ
// (triangulated, identical vertices joined: a vertex stays split wherever its texture
// coordinates differ, as a renderer's file has it) and its exporters write it as glTF,
// Collada or FBX. Test modules that include this link assimp::assimp.

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <stdexcept>
#include <string>

namespace drape::testing {

struct Exported {
  unsigned vertices = 0;   ///< the vertices of the scene that was exported, over its meshes
  unsigned triangles = 0;
};

/// Writes `objPath` with its vertices scaled by `scale` to `outPath` with Assimp's
/// exporter `formatId` ("glb2", "gltf2", "collada", "fbxa", ...). Throws on failure.
inline Exported exportThroughAssimp(const std::string& objPath, double scale, const std::string& formatId,
                                    const std::string& outPath) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(objPath, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr) throw std::runtime_error(objPath + ": Assimp cannot import it: " + importer.GetErrorString());
  Exported out;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    aiMesh& mesh = *scene->mMeshes[m];
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) mesh.mVertices[v] *= static_cast<ai_real>(scale);
    out.vertices += mesh.mNumVertices;
    out.triangles += mesh.mNumFaces;
  }
  Assimp::Exporter exporter;
  if (exporter.Export(scene, formatId, outPath) != AI_SUCCESS)
    throw std::runtime_error(outPath + ": Assimp's " + formatId + " exporter failed: " + exporter.GetErrorString());
  return out;
}

/// Writes the file at `inPath`, imported by Assimp as it is (no processing), to `outPath`
/// with Assimp's exporter `formatId`: a skinned character as another tool converts it.
/// Throws on failure.
inline void convertThroughAssimp(const std::string& inPath, const std::string& formatId, const std::string& outPath) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(inPath, 0);
  if (scene == nullptr) throw std::runtime_error(inPath + ": Assimp cannot import it: " + importer.GetErrorString());
  Assimp::Exporter exporter;
  if (exporter.Export(scene, formatId, outPath) != AI_SUCCESS)
    throw std::runtime_error(outPath + ": Assimp's " + formatId + " exporter failed: " + exporter.GetErrorString());
}

}  // namespace drape::testing
