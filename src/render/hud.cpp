#include "hud.hpp"

#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <filesystem>

#include <fmt/format.h>

namespace drape::render {
namespace {

constexpr const char* kMonoBold = "/usr/share/fonts/truetype/dejavu/DejaVuSansMono-Bold.ttf";
constexpr const char* kSans = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

/// A TTF font when the system has DejaVu (package fonts-dejavu-core), else ImGui's own.
ImFont* loadFont(ImGuiIO& io, const char* path, float pixels) {
  if (std::filesystem::exists(path)) {
    if (ImFont* font = io.Fonts->AddFontFromFileTTF(path, pixels)) return font;
  }
  ImFontConfig config;
  config.SizePixels = pixels;
  return io.Fonts->AddFontDefault(&config);
}

void boxedText(ImDrawList* list, ImFont* font, float size, ImVec2 pos, ImU32 colour, const std::string& text,
               float pad) {
  const ImVec2 extent = font->CalcTextSizeA(size, 1e9f, 0.0f, text.c_str());
  list->AddRectFilled(ImVec2(pos.x - pad, pos.y - pad), ImVec2(pos.x + extent.x + pad, pos.y + extent.y + pad),
                      IM_COL32(10, 12, 18, 170), pad);
  list->AddText(font, size, pos, colour, text.c_str());
}

}  // namespace

ImGuiLayer::ImGuiLayer() {
  IMGUI_CHECKVERSION();
  ImGuiContext* previous = ImGui::GetCurrentContext();
  context_ = ImGui::CreateContext();
  ImGui::SetCurrentContext(context_);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini left in the working directory
  io.LogFilename = nullptr;
  small_ = loadFont(io, kSans, 17.0f);
  large_ = loadFont(io, kMonoBold, 64.0f);
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 6.0f;
  ImGui::GetStyle().Alpha = 0.95f;
  ImGui_ImplOpenGL3_Init("#version 330 core");
  if (previous != nullptr) ImGui::SetCurrentContext(previous);
}

ImGuiLayer::~ImGuiLayer() {
  ImGui::SetCurrentContext(context_);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui::DestroyContext(context_);
}

void ImGuiLayer::beginFrame(int width, int height, void (*platformNewFrame)()) {
  makeCurrent();
  if (platformNewFrame == nullptr) {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(static_cast<float>(width), static_cast<float>(height));
    io.DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
    io.DeltaTime = 1.0f / 30.0f;
  }
  ImGui_ImplOpenGL3_NewFrame();
  if (platformNewFrame != nullptr) platformNewFrame();
  ImGui::NewFrame();
}

void ImGuiLayer::endFrame() {
  makeCurrent();
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void ImGuiLayer::drawHud(const HudInfo& hud, int width, int height) {
  if (!hud.show) return;
  ImDrawList* list = ImGui::GetForegroundDrawList();
  const auto h = static_cast<float>(height);
  const ImU32 white = IM_COL32(245, 245, 240, 255);
  if (hud.timeCodeOnly) {
    const float size = std::clamp(h / 8.0f, 12.0f, 64.0f);
    boxedText(list, large_, size, ImVec2(size * 0.4f, h - size * 1.4f), white, hud.time.smpte(), size * 0.15f);
    return;
  }
  const float big = std::clamp(h / 20.0f, 14.0f, 64.0f);
  const float small = std::clamp(h / 42.0f, 11.0f, 24.0f);
  const float margin = big * 0.5f;
  boxedText(list, large_, big, ImVec2(margin, margin), white, hud.time.smpte(), big * 0.15f);
  std::string lines =
      hud.frames ? fmt::format("frame {} / {}", hud.frame, *hud.frames) : fmt::format("frame {}", hud.frame);
  if (hud.fps > 0.0) lines += fmt::format("\n{:.1f} fps", hud.fps);
  std::size_t column = 10;  // "mean collide" and the like (a run's means) widen it
  for (const StageTime& s : hud.stages) column = std::max(column, s.stage.size());
  for (const StageTime& s : hud.stages) lines += fmt::format("\n{:<{}} {:7.3f} ms", s.stage, column, s.ms);
  boxedText(list, small_, small, ImVec2(margin, margin + big * 1.5f), IM_COL32(225, 228, 235, 255), lines,
            small * 0.3f);
  (void)width;
}

}  // namespace drape::render
