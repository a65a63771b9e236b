// `drape bench render`: headless rendering speed on a synthetic scene (a waving cloth of
// N x N vertices beside a cylinder body part), split into drawing + read-back and PNG
// encoding. Prints one JSON object.

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <numbers>

#include <nlohmann/json.hpp>

#include "bench_machine.hpp"
#include "command.hpp"
#include "drape/render/headless.hpp"
#include "render_options.hpp"

namespace drape::cli {
namespace {

struct BenchRenderOptions {
  std::string size = "1280x720";
  int frames = 30;
  int clothSide = 100;
  bool json = false;
};

/// A cloth of side x side vertices (1 m square) and a closed 32-sided cylinder.
std::vector<render::MeshInfo> syntheticMeshes(int side) {
  render::MeshInfo cloth{"cloth", render::MeshRole::Garment, static_cast<std::size_t>(side * side), {}};
  for (int j = 0; j + 1 < side; ++j)
    for (int i = 0; i + 1 < side; ++i) {
      const auto a = static_cast<std::uint32_t>(j * side + i), s = static_cast<std::uint32_t>(side);
      cloth.triangles.push_back({a, a + 1, a + s + 1});
      cloth.triangles.push_back({a, a + s + 1, a + s});
    }
  render::MeshInfo body{"body", render::MeshRole::Segment, 64, {}};
  for (std::uint32_t i = 0; i < 32; ++i) {
    const std::uint32_t j = (i + 1) % 32;
    body.triangles.push_back({i, j, 32 + j});
    body.triangles.push_back({i, 32 + j, 32 + i});
  }
  return {cloth, body};
}

render::Frame syntheticFrame(int side, int f) {
  render::Frame frame;
  frame.index = f;
  frame.time = TimeCode{f, 30.0};
  std::vector<Vec3> cloth;
  const double t = f / 30.0;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const double u = static_cast<double>(i) / (side - 1), v = static_cast<double>(j) / (side - 1);
      cloth.emplace_back(0.3 + u, 0.2 + v, 0.15 * u * std::sin(9.0 * u - 6.0 * t));
    }
  std::vector<Vec3> body;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < 32; ++i) {
      const double a = 2.0 * std::numbers::pi * i / 32;
      body.emplace_back(0.15 * std::cos(a), ring == 0 ? 0.0 : 1.4, -0.15 * std::sin(a));
    }
  frame.positions = {cloth, body};
  return frame;
}

RunFunction setupBenchRender(CLI::App& app) {
  static BenchRenderOptions o;
  app.add_option("--size", o.size, "Picture size WIDTHxHEIGHT")->capture_default_str();
  app.add_option("--frames", o.frames, "Frames to render")->capture_default_str()->check(CLI::Range(1, 100000));
  app.add_option("--cloth-side", o.clothSide, "Cloth vertices per side")->capture_default_str()->check(CLI::Range(2, 2000));
  app.add_flag("--json", o.json, "Accepted for symmetry with the other benchmarks (output is always JSON)");
  return [] {
    using Clock = std::chrono::steady_clock;
    const auto [w, h] = PictureOptions::parseSize(o.size, "--size");
    render::HeadlessRenderer renderer(syntheticMeshes(o.clothSide), w, h);
    render::ViewSettings view;
    view.bounds = Aabb{Vec3(-0.2, 0.0, -0.2), Vec3(1.3, 1.4, 0.2)};
    render::HudInfo hud;
    const std::string png = (std::filesystem::temp_directory_path() / "drape-bench-render.png").string();
    double renderMs = 0.0, pngMs = 0.0;
    (void)renderer.render(syntheticFrame(o.clothSide, 0), view, render::OverlaySettings{}, hud);  // warm-up
    for (int f = 0; f < o.frames; ++f) {
      const render::Frame frame = syntheticFrame(o.clothSide, f);
      hud.time = frame.time;
      hud.frame = f;
      const auto t0 = Clock::now();
      const render::Image image = renderer.render(frame, view, render::OverlaySettings{}, hud);
      const auto t1 = Clock::now();
      render::writePng(png, image);
      const auto t2 = Clock::now();
      renderMs += std::chrono::duration<double, std::milli>(t1 - t0).count();
      pngMs += std::chrono::duration<double, std::milli>(t2 - t1).count();
    }
    std::filesystem::remove(png);
    nlohmann::json out;
    out["benchmark"] = "render";
    out["machine"] = benchMachine();
    out["gl"] = renderer.description();
    out["width"] = w;
    out["height"] = h;
    out["frames"] = o.frames;
    out["cloth_vertices"] = o.clothSide * o.clothSide;
    out["ms_per_frame_render_readback"] = renderMs / o.frames;
    out["ms_per_frame_png"] = pngMs / o.frames;
    out["frames_per_second"] = 1000.0 * o.frames / (renderMs + pngMs);
    std::cout << out.dump() << '\n';
    return 0;
  };
}

const bool registered_bench_render =
    registerCommand({"render", "Headless rendering speed (draw + read-back, PNG encoding)", "bench", 40, &setupBenchRender});

}  // namespace
}  // namespace drape::cli
