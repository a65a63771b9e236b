#pragma once
// The OpenGL 3.3 core renderer: one set of shaders for the window (`drape play`) and the
// headless path (EGL surfaceless, `drape render`). It draws avatar segments in the body
// colour, garments with per-frame normals and two-sided lighting, a floor grid with planar
// shadows, and the overlays (collision-state colours, offset surfaces T1-T3, a distance
// slice plane, pinned/bound markers). No GL type leaks out of this header.

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/render/frame.hpp"

namespace drape::render {

/// Where the camera is. It always looks at the centre of `bounds` (or of the frame's own
/// bounds) from far enough away to see all of it, then orbits and zooms from there.
struct ViewSettings {
  double azimuthDeg = 30.0;    ///< orbit angle about +Y; 0 looks along -Z (from the front, +Z side)
  double elevationDeg = 12.0;  ///< angle above the horizon
  double zoom = 1.0;           ///< > 1 moves closer
  /// Height the camera aims at, as a fraction of what it frames (0 its bottom, 1 its top):
  /// with a zoom, what stays in the picture (0.85 keeps a standing person's shoulders).
  double aimHeight = 0.5;
  double fovYDeg = 35.0;
  std::optional<Aabb> bounds;  ///< m; what to frame (a replay passes the whole run's bounds)
};

/// A signed distance (m, negative inside) from a body part, for the distance slice overlay.
/// The collision work supplies the real field; without one the renderer measures the
/// distance to the segment's triangles by brute force.
using DistanceFunction = std::function<double(const Vec3& world)>;

struct OverlaySettings {
  bool floor = true;              ///< floor grid under the lowest point of the run
  bool shadows = true;            ///< planar shadows of every mesh on the floor
  bool collisionColours = false;  ///< colour garment vertices by vertex_state collision bits
  bool offsetSurfaces = false;    ///< draw the segments' offset surfaces T1-T3 (translucent shells)
  std::array<double, 3> offsets_m = {0.004, 0.008, 0.016};  ///< T1, T2, T3 from the body surface
  bool distanceSlice = false;      ///< a horizontal slice plane coloured by distance to one part
  int slicePart = -1;              ///< mesh index (a segment) the slice measures; -1: the first segment
  double sliceHeight = 0.5;        ///< 0 = bottom of the part, 1 = top
  DistanceFunction sliceDistance;  ///< optional real field for slicePart
  bool markers = false;            ///< mark pinned (yellow) and bound (cyan) vertices
  /// Draw the avatar as the rigid segments the cloth collides with, also when the run has
  /// its skinned body (which is drawn otherwise).
  bool segments = false;
};

/// Text drawn over the picture with Dear ImGui.
struct HudInfo {
  bool show = true;
  TimeCode time;
  std::int64_t frame = 0;              ///< 0-based sample
  std::optional<std::int64_t> frames;  ///< total, when known
  double fps = 0.0;                    ///< drawing rate; 0: not shown
  std::vector<StageTime> stages;
  bool timeCodeOnly = false;  ///< contact-sheet tiles: one large time code label
};

/// Background colour (linear 0-255 RGB as written to images) at normalised height v
/// (0 = bottom row, 1 = top row): a vertical gradient. Tests use it to tell background.
[[nodiscard]] std::array<float, 3> backgroundColour(double v);

/// Camera matrices of a view (column-major 4x4, OpenGL clip space).
struct CameraMatrices {
  Eigen::Matrix4f view;
  Eigen::Matrix4f projection;
  Eigen::Vector3f eye;
  [[nodiscard]] Eigen::Matrix4f viewProjection() const { return projection * view; }
};
[[nodiscard]] CameraMatrices cameraFor(const Aabb& bounds, const ViewSettings& view, double aspect);

/// Draws into the framebuffer that is bound when draw() is called. A GL 3.3 core context
/// must be current for the whole life of the object (constructor to destructor).
class Renderer {
 public:
  explicit Renderer(std::vector<MeshInfo> meshes);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Uploads a frame: positions, per-frame normals and states of every mesh.
  void setFrame(const Frame& frame);
  /// Draws the current frame into a `width` x `height` viewport.
  void draw(int width, int height, const ViewSettings& view, const OverlaySettings& overlay);
  /// The camera draw() uses for these settings and the current frame.
  [[nodiscard]] CameraMatrices camera(int width, int height, const ViewSettings& view) const;
  [[nodiscard]] const std::vector<MeshInfo>& meshes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::render
