#pragma once
// Shared by the test modules: a binary glTF file drape wrote, read back with TinyGLTF, and
// its accessors' numbers (drape writes them tightly packed). Test modules that include this
// link TinyGLTF::TinyGLTF.

#include <tiny_gltf.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace drape::testing {

/// The .glb at `path`; throws std::runtime_error with TinyGLTF's message when it cannot be read.
inline tinygltf::Model loadGlb(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string err, warn;
  if (!loader.LoadBinaryFromFile(&model, &err, &warn, path)) throw std::runtime_error(path + ": " + err);
  return model;
}

/// Accessor `index`'s components, as `T` (float for drape's positions, times and weights).
template <typename T>
std::vector<T> accessorData(const tinygltf::Model& model, int index) {
  const tinygltf::Accessor& a = model.accessors.at(static_cast<std::size_t>(index));
  const tinygltf::BufferView& v = model.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  std::vector<T> out(a.count * static_cast<std::size_t>(tinygltf::GetNumComponentsInType(a.type)));
  std::memcpy(out.data(),
              model.buffers.at(static_cast<std::size_t>(v.buffer)).data.data() + v.byteOffset + a.byteOffset,
              out.size() * sizeof(T));
  return out;
}

}  // namespace drape::testing
