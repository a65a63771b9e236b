#include "drape/render/player.hpp"

#include <epoxy/gl.h>
// epoxy first: GLFW must not pull in a second set of GL declarations.
#include <GLFW/glfw3.h>
#include <imgui_impl_glfw.h>

#include <algorithm>
#include <array>
#include <string>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/render/follow.hpp"
#include "drape/render/image.hpp"
#include "gl_util.hpp"
#include "hud.hpp"

namespace drape::render {
namespace {

std::string& glfwLastError() {
  static std::string message;
  return message;
}

void onGlfwError(int /*code*/, const char* description) { glfwLastError() = description ? description : "unknown"; }

/// GLFW is initialised for the window only (never on the headless path) and terminated
/// when the player ends, even on an exception.
struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback(&onGlfwError);
    if (glfwInit() != GLFW_TRUE) {
      throw Error(fmt::format("drape play needs a display ({}); without one, run it under xvfb-run or use drape render",
                              glfwLastError()));
    }
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

/// Mouse and keyboard state the callbacks share with the loop.
struct Input {
  double scroll = 0.0;
};

void onScroll(GLFWwindow* window, double /*dx*/, double dy) {
  if (auto* input = static_cast<Input*>(glfwGetWindowUserPointer(window))) input->scroll += dy;
}

/// Edge-triggered key presses from polling.
class Keys {
 public:
  bool pressed(GLFWwindow* window, int key) {
    const bool down = glfwGetKey(window, key) == GLFW_PRESS;
    bool& was = down_[static_cast<std::size_t>(key) % down_.size()];
    const bool edge = down && !was;
    was = down;
    return edge;
  }

 private:
  std::array<bool, GLFW_KEY_LAST + 1> down_{};
};

/// The overlay panel: toggles for every overlay, the T1-T3 offsets, the slice part.
void drawPanel(OverlaySettings& overlay, const std::vector<MeshInfo>& meshes, bool hasStates, bool& paused,
               bool& following, ViewSettings& view, const ViewSettings& initialView) {
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 10.0f, 10.0f), ImGuiCond_Always, ImVec2(1.0f, 0.0f));
  ImGui::SetNextWindowBgAlpha(0.75f);
  ImGui::SetNextWindowCollapsed(io.DisplaySize.x < 800.0f,
                                ImGuiCond_FirstUseEver);  // small windows: keep the picture clear
  ImGui::Begin("overlays", nullptr, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove);
  ImGui::Checkbox("paused (space)", &paused);
  ImGui::Checkbox("follow the characters (F)", &following);
  ImGui::Checkbox("floor", &overlay.floor);
  ImGui::SameLine();
  ImGui::Checkbox("shadows", &overlay.shadows);
  if (hasSkin(meshes)) ImGui::Checkbox("collision segments, not the skinned body", &overlay.segments);
  ImGui::Checkbox("collision states", &overlay.collisionColours);
  if (overlay.collisionColours && !hasStates) ImGui::TextDisabled("  (this run has no state data)");
  ImGui::Checkbox("pinned / bound markers", &overlay.markers);
  ImGui::Checkbox("offset surfaces T1-T3", &overlay.offsetSurfaces);
  if (overlay.offsetSurfaces || overlay.distanceSlice) {
    std::array<float, 3> mm = {static_cast<float>(overlay.offsets_m[0] * 1000),
                               static_cast<float>(overlay.offsets_m[1] * 1000),
                               static_cast<float>(overlay.offsets_m[2] * 1000)};
    if (ImGui::SliderFloat3("T1 T2 T3 (mm)", mm.data(), 0.0f, 50.0f, "%.1f")) {
      for (std::size_t i = 0; i < 3; ++i) overlay.offsets_m[i] = mm[i] / 1000.0;
    }
  }
  ImGui::Checkbox("distance slice", &overlay.distanceSlice);
  if (overlay.distanceSlice) {
    std::vector<int> segments;
    for (std::size_t m = 0; m < meshes.size(); ++m)
      if (meshes[m].role == MeshRole::Segment) segments.push_back(static_cast<int>(m));
    if (segments.empty()) {
      ImGui::TextDisabled("  (no body parts in this run)");
    } else {
      if (overlay.slicePart < 0) overlay.slicePart = segments.front();
      const std::string current = meshes[static_cast<std::size_t>(overlay.slicePart)].name;
      if (ImGui::BeginCombo("part", current.c_str())) {
        for (int m : segments)
          if (ImGui::Selectable(meshes[static_cast<std::size_t>(m)].name.c_str(), m == overlay.slicePart))
            overlay.slicePart = m;
        ImGui::EndCombo();
      }
      float height = static_cast<float>(overlay.sliceHeight);
      if (ImGui::SliderFloat("height", &height, 0.0f, 1.0f)) overlay.sliceHeight = height;
    }
  }
  if (ImGui::Button("reset view (R)")) view = initialView;
  ImGui::End();
}

/// The picture just drawn into the window's back buffer, rows top to bottom.
Image readBackBuffer(int width, int height) {
  Image image;
  image.width = width;
  image.height = height;
  std::vector<std::uint8_t> rows(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  glReadBuffer(GL_BACK);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  image.rgb.resize(rows.size());
  const std::size_t stride = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)
    std::copy_n(rows.data() + static_cast<std::size_t>(height - 1 - y) * stride, stride,
                image.rgb.data() + static_cast<std::size_t>(y) * stride);
  return image;
}

}  // namespace

PlayerStats Player::run(FrameSource& source) {
  GlfwSession session;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  GLFWwindow* window = glfwCreateWindow(options_.width, options_.height, options_.title.c_str(), nullptr, nullptr);
  if (window == nullptr)
    throw Error(fmt::format("cannot open an OpenGL 3.3 core window ({})", glfwLastError()), ExitCode::Internal);
  Input input;
  glfwSetWindowUserPointer(window, &input);
  glfwSetScrollCallback(window, &onScroll);  // before ImGui's backend, which chains to it
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  gl::requireGl33("drape play");

  PlayerStats stats;
  {
    Renderer renderer(source.meshes());
    ImGuiLayer imgui;
    imgui.makeCurrent();
    ImGui_ImplGlfw_InitForOpenGL(window, true);

    Frame frame;
    std::int64_t index = 0;
    if (!source.read(0, frame)) throw Error("the run has no frames to play");
    renderer.setFrame(frame);
    stats.framesDrawn = 1;
    Aabb seen = frameBounds(frame);
    FollowCamera follow;
    follow.update(seen, 0.0);
    bool following = options_.follow;
    const bool hasStates =
        std::any_of(frame.states.begin(), frame.states.end(), [](const auto& s) { return !s.empty(); });

    ViewSettings view = options_.view;
    const ViewSettings initialView = view;
    OverlaySettings overlay = options_.overlay;
    bool paused = false, finished = false;
    Keys keys;
    double lastCursorX = 0, lastCursorY = 0;
    const double start = glfwGetTime();
    double nextFrameAt = start + 1.0 / source.frameRate();
    double fps = 0.0, fpsWindowStart = start;
    int fpsFrames = 0;

    auto advance = [&](std::int64_t to) {
      const std::optional<std::int64_t> count = source.frameCount();
      if (count && to >= *count) {
        if (!options_.loop) return false;
        to = 0;
      }
      if (count && to < 0) to = *count - 1;
      if (!source.read(to, frame)) return false;
      index = to;
      renderer.setFrame(frame);
      const Aabb box = frameBounds(frame);
      follow.update(box, 1.0 / source.frameRate());
      if (!box.empty()) {
        seen.extend(box.min);
        seen.extend(box.max);
      }
      ++stats.framesDrawn;
      return true;
    };

    while (!glfwWindowShouldClose(window)) {
      glfwPollEvents();
      const double now = glfwGetTime();
      imgui.makeCurrent();
      const ImGuiIO& io = ImGui::GetIO();

      // Input: keys, orbit by dragging, zoom by the wheel.
      if (keys.pressed(window, GLFW_KEY_ESCAPE) || keys.pressed(window, GLFW_KEY_Q)) break;
      if (options_.close != nullptr && options_.close->load()) glfwSetWindowShouldClose(window, GLFW_TRUE);  // drawn once more: the screenshot
      if (keys.pressed(window, GLFW_KEY_SPACE)) paused = !paused;
      if (keys.pressed(window, GLFW_KEY_R)) view = initialView;
      if (keys.pressed(window, GLFW_KEY_F)) following = !following;
      if (paused && keys.pressed(window, GLFW_KEY_RIGHT) && source.ready(index + 1)) advance(index + 1);
      if (paused && keys.pressed(window, GLFW_KEY_LEFT) && source.frameCount()) advance(index - 1);
      double cursorX = 0, cursorY = 0;
      glfwGetCursorPos(window, &cursorX, &cursorY);
      if (!io.WantCaptureMouse && glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
        view.azimuthDeg -= (cursorX - lastCursorX) * 0.4;
        view.elevationDeg = std::clamp(view.elevationDeg + (cursorY - lastCursorY) * 0.3, -85.0, 85.0);
      }
      lastCursorX = cursorX;
      lastCursorY = cursorY;
      if (!io.WantCaptureMouse && input.scroll != 0.0)
        view.zoom = std::clamp(view.zoom * std::pow(1.1, input.scroll), 0.2, 20.0);
      input.scroll = 0.0;

      // Time: one new frame per frame period (or per redraw when not real-time).
      // A live source's frame that has not come yet is asked for again at the next redraw.
      if (!paused && !finished && (!options_.realTime || now >= nextFrameAt) && source.ready(index + 1)) {
        nextFrameAt = std::max(nextFrameAt + 1.0 / source.frameRate(), now);
        if (!advance(index + 1)) finished = true;
      }
      if (options_.maxFrames && stats.framesDrawn >= *options_.maxFrames) glfwSetWindowShouldClose(window, GLFW_TRUE);
      if (finished && options_.maxFrames) glfwSetWindowShouldClose(window, GLFW_TRUE);

      // Draw: the scene, then the HUD and the panel.
      int width = 0, height = 0;
      glfwGetFramebufferSize(window, &width, &height);
      if (width > 0 && height > 0) {
        ViewSettings drawView = view;
        if (following) {
          const auto at = static_cast<std::size_t>(index);
          drawView.bounds = at < options_.followFraming.size() ? options_.followFraming[at] : follow.framing();
        } else if (!drawView.bounds) {
          drawView.bounds = seen;
        }
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        renderer.draw(width, height, drawView, overlay);
        imgui.beginFrame(width, height, &ImGui_ImplGlfw_NewFrame);
        HudInfo hud;
        hud.time = frame.time;
        hud.frame = frame.index;
        hud.frames = source.frameCount();
        hud.fps = fps;
        hud.stages = frame.stages;
        imgui.drawHud(hud, width, height);
        drawPanel(overlay, source.meshes(), hasStates, paused, following, view, initialView);
        imgui.endFrame();
        if (!options_.screenshot.empty() && glfwWindowShouldClose(window))
          writePng(options_.screenshot, readBackBuffer(width, height));
        glfwSwapBuffers(window);
      }
      ++fpsFrames;
      if (now - fpsWindowStart >= 0.5) {
        fps = fpsFrames / (now - fpsWindowStart);
        fpsFrames = 0;
        fpsWindowStart = now;
      }
    }
    stats.seconds = glfwGetTime() - start;
    imgui.makeCurrent();
    ImGui_ImplGlfw_Shutdown();
  }
  glfwDestroyWindow(window);
  return stats;
}

}  // namespace drape::render
