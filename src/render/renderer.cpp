#include "drape/render/renderer.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/mesh/surface_distance.hpp"
#include "gl_util.hpp"

namespace drape::render {
namespace {

using Mat4 = Eigen::Matrix4f;
using V3 = Eigen::Vector3f;

// Colours are given in sRGB (as a person picks them) and lit in linear space.
constexpr std::array<float, 3> kGarmentSrgb = {0.80f, 0.22f, 0.25f};  // a warm red cloth
constexpr std::array<float, 3> kSegmentSrgb = {0.80f, 0.74f, 0.68f};  // clay-coloured body
constexpr std::array<float, 3> kDrawnSrgb = {0.36f, 0.31f, 0.28f};    // its hair and eyes, a darker clay
constexpr std::array<float, 3> kBackgroundTop = {44.f, 50.f, 62.f};   // 0-255
constexpr std::array<float, 3> kBackgroundBottom = {120.f, 128.f, 140.f};

// ---------------------------------------------------------------------------------------
// Shaders. One lit program for meshes (also shadows and offset shells, by uMode), one for
// the floor grid, one for the background, one for markers, one for the slice plane.

constexpr const char* kMeshVs = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in uint aState;
uniform mat4 uViewProj;
uniform mat4 uModel;
uniform float uInflate;
out vec3 vWorld;
out vec3 vNormal;
flat out uint vState;
void main() {
  vec4 w = uModel * vec4(aPos + uInflate * aNormal, 1.0);
  vWorld = w.xyz / w.w;
  vNormal = aNormal;
  vState = aState;
  gl_Position = uViewProj * w;
}
)";

constexpr const char* kMeshFs = R"(#version 330 core
in vec3 vWorld;
in vec3 vNormal;
flat in uint vState;
uniform int uMode;          // 0 lit, 1 flat colour (shadows), 2 lit translucent shell
uniform vec3 uColour;       // linear RGB
uniform float uAlpha;
uniform vec3 uEye;
uniform vec3 uLight;        // towards the key light
uniform bool uStateColours;
out vec4 fragColour;

vec3 stateColour(uint s) {
  if (s == 1u) return vec3(0.95, 0.55, 0.02);  // inside a volume
  if (s == 2u) return vec3(0.05, 0.65, 0.10);  // on the collision surface
  if (s == 3u) return vec3(0.75, 0.02, 0.60);  // penalty zone
  return vec3(0.10, 0.25, 0.70);               // outside
}

void main() {
  if (uMode == 1) { fragColour = vec4(uColour, uAlpha); return; }
  vec3 n = normalize(vNormal);
  vec3 v = normalize(uEye - vWorld);
  // Two-sided, by the triangle's own facing: cloth shows both sides. Flipping by the
  // smoothed normal instead turned every fragment whose interpolated normal leans away from
  // the camera (at silhouettes, in creases such as under the breasts) towards the key light,
  // as bright specks among its neighbours.
  if (!gl_FrontFacing) n = -n;
  // Where the smoothed normal still leans away (a front face at a silhouette), shade it as
  // the silhouette it is: the normal turned until it is square to the view.
  float nv = dot(n, v);
  if (nv < 0.0) n = normalize(n - nv * v);
  vec3 base = uStateColours ? stateColour(vState & 3u) : uColour;
  vec3 l = normalize(uLight);
  float key = max(dot(n, l), 0.0);
  float fill = max(dot(n, normalize(vec3(-l.x, 0.3, -l.z))), 0.0);
  vec3 sky = mix(vec3(0.10, 0.09, 0.09), vec3(0.30, 0.34, 0.42), 0.5 + 0.5 * n.y);
  float spec = pow(max(dot(n, normalize(l + v)), 0.0), 40.0) * 0.10;
  float rim = pow(1.0 - max(dot(n, v), 0.0), 3.0) * 0.20;
  vec3 c = base * (sky + key * vec3(1.00, 0.95, 0.88) * 0.95 + fill * vec3(0.45, 0.55, 0.70) * 0.30)
         + vec3(spec) + rim * vec3(0.55, 0.65, 0.85) * 0.5;
  c = c / (1.0 + 0.20 * c);  // a soft shoulder instead of clipping highlights
  fragColour = vec4(pow(c, vec3(1.0 / 2.2)), uMode == 2 ? uAlpha : 1.0);
}
)";

constexpr const char* kGridVs = R"(#version 330 core
layout(location = 0) in vec2 aCorner;
uniform mat4 uViewProj;
uniform vec3 uCentre;
uniform float uRadius;
out vec3 vWorld;
void main() {
  vWorld = vec3(uCentre.x + aCorner.x * uRadius, uCentre.y, uCentre.z + aCorner.y * uRadius);
  gl_Position = uViewProj * vec4(vWorld, 1.0);
}
)";

constexpr const char* kGridFs = R"(#version 330 core
in vec3 vWorld;
uniform vec3 uCentre;
uniform float uRadius;
uniform float uSpacing;
out vec4 fragColour;
float lines(vec2 coord) {
  vec2 g = abs(fract(coord - 0.5) - 0.5) / max(fwidth(coord), vec2(1e-6));
  return 1.0 - min(min(g.x, g.y), 1.0);
}
void main() {
  vec2 coord = vWorld.xz / uSpacing;
  float minor = lines(coord);
  float major = lines(coord / 5.0);
  float d = length(vWorld.xz - uCentre.xz) / uRadius;
  float fade = 1.0 - smoothstep(0.15, 1.0, d);
  vec3 floorColour = vec3(0.60, 0.62, 0.65);
  vec3 c = mix(floorColour, vec3(0.42, 0.44, 0.48), max(minor * 0.35, major * 0.8));
  fragColour = vec4(c, fade);
}
)";

constexpr const char* kBackgroundVs = R"(#version 330 core
const vec2 corners[3] = vec2[3](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
void main() { gl_Position = vec4(corners[gl_VertexID], 0.0, 1.0); }
)";

constexpr const char* kBackgroundFs = R"(#version 330 core
uniform vec3 uTop;
uniform vec3 uBottom;
uniform float uHeight;
out vec4 fragColour;
void main() { fragColour = vec4(mix(uBottom, uTop, gl_FragCoord.y / uHeight) / 255.0, 1.0); }
)";

constexpr const char* kMarkerVs = R"(#version 330 core
layout(location = 0) in vec3 aPos;
layout(location = 2) in uint aState;
uniform mat4 uViewProj;
uniform float uPointSize;
flat out uint vState;
void main() {
  vState = aState;
  if ((aState & 12u) == 0u) { gl_Position = vec4(2.0, 2.0, 2.0, 1.0); gl_PointSize = 1.0; return; }
  gl_Position = uViewProj * vec4(aPos, 1.0);
  gl_Position.z -= 0.002 * gl_Position.w;  // stay in front of the surface they sit on
  gl_PointSize = uPointSize;
}
)";

constexpr const char* kMarkerFs = R"(#version 330 core
flat in uint vState;
out vec4 fragColour;
void main() {
  vec2 p = gl_PointCoord * 2.0 - 1.0;
  float r = dot(p, p);
  if (r > 1.0) discard;
  vec3 c = (vState & 4u) != 0u ? vec3(1.0, 0.85, 0.1) : vec3(0.1, 0.9, 0.95);
  fragColour = vec4(mix(c, vec3(0.05), smoothstep(0.55, 1.0, r)), 1.0);
}
)";

constexpr const char* kSliceVs = R"(#version 330 core
layout(location = 0) in vec2 aCorner;
uniform mat4 uViewProj;
uniform vec3 uMin;   // corner of the slice (x, y, z)
uniform vec2 uSize;  // extent along x and z
out vec2 vUv;
void main() {
  vUv = aCorner * 0.5 + 0.5;
  gl_Position = uViewProj * vec4(uMin.x + vUv.x * uSize.x, uMin.y, uMin.z + vUv.y * uSize.y, 1.0);
}
)";

constexpr const char* kSliceFs = R"(#version 330 core
in vec2 vUv;
uniform sampler2D uDistance;  // m, negative inside
uniform vec3 uOffsets;        // T1, T2, T3 in m
uniform float uBand;          // m between iso lines
out vec4 fragColour;
float contour(float d, float level) {
  float w = fwidth(d);
  return 1.0 - smoothstep(0.0, 1.5 * w, abs(d - level));
}
void main() {
  float d = texture(uDistance, vUv).r;
  vec3 c = d < 0.0 ? mix(vec3(0.9, 0.3, 0.2), vec3(0.5, 0.05, 0.05), clamp(-d / (4.0 * uBand), 0.0, 1.0))
                   : mix(vec3(0.3, 0.6, 0.95), vec3(0.05, 0.1, 0.35), clamp(d / (10.0 * uBand), 0.0, 1.0));
  float bands = contour(fract(d / uBand + 0.5) - 0.5, 0.0) * 0.35;
  c = mix(c, vec3(0.0), bands);
  c = mix(c, vec3(1.0), contour(d, 0.0));
  c = mix(c, vec3(1.0, 0.3, 1.0), contour(d, uOffsets.x));
  c = mix(c, vec3(0.3, 1.0, 0.3), contour(d, uOffsets.y));
  c = mix(c, vec3(0.3, 0.8, 1.0), contour(d, uOffsets.z));
  fragColour = vec4(c, 0.8);
}
)";

// ---------------------------------------------------------------------------------------
// Camera and geometry helpers.

Mat4 lookAt(const V3& eye, const V3& target, const V3& up) {
  const V3 f = (target - eye).normalized();
  const V3 s = f.cross(up).normalized();
  const V3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 perspective(float fovY, float aspect, float zNear, float zFar) {
  const float t = 1.0f / std::tan(0.5f * fovY);
  Mat4 m = Mat4::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (zFar + zNear) / (zNear - zFar);
  m(2, 3) = 2.0f * zFar * zNear / (zNear - zFar);
  m(3, 2) = -1.0f;
  return m;
}

/// Projects points along the directional light `l` (towards the light) onto the plane y = h.
Mat4 planarShadow(const V3& l, float h) {
  const Eigen::Vector4f plane(0.0f, 1.0f, 0.0f, -h);
  const Eigen::Vector4f light(l.x(), l.y(), l.z(), 0.0f);
  return plane.dot(light) * Mat4::Identity() - light * plane.transpose();
}

V3 srgbToLinear(const std::array<float, 3>& c) {
  return V3(std::pow(c[0], 2.2f), std::pow(c[1], 2.2f), std::pow(c[2], 2.2f));
}

/// Direction towards the key light: above, in front and to the left of the camera, so the
/// shadow falls behind and to the right where the floor shows it.
V3 keyLight(const ViewSettings& view) {
  const double az = (view.azimuthDeg + 40.0) * std::numbers::pi / 180.0;
  return V3(static_cast<float>(std::sin(az) * 0.55), 1.0f, static_cast<float>(std::cos(az) * 0.55)).normalized();
}

struct GpuMesh {
  GLuint vao = 0;
  GLuint positions = 0;
  GLuint normals = 0;
  GLuint states = 0;
  GLuint indices = 0;
  GLsizei indexCount = 0;
  bool hasStates = false;
};

}  // namespace

std::array<float, 3> backgroundColour(double v) {
  std::array<float, 3> c{};
  for (int i = 0; i < 3; ++i)
    c[i] = static_cast<float>(kBackgroundBottom[i] + (kBackgroundTop[i] - kBackgroundBottom[i]) * v);
  return c;
}

CameraMatrices cameraFor(const Aabb& boundsIn, const ViewSettings& view, double aspect) {
  const Aabb bounds = boundsIn.empty() ? Aabb{Vec3(-0.5, 0, -0.5), Vec3(0.5, 1, 0.5)} : boundsIn;
  Vec3 aim = bounds.center();
  aim.y() = bounds.min.y() + std::clamp(view.aimHeight, 0.0, 1.0) * bounds.size().y();
  const V3 centre = aim.cast<float>();
  const float radius = std::max(0.05f, 0.5f * static_cast<float>(bounds.size().norm()));
  const float fovY = static_cast<float>(view.fovYDeg * std::numbers::pi / 180.0);
  const float halfX = std::atan(std::tan(0.5f * fovY) * static_cast<float>(aspect));
  const float half = std::min(0.5f * fovY, halfX);
  const float distance = radius / std::sin(half) / static_cast<float>(std::max(view.zoom, 0.05)) * 1.02f;
  const double az = view.azimuthDeg * std::numbers::pi / 180.0;
  const double el = std::clamp(view.elevationDeg, -89.0, 89.0) * std::numbers::pi / 180.0;
  const V3 dir(static_cast<float>(std::sin(az) * std::cos(el)), static_cast<float>(std::sin(el)),
               static_cast<float>(std::cos(az) * std::cos(el)));
  CameraMatrices cam;
  cam.eye = centre + distance * dir;
  cam.view = lookAt(cam.eye, centre, V3::UnitY());
  const float zNear = std::max(0.01f * distance, distance - 2.0f * radius);
  const float zFar = distance + 12.0f * radius;
  cam.projection = perspective(fovY, static_cast<float>(aspect), zNear, zFar);
  return cam;
}

// ---------------------------------------------------------------------------------------

struct Renderer::Impl {
  std::vector<MeshInfo> meshes;
  std::vector<std::uint8_t> skinned;  ///< per mesh: its character's skinned body is in the run
  std::vector<GpuMesh> gpu;
  std::vector<std::vector<float>> positions;  ///< per mesh, xyz float (uploaded)
  std::vector<std::vector<float>> normals;    ///< per mesh, xyz float, area-weighted, unit
  Frame frame;                                ///< the current frame (for the slice)
  Aabb frameBounds;
  std::uint64_t generation = 0;                                                  ///< counts setFrame calls
  std::tuple<std::uint64_t, int, double, bool> sliceKey{~0ull, -1, 0.0, false};  ///< what the slice texture shows
  GLuint meshProgram = 0, gridProgram = 0, backgroundProgram = 0, markerProgram = 0, sliceProgram = 0;
  GLuint quadVao = 0, quadVbo = 0, emptyVao = 0, sliceTexture = 0;

  void createPrograms() {
    meshProgram = gl::buildProgram(kMeshVs, kMeshFs, "mesh");
    gridProgram = gl::buildProgram(kGridVs, kGridFs, "floor grid");
    backgroundProgram = gl::buildProgram(kBackgroundVs, kBackgroundFs, "background");
    markerProgram = gl::buildProgram(kMarkerVs, kMarkerFs, "marker");
    sliceProgram = gl::buildProgram(kSliceVs, kSliceFs, "slice");
  }

  void createQuad() {
    const float corners[] = {-1, -1, 1, -1, 1, 1, -1, -1, 1, 1, -1, 1};
    glGenVertexArrays(1, &quadVao);
    glBindVertexArray(quadVao);
    glGenBuffers(1, &quadVbo);
    glBindBuffer(GL_ARRAY_BUFFER, quadVbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenVertexArrays(1, &emptyVao);
    glGenTextures(1, &sliceTexture);
    glBindTexture(GL_TEXTURE_2D, sliceTexture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindVertexArray(0);
  }

  void createMesh(const MeshInfo& info, GpuMesh& g) {
    for (const mesh::Triangle& t : info.triangles) {
      if (t[0] >= info.vertexCount || t[1] >= info.vertexCount || t[2] >= info.vertexCount) {
        throw Error(fmt::format("mesh '{}': a triangle refers to a vertex beyond its {} vertices", info.name,
                                info.vertexCount));
      }
    }
    const auto vertexBytes = static_cast<GLsizeiptr>(info.vertexCount * 3 * sizeof(float));
    glGenVertexArrays(1, &g.vao);
    glBindVertexArray(g.vao);
    glGenBuffers(1, &g.positions);
    glBindBuffer(GL_ARRAY_BUFFER, g.positions);
    glBufferData(GL_ARRAY_BUFFER, vertexBytes, nullptr, GL_DYNAMIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &g.normals);
    glBindBuffer(GL_ARRAY_BUFFER, g.normals);
    glBufferData(GL_ARRAY_BUFFER, vertexBytes, nullptr, GL_DYNAMIC_DRAW);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenBuffers(1, &g.states);
    glBindBuffer(GL_ARRAY_BUFFER, g.states);
    const std::vector<std::uint8_t> zeros(info.vertexCount, 0);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(zeros.size()), zeros.data(), GL_DYNAMIC_DRAW);
    glEnableVertexAttribArray(2);
    glVertexAttribIPointer(2, 1, GL_UNSIGNED_BYTE, 0, nullptr);
    glGenBuffers(1, &g.indices);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(info.triangles.size() * sizeof(mesh::Triangle)),
                 info.triangles.data(), GL_STATIC_DRAW);
    g.indexCount = static_cast<GLsizei>(info.triangles.size() * 3);
    glBindVertexArray(0);
  }

  /// Area-weighted vertex normals of mesh m from its current float positions.
  void computeNormals(std::size_t m) {
    const std::vector<float>& p = positions[m];
    std::vector<float>& n = normals[m];
    std::fill(n.begin(), n.end(), 0.0f);
    for (const mesh::Triangle& t : meshes[m].triangles) {
      const V3 a(p[3 * t[0]], p[3 * t[0] + 1], p[3 * t[0] + 2]);
      const V3 b(p[3 * t[1]], p[3 * t[1] + 1], p[3 * t[1] + 2]);
      const V3 c(p[3 * t[2]], p[3 * t[2] + 1], p[3 * t[2] + 2]);
      const V3 fn = (b - a).cross(c - a);
      for (std::uint32_t v : t)
        for (int k = 0; k < 3; ++k) n[3 * v + k] += fn[k];
    }
    for (std::size_t v = 0; v < meshes[m].vertexCount; ++v) {
      Eigen::Map<V3> nv(&n[3 * v]);
      const float len = nv.norm();
      if (len > 0.0f) nv /= len;
    }
  }

  void drawBackground(int height) {
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glUseProgram(backgroundProgram);
    glUniform3f(glGetUniformLocation(backgroundProgram, "uTop"), kBackgroundTop[0], kBackgroundTop[1],
                kBackgroundTop[2]);
    glUniform3f(glGetUniformLocation(backgroundProgram, "uBottom"), kBackgroundBottom[0], kBackgroundBottom[1],
                kBackgroundBottom[2]);
    glUniform1f(glGetUniformLocation(backgroundProgram, "uHeight"), static_cast<float>(height));
    glBindVertexArray(emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthMask(GL_TRUE);
    glEnable(GL_DEPTH_TEST);
  }

  /// The floor: a grid disc under the lowest point, fading into the background. It marks
  /// the stencil so shadows land on it only.
  void drawFloor(const Mat4& viewProj, const Aabb& bounds, float floorY) {
    const float extent = std::max(0.5f, static_cast<float>(bounds.size().maxCoeff()));
    const float spacing = std::pow(10.0f, std::floor(std::log10(extent))) / 10.0f;  // 10 cm lines for a person
    const V3 c = bounds.center().cast<float>();
    glUseProgram(gridProgram);
    glUniformMatrix4fv(glGetUniformLocation(gridProgram, "uViewProj"), 1, GL_FALSE, viewProj.data());
    glUniform3f(glGetUniformLocation(gridProgram, "uCentre"), c.x(), floorY, c.z());
    glUniform1f(glGetUniformLocation(gridProgram, "uRadius"), extent * 4.0f);
    glUniform1f(glGetUniformLocation(gridProgram, "uSpacing"), spacing);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_ALWAYS, 1, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    glDepthMask(GL_FALSE);
    glBindVertexArray(quadVao);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glDepthMask(GL_TRUE);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
  }

  void setMeshUniforms(const Mat4& viewProj, const Mat4& model, const CameraMatrices& cam, const V3& light) {
    glUseProgram(meshProgram);
    glUniformMatrix4fv(glGetUniformLocation(meshProgram, "uViewProj"), 1, GL_FALSE, viewProj.data());
    glUniformMatrix4fv(glGetUniformLocation(meshProgram, "uModel"), 1, GL_FALSE, model.data());
    glUniform3fv(glGetUniformLocation(meshProgram, "uEye"), 1, cam.eye.data());
    glUniform3fv(glGetUniformLocation(meshProgram, "uLight"), 1, light.data());
    glUniform1f(glGetUniformLocation(meshProgram, "uInflate"), 0.0f);
  }

  /// Planar shadows: every mesh flattened onto the floor along the light, blended once per
  /// pixel (the stencil goes from 1 to 2 on the first hit) so overlaps do not darken twice.
  /// Whether mesh m is drawn: the skinned body and its drawn meshes, or the segments when
  /// the run has no skin or the overlay asks for them.
  bool drawn(std::size_t m, const OverlaySettings& overlay) const {
    switch (meshes[m].role) {
      case MeshRole::Garment:
        return true;
      case MeshRole::Skin:
      case MeshRole::Drawn:
        return !overlay.segments;
      case MeshRole::Segment:
        return overlay.segments || !skinned[m];
    }
    return true;
  }

  void drawShadows(const Mat4& viewProj, const CameraMatrices& cam, const V3& light, float floorY,
                   const OverlaySettings& overlay) {
    setMeshUniforms(viewProj, planarShadow(light, floorY + 1e-4f), cam, light);
    glUniform1i(glGetUniformLocation(meshProgram, "uMode"), 1);
    glUniform3f(glGetUniformLocation(meshProgram, "uColour"), 0.05f, 0.06f, 0.08f);
    glUniform1f(glGetUniformLocation(meshProgram, "uAlpha"), 0.35f);
    glUniform1i(glGetUniformLocation(meshProgram, "uStateColours"), 0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_EQUAL, 1, 0xff);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    glDepthMask(GL_FALSE);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(-1.0f, -1.0f);
    for (std::size_t m = 0; m < gpu.size(); ++m) {
      if (!drawn(m, overlay)) continue;
      glBindVertexArray(gpu[m].vao);
      glDrawElements(GL_TRIANGLES, gpu[m].indexCount, GL_UNSIGNED_INT, nullptr);
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDepthMask(GL_TRUE);
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
  }

  void drawMeshes(const Mat4& viewProj, const CameraMatrices& cam, const V3& light, const OverlaySettings& overlay) {
    setMeshUniforms(viewProj, Mat4::Identity(), cam, light);
    glUniform1i(glGetUniformLocation(meshProgram, "uMode"), 0);
    glUniform1f(glGetUniformLocation(meshProgram, "uAlpha"), 1.0f);
    for (std::size_t m = 0; m < gpu.size(); ++m) {
      if (!drawn(m, overlay)) continue;
      const bool garment = meshes[m].role == MeshRole::Garment;
      const std::optional<Vec3>& own = meshes[m].colour;
      // A garment in its scene's colour; the bodies in clay, their drawn meshes darker.
      const V3 colour = srgbToLinear(
          garment && own ? std::array<float, 3>{static_cast<float>(own->x()), static_cast<float>(own->y()),
                                                static_cast<float>(own->z())}
          : garment      ? kGarmentSrgb
          : meshes[m].role == MeshRole::Drawn ? kDrawnSrgb
                                              : kSegmentSrgb);
      glUniform3fv(glGetUniformLocation(meshProgram, "uColour"), 1, colour.data());
      glUniform1i(glGetUniformLocation(meshProgram, "uStateColours"), garment && overlay.collisionColours ? 1 : 0);
      glBindVertexArray(gpu[m].vao);
      glDrawElements(GL_TRIANGLES, gpu[m].indexCount, GL_UNSIGNED_INT, nullptr);
    }
  }

  /// Offset surfaces T1-T3 of every segment: its mesh pushed out along the vertex normals,
  /// drawn as translucent shells, outermost first.
  void drawOffsetSurfaces(const Mat4& viewProj, const CameraMatrices& cam, const V3& light,
                          const OverlaySettings& overlay) {
    static constexpr std::array<std::array<float, 3>, 3> kShellSrgb = {
        {{0.9f, 0.3f, 0.9f}, {0.3f, 0.9f, 0.3f}, {0.3f, 0.7f, 1.0f}}};
    setMeshUniforms(viewProj, Mat4::Identity(), cam, light);
    glUniform1i(glGetUniformLocation(meshProgram, "uMode"), 2);
    glUniform1f(glGetUniformLocation(meshProgram, "uAlpha"), 0.18f);
    glUniform1i(glGetUniformLocation(meshProgram, "uStateColours"), 0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_CULL_FACE);
    glDepthMask(GL_FALSE);
    for (int shell = 2; shell >= 0; --shell) {
      const V3 colour = srgbToLinear(kShellSrgb[static_cast<std::size_t>(shell)]);
      glUniform3fv(glGetUniformLocation(meshProgram, "uColour"), 1, colour.data());
      glUniform1f(glGetUniformLocation(meshProgram, "uInflate"),
                  static_cast<float>(overlay.offsets_m[static_cast<std::size_t>(shell)]));
      for (std::size_t m = 0; m < gpu.size(); ++m) {
        if (meshes[m].role != MeshRole::Segment) continue;
        glBindVertexArray(gpu[m].vao);
        glDrawElements(GL_TRIANGLES, gpu[m].indexCount, GL_UNSIGNED_INT, nullptr);
      }
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
  }

  void drawMarkers(const Mat4& viewProj, int height) {
    glUseProgram(markerProgram);
    glUniformMatrix4fv(glGetUniformLocation(markerProgram, "uViewProj"), 1, GL_FALSE, viewProj.data());
    glUniform1f(glGetUniformLocation(markerProgram, "uPointSize"), std::max(4.0f, static_cast<float>(height) / 120.0f));
    glEnable(GL_PROGRAM_POINT_SIZE);
    for (std::size_t m = 0; m < gpu.size(); ++m) {
      if (meshes[m].role != MeshRole::Garment || !gpu[m].hasStates) continue;
      glBindVertexArray(gpu[m].vao);
      glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(meshes[m].vertexCount));
    }
    glDisable(GL_PROGRAM_POINT_SIZE);
  }

  int slicePart(const OverlaySettings& overlay) const {
    if (overlay.slicePart >= 0 && static_cast<std::size_t>(overlay.slicePart) < meshes.size()) return overlay.slicePart;
    for (std::size_t m = 0; m < meshes.size(); ++m)
      if (meshes[m].role == MeshRole::Segment) return static_cast<int>(m);
    return -1;
  }

  /// A horizontal plane through the chosen part, coloured by its distance (white: the
  /// surface, then T1, T2, T3 contours, dark bands every centimetre or so).
  void drawDistanceSlice(const Mat4& viewProj, const OverlaySettings& overlay) {
    const int part = slicePart(overlay);
    if (part < 0 || frame.positions.size() <= static_cast<std::size_t>(part)) return;
    Aabb box;
    for (const Vec3& p : frame.positions[static_cast<std::size_t>(part)]) box.extend(p);
    if (box.empty()) return;
    const double margin = std::max(0.05, 0.5 * std::max(box.size().x(), box.size().z()));
    const double y = box.min.y() + std::clamp(overlay.sliceHeight, 0.0, 1.0) * box.size().y();
    const Vec3 lo(box.min.x() - margin, y, box.min.z() - margin);
    const Vec3 size(box.size().x() + 2 * margin, 0.0, box.size().z() + 2 * margin);
    // Sample the distances only when the frame or the slice changed (the window redraws
    // far more often than frames arrive).
    const auto key = std::make_tuple(generation, part, overlay.sliceHeight, static_cast<bool>(overlay.sliceDistance));
    glBindTexture(GL_TEXTURE_2D, sliceTexture);
    if (key != sliceKey) {
      sliceKey = key;
      constexpr int kCells = 96;
      std::vector<float> distance(kCells * kCells);
      // Without the collision's field, the exact distance to the part's triangles as drawn.
      std::optional<mesh::SurfaceDistance> surface;
      if (!overlay.sliceDistance)
        surface.emplace(frame.positions[static_cast<std::size_t>(part)], meshes[static_cast<std::size_t>(part)].triangles);
      for (int j = 0; j < kCells; ++j) {
        for (int i = 0; i < kCells; ++i) {
          const Vec3 p(lo.x() + (i + 0.5) / kCells * size.x(), y, lo.z() + (j + 0.5) / kCells * size.z());
          const double d = surface ? surface->at(p).distance_m : overlay.sliceDistance(p);
          distance[static_cast<std::size_t>(j * kCells + i)] = static_cast<float>(d);
        }
      }
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, kCells, kCells, 0, GL_RED, GL_FLOAT, distance.data());
    }
    glUseProgram(sliceProgram);
    glUniformMatrix4fv(glGetUniformLocation(sliceProgram, "uViewProj"), 1, GL_FALSE, viewProj.data());
    glUniform3f(glGetUniformLocation(sliceProgram, "uMin"), static_cast<float>(lo.x()), static_cast<float>(lo.y()),
                static_cast<float>(lo.z()));
    glUniform2f(glGetUniformLocation(sliceProgram, "uSize"), static_cast<float>(size.x()),
                static_cast<float>(size.z()));
    glUniform3f(glGetUniformLocation(sliceProgram, "uOffsets"), static_cast<float>(overlay.offsets_m[0]),
                static_cast<float>(overlay.offsets_m[1]), static_cast<float>(overlay.offsets_m[2]));
    glUniform1f(glGetUniformLocation(sliceProgram, "uBand"), static_cast<float>(std::max(0.005, margin / 5.0)));
    glUniform1i(glGetUniformLocation(sliceProgram, "uDistance"), 0);
    glActiveTexture(GL_TEXTURE0);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindVertexArray(quadVao);
    glDrawArrays(GL_TRIANGLES, 0, 6);
    glDisable(GL_BLEND);
  }
};

Renderer::Renderer(std::vector<MeshInfo> meshes) : impl_(std::make_unique<Impl>()) {
  gl::requireGl33("renderer");
  impl_->meshes = std::move(meshes);
  impl_->skinned.clear();
  for (const MeshInfo& m : impl_->meshes) impl_->skinned.push_back(hasSkin(impl_->meshes, m.character) ? 1 : 0);
  impl_->createPrograms();
  impl_->createQuad();
  impl_->gpu.resize(impl_->meshes.size());
  impl_->positions.resize(impl_->meshes.size());
  impl_->normals.resize(impl_->meshes.size());
  for (std::size_t m = 0; m < impl_->meshes.size(); ++m) {
    impl_->createMesh(impl_->meshes[m], impl_->gpu[m]);
    impl_->positions[m].assign(impl_->meshes[m].vertexCount * 3, 0.0f);
    impl_->normals[m].assign(impl_->meshes[m].vertexCount * 3, 0.0f);
  }
}

Renderer::~Renderer() {
  for (GpuMesh& g : impl_->gpu) {
    const GLuint buffers[] = {g.positions, g.normals, g.states, g.indices};
    glDeleteBuffers(4, buffers);
    glDeleteVertexArrays(1, &g.vao);
  }
  glDeleteBuffers(1, &impl_->quadVbo);
  glDeleteVertexArrays(1, &impl_->quadVao);
  glDeleteVertexArrays(1, &impl_->emptyVao);
  glDeleteTextures(1, &impl_->sliceTexture);
  for (GLuint p :
       {impl_->meshProgram, impl_->gridProgram, impl_->backgroundProgram, impl_->markerProgram, impl_->sliceProgram})
    glDeleteProgram(p);
}

const std::vector<MeshInfo>& Renderer::meshes() const { return impl_->meshes; }

void Renderer::setFrame(const Frame& frame) {
  Impl& s = *impl_;
  if (frame.positions.size() != s.meshes.size()) {
    throw Error(fmt::format("frame {} has positions for {} meshes, the run has {}", frame.index, frame.positions.size(),
                            s.meshes.size()),
                ExitCode::Internal);
  }
  s.frame = frame;
  s.frameBounds = frameBounds(frame);
  ++s.generation;
  for (std::size_t m = 0; m < s.meshes.size(); ++m) {
    const std::vector<Vec3>& x = frame.positions[m];
    if (x.size() != s.meshes[m].vertexCount) {
      throw Error(fmt::format("frame {}: mesh '{}' has {} positions, its topology {} vertices", frame.index,
                              s.meshes[m].name, x.size(), s.meshes[m].vertexCount),
                  ExitCode::Internal);
    }
    std::vector<float>& p = s.positions[m];
    for (std::size_t v = 0; v < x.size(); ++v)
      for (int k = 0; k < 3; ++k) p[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(x[v][k]);
    s.computeNormals(m);
    const auto bytes = static_cast<GLsizeiptr>(p.size() * sizeof(float));
    glBindBuffer(GL_ARRAY_BUFFER, s.gpu[m].positions);
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, p.data());
    glBindBuffer(GL_ARRAY_BUFFER, s.gpu[m].normals);
    glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, s.normals[m].data());
    const bool states = m < frame.states.size() && frame.states[m].size() == x.size();
    if (states) {
      glBindBuffer(GL_ARRAY_BUFFER, s.gpu[m].states);
      glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(x.size()), frame.states[m].data());
    } else if (s.gpu[m].hasStates) {
      const std::vector<std::uint8_t> zeros(x.size(), 0);
      glBindBuffer(GL_ARRAY_BUFFER, s.gpu[m].states);
      glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(x.size()), zeros.data());
    }
    s.gpu[m].hasStates = states;
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

CameraMatrices Renderer::camera(int width, int height, const ViewSettings& view) const {
  const Aabb bounds = view.bounds ? *view.bounds : impl_->frameBounds;
  return cameraFor(bounds, view, static_cast<double>(width) / std::max(1, height));
}

void Renderer::draw(int width, int height, const ViewSettings& view, const OverlaySettings& overlay) {
  Impl& s = *impl_;
  const Aabb bounds = view.bounds ? *view.bounds : s.frameBounds;
  const CameraMatrices cam = camera(width, height, view);
  const Mat4 viewProj = cam.viewProjection();
  const V3 light = keyLight(view);
  const float floorY = bounds.empty() ? 0.0f : static_cast<float>(bounds.min.y());

  glViewport(0, 0, width, height);
  glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);

  s.drawBackground(height);                                  // sky gradient
  if (overlay.floor) s.drawFloor(viewProj, bounds, floorY);  // grid, marks stencil
  if (overlay.floor && overlay.shadows) s.drawShadows(viewProj, cam, light, floorY, overlay);
  s.drawMeshes(viewProj, cam, light, overlay);                                      // bodies and cloth
  if (overlay.markers) s.drawMarkers(viewProj, height);                             // pinned / bound
  if (overlay.distanceSlice) s.drawDistanceSlice(viewProj, overlay);                // field slice
  if (overlay.offsetSurfaces) s.drawOffsetSurfaces(viewProj, cam, light, overlay);  // T1-T3 shells
  glBindVertexArray(0);
  glUseProgram(0);
}

}  // namespace drape::render
