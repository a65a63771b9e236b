#include "drape/mesh/trimesh.hpp"

namespace drape::mesh {

Aabb TriMesh::bounds() const {
  Aabb box;
  for (const Vec3& p : positions) box.extend(p);
  return box;
}

Vec3 TriMesh::triangleNormalArea(std::size_t t) const {
  const Triangle& tri = triangles[t];
  const Vec3& a = positions[tri[0]];
  return (positions[tri[1]] - a).cross(positions[tri[2]] - a);
}

double TriMesh::totalArea() const {
  double area = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) area += triangleArea(t);
  return area;
}

std::vector<Vec3> TriMesh::vertexNormals() const {
  std::vector<Vec3> normals;
  mesh::vertexNormals(positions, triangles, normals);
  return normals;
}

void vertexNormals(std::span<const Vec3> positions, std::span<const Triangle> triangles, std::vector<Vec3>& out) {
  out.assign(positions.size(), Vec3::Zero());
  for (const Triangle& t : triangles) {
    const Vec3 n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
    for (const std::uint32_t v : t) out[v] += n;
  }
  for (Vec3& n : out)
    if (const double len = n.norm(); len > 0) n /= len;
}

void TriMesh::scale(double factor) {
  for (Vec3& p : positions) p *= factor;
}

void TriMesh::transform(const RigidTransform& t) {
  for (Vec3& p : positions) p = t.apply(p);
}

void triangulatePolygon(const std::vector<std::uint32_t>& polygon, std::vector<Triangle>& out) {
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) out.push_back({polygon[0], polygon[i], polygon[i + 1]});
}

}  // namespace drape::mesh
