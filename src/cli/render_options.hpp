#pragma once
// Options shared by `drape render` and `drape play`: picture size, camera, overlays.

#include <cstdio>
#include <string>

#include <fmt/format.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/render/display_surface.hpp"
#include "drape/render/renderer.hpp"

namespace drape::cli {

struct PictureOptions {
  std::string size = "1280x720";
  double azimuthDeg = 30.0;
  double elevationDeg = 12.0;
  double zoom = 1.0;
  double aim = 0.5;
  bool follow = false;
  bool noFloor = false;
  bool noShadows = false;
  bool collisionColours = false;
  bool offsetSurfaces = false;
  bool distanceSlice = false;
  bool markers = false;
  bool segments = false;
  int subdivide = render::kDefaultSubdivisionLevels;

  void add(CLI::App& app) {
    app.add_option("--size", size, "Picture size WIDTHxHEIGHT in pixels")->capture_default_str();
    app.add_option("--azimuth", azimuthDeg, "Camera orbit angle about the vertical, degrees (0: from the front)")
        ->capture_default_str();
    app.add_option("--elevation", elevationDeg, "Camera angle above the horizon, degrees")->capture_default_str();
    app.add_option("--zoom", zoom, "Camera zoom (> 1 is closer)")->capture_default_str()->check(CLI::PositiveNumber);
    app.add_option("--aim", aim,
                   "Height the camera aims at, as a fraction of what it frames (0: the bottom, 1: the top); "
                   "with --zoom, 0.85 keeps a standing person's shoulders in the picture")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    app.add_flag("--follow", follow,
                 "The camera follows the characters (one size, centred on each frame, moving smoothly) "
                 "instead of framing the whole run");
    app.add_flag("--no-floor", noFloor, "Leave out the floor grid (and its shadows)");
    app.add_flag("--no-shadows", noShadows, "Leave out the shadows on the floor");
    app.add_flag("--collision-states", collisionColours, "Colour garment vertices by collision state");
    app.add_flag("--offset-surfaces", offsetSurfaces, "Draw the body parts' offset surfaces T1-T3");
    app.add_flag("--distance-slice", distanceSlice, "Draw a distance slice through the first body part");
    app.add_flag("--markers", markers, "Mark pinned and bound garment vertices");
    app.add_flag("--segments", segments,
                 "Draw the avatar as the rigid segments the cloth collides with instead of its skinned body");
    app.add_option("--subdivide", subdivide,
                   "Draw the garments as Loop subdivision surfaces of their simulated meshes, refined this many "
                   "times (each time four triangles for one); 0: the simulated triangles as they are")
        ->capture_default_str()
        ->check(CLI::Range(0, 4));
  }

  /// WIDTHxHEIGHT; throws drape::Error naming --size otherwise.
  [[nodiscard]] std::pair<int, int> parsedSize() const { return parseSize(size, "--size"); }

  static std::pair<int, int> parseSize(const std::string& text, const char* option) {
    int w = 0, h = 0, used = 0;
    const bool digitsOnly = text.find_first_not_of("0123456789x") == std::string::npos;
    if (!digitsOnly || std::sscanf(text.c_str(), "%5dx%5d%n", &w, &h, &used) != 2 ||
        used != static_cast<int>(text.size())) {
      throw Error(fmt::format("{} '{}': expected WIDTHxHEIGHT, e.g. 1280x720", option, text));
    }
    if (w < 16 || h < 16 || w > 8192 || h > 8192)
      throw Error(fmt::format("{} '{}': each side must be 16 to 8192 pixels", option, text));
    return {w, h};
  }

  [[nodiscard]] render::ViewSettings view() const {
    render::ViewSettings v;
    v.azimuthDeg = azimuthDeg;
    v.elevationDeg = elevationDeg;
    v.zoom = zoom;
    v.aimHeight = aim;
    return v;
  }

  [[nodiscard]] render::OverlaySettings overlay() const {
    render::OverlaySettings o;
    o.floor = !noFloor;
    o.shadows = !noShadows;
    o.collisionColours = collisionColours;
    o.offsetSurfaces = offsetSurfaces;
    o.distanceSlice = distanceSlice;
    o.markers = markers;
    o.segments = segments;
    return o;
  }
};

}  // namespace drape::cli
