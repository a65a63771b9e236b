#pragma once
// The Dear ImGui side of the renderer: one ImGui context per window or headless renderer,
// its fonts, and the heads-up display (time code, frame, fps, ms per stage) drawn with the
// foreground draw list so it needs no window layout and shows on the very first frame.

#include <imgui.h>

#include "drape/render/renderer.hpp"

namespace drape::render {

class ImGuiLayer {
 public:
  /// Creates the context and the OpenGL3 backend (the GL context must be current). The
  /// window player then adds the GLFW backend itself.
  ImGuiLayer();
  ~ImGuiLayer();
  ImGuiLayer(const ImGuiLayer&) = delete;
  ImGuiLayer& operator=(const ImGuiLayer&) = delete;

  void makeCurrent() { ImGui::SetCurrentContext(context_); }
  /// Starts a frame. Headless callers pass no platform hook and get `width` x `height`;
  /// the window passes its GLFW backend's NewFrame, which sets the size and input.
  void beginFrame(int width, int height, void (*platformNewFrame)() = nullptr);
  /// Renders everything drawn since beginFrame into the bound framebuffer.
  void endFrame();
  /// Draws the HUD for an image `width` x `height` pixels.
  void drawHud(const HudInfo& hud, int width, int height);

 private:
  ImGuiContext* context_ = nullptr;
  ImFont* small_ = nullptr;  ///< panel and HUD text
  ImFont* large_ = nullptr;  ///< time codes (scaled down from a large atlas size)
};

}  // namespace drape::render
