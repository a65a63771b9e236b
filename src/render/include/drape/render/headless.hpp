#pragma once
// Headless rendering: an EGL surfaceless context (Mesa llvmpipe, no X server, no GPU
// needed), a multisampled framebuffer and glReadPixels. GLFW is never initialised here.

#include <memory>

#include "drape/render/image.hpp"
#include "drape/render/renderer.hpp"

namespace drape::render {

class HeadlessRenderer {
 public:
  /// Creates the EGL context and the framebuffer; throws drape::Error (exit code 1)
  /// naming the missing piece when EGL or an OpenGL 3.3 core context is not available.
  HeadlessRenderer(std::vector<MeshInfo> meshes, int width, int height);
  ~HeadlessRenderer();
  HeadlessRenderer(const HeadlessRenderer&) = delete;
  HeadlessRenderer& operator=(const HeadlessRenderer&) = delete;

  /// Renders one frame with its overlays and HUD and reads it back.
  [[nodiscard]] Image render(const Frame& frame, const ViewSettings& view, const OverlaySettings& overlay,
                             const HudInfo& hud);
  /// The same without any text over the picture.
  [[nodiscard]] Image render(const Frame& frame, const ViewSettings& view, const OverlaySettings& overlay);
  /// Changes the output size (the contact sheet renders small tiles).
  void resize(int width, int height);
  [[nodiscard]] Renderer& renderer();
  /// "OpenGL <version> (<renderer>)" of the context, for logs and reports.
  [[nodiscard]] std::string description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace drape::render
