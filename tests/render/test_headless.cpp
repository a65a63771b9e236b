// The headless renderer on a known scene (tests/formats/test_run_fixture.hpp): where the
// garment's colour appears, where the background stays, what changes between frames and
// what the per-vertex state channel does; and the light on a closed body at its silhouette.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "../formats/test_run_fixture.hpp"
#include "drape/core/error.hpp"
#include "drape/render/headless.hpp"
#include "drape/render/run_replay.hpp"

namespace drape::render {
namespace {

constexpr int kW = 320, kH = 240;

struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  [[nodiscard]] bool contains(int x, int y, int margin = 0) const {
    return x >= x0 - margin && x <= x1 + margin && y >= y0 - margin && y <= y1 + margin;
  }
  [[nodiscard]] long area() const { return static_cast<long>(x1 - x0 + 1) * (y1 - y0 + 1); }
};

/// Pixel box (rows top-down) covering every position of a mesh over the given frames.
Box projectedBox(const CameraMatrices& cam, const std::vector<Vec3>& points) {
  Box box;
  const Eigen::Matrix4f vp = cam.viewProjection();
  for (const Vec3& p : points) {
    const Eigen::Vector4f c =
        vp * Eigen::Vector4f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 1.0f);
    const double x = (c.x() / c.w() * 0.5 + 0.5) * kW;
    const double y = (1.0 - (c.y() / c.w() * 0.5 + 0.5)) * kH;
    box.x0 = std::min(box.x0, static_cast<int>(std::floor(x)));
    box.x1 = std::max(box.x1, static_cast<int>(std::ceil(x)));
    box.y0 = std::min(box.y0, static_cast<int>(std::floor(y)));
    box.y1 = std::max(box.y1, static_cast<int>(std::ceil(y)));
  }
  return box;
}

bool isClothRed(const std::uint8_t* p) { return p[0] > p[1] + 40 && p[0] > p[2] + 40; }

bool isBackground(const Image& image, int x, int y) {
  const auto bg = backgroundColour(1.0 - (y + 0.5) / image.height);
  const std::uint8_t* p = image.pixel(x, y);
  for (int k = 0; k < 3; ++k)
    if (std::abs(p[k] - bg[static_cast<std::size_t>(k)]) > 3.0f) return false;
  return true;
}

class Headless : public ::testing::Test {
 protected:
  void SetUp() override {
    replay_ = std::make_unique<RunReplay>(testrun::writeTestRun(testrun::freshDir("headless")));
    view_.azimuthDeg = 0.0;
    view_.elevationDeg = 10.0;
    view_.bounds = replay_->bounds();
    plain_.floor = false;  // nothing but background around the meshes
    plain_.shadows = false;
  }
  Frame frame(std::int64_t i) {
    Frame f;
    EXPECT_TRUE(replay_->read(i, f));
    return f;
  }

  std::unique_ptr<RunReplay> replay_;
  ViewSettings view_;
  OverlaySettings plain_;
};

TEST_F(Headless, GarmentColourInsideItsBoxBackgroundOutside) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  const Frame f0 = frame(0);
  const Image image = renderer.render(f0, view_, plain_);
  ASSERT_EQ(image.width, kW);
  ASSERT_EQ(image.height, kH);
  const CameraMatrices cam = renderer.renderer().camera(kW, kH, view_);
  const Box flag = projectedBox(cam, f0.positions[1]);
  const Box torso = projectedBox(cam, f0.positions[0]);
  ASSERT_GT(flag.area(), 1000) << "the flag should cover a good part of the picture";

  long redInside = 0, redOutside = 0, notBackgroundOutside = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const bool red = isClothRed(image.pixel(x, y));
      if (flag.contains(x, y)) {
        redInside += red ? 1 : 0;
      } else if (!flag.contains(x, y, 2)) {
        redOutside += red;
        if (!torso.contains(x, y, 2) && !isBackground(image, x, y)) ++notBackgroundOutside;
      }
    }
  }
  EXPECT_GT(redInside, flag.area() / 2) << "cloth-coloured pixels fill the flag's box";
  EXPECT_EQ(redOutside, 0) << "no cloth colour outside the flag's box";
  EXPECT_EQ(notBackgroundOutside, 0) << "background everywhere no mesh projects";
}

TEST_F(Headless, FramesDifferWhereTheClothMovedNotInEmptyCorners) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  const Image a = renderer.render(frame(0), view_, plain_);
  const Image b = renderer.render(frame(12), view_, plain_);
  const CameraMatrices cam = renderer.renderer().camera(kW, kH, view_);
  std::vector<Vec3> flagBoth = frame(0).positions[1];
  const Frame f12 = frame(12);
  for (const Vec3& p : f12.positions[1]) flagBoth.push_back(p);
  const Box flag = projectedBox(cam, flagBoth);
  long changedInFlag = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (flag.contains(x, y) && !std::equal(a.pixel(x, y), a.pixel(x, y) + 3, b.pixel(x, y))) ++changedInFlag;
  EXPECT_GT(changedInFlag, flag.area() / 20) << "the waving flag changes its pixels";
  // The four 24x24 corners hold nothing but background: identical in both frames.
  for (int corner = 0; corner < 4; ++corner) {
    const int cx = corner % 2 == 0 ? 0 : kW - 24, cy = corner / 2 == 0 ? 0 : kH - 24;
    for (int y = cy; y < cy + 24; ++y)
      for (int x = cx; x < cx + 24; ++x)
        ASSERT_TRUE(std::equal(a.pixel(x, y), a.pixel(x, y) + 3, b.pixel(x, y))) << x << "," << y;
  }
}

TEST_F(Headless, TheSameFrameRendersTheSamePixels) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  const Image a = renderer.render(frame(5), view_, plain_);
  const Image b = renderer.render(frame(5), view_, plain_);
  EXPECT_EQ(a.rgb, b.rgb);
}

TEST_F(Headless, StateChannelColoursAndMarksVertices) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  Frame f = frame(0);
  const std::size_t n = f.positions[1].size();
  f.states.assign(2, {});
  f.states[1].assign(n, vertex_state::kOnSurface);
  OverlaySettings overlay = plain_;
  overlay.collisionColours = true;
  const Image green = renderer.render(f, view_, overlay);
  long red = 0, greenish = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::uint8_t* p = green.pixel(x, y);
      red += isClothRed(p);
      greenish += p[1] > p[0] + 30 && p[1] > p[2] + 30;
    }
  EXPECT_EQ(red, 0) << "every garment vertex is on the surface: no cloth red left";
  EXPECT_GT(greenish, 1000);

  // Without the toggle the state channel changes nothing.
  const Image plainWithStates = renderer.render(f, view_, plain_);
  const Image plainNoStates = renderer.render(frame(0), view_, plain_);
  EXPECT_EQ(plainWithStates.rgb, plainNoStates.rgb);

  // Pinned vertices (the left column) get yellow markers.
  for (std::size_t v = 0; v < n; v += testrun::kFlagColumns) f.states[1][v] = vertex_state::kPinned;
  overlay = plain_;
  overlay.markers = true;
  const Image marked = renderer.render(f, view_, overlay);
  long yellow = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::uint8_t* p = marked.pixel(x, y);
      yellow += p[0] > 200 && p[1] > 170 && p[2] < 80;
    }
  EXPECT_GT(yellow, testrun::kFlagRows * 4) << "a visible marker on each pinned vertex";
}

TEST_F(Headless, OffsetSurfacesAndSliceDrawAroundTheSegmentOnly) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  const Frame f = frame(0);
  const Image plain = renderer.render(f, view_, plain_);
  OverlaySettings overlay = plain_;
  overlay.offsetSurfaces = true;
  overlay.offsets_m = {0.01, 0.02, 0.04};
  const Image shells = renderer.render(f, view_, overlay);
  overlay = plain_;
  overlay.distanceSlice = true;
  const Image slice = renderer.render(f, view_, overlay);
  const CameraMatrices cam = renderer.renderer().camera(kW, kH, view_);
  // Shells reach T3 = 4 cm out; the slice plane spans the part's box (30 cm wide) plus a
  // margin of half its width on each side.
  std::vector<Vec3> grown;
  for (const Vec3& p : f.positions[0])
    for (double sx : {-1.0, 1.0})
      for (double sy : {-1.0, 1.0})
        for (double sz : {-1.0, 1.0}) grown.push_back(p + Vec3(0.31 * sx, 0.05 * sy, 0.31 * sz));
  const Box around = projectedBox(cam, grown);
  long shellChanged = 0, sliceChanged = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool s = !std::equal(plain.pixel(x, y), plain.pixel(x, y) + 3, shells.pixel(x, y));
      const bool d = !std::equal(plain.pixel(x, y), plain.pixel(x, y) + 3, slice.pixel(x, y));
      if (!around.contains(x, y, 2)) {
        ASSERT_FALSE(s) << "shell pixel far from the segment at " << x << "," << y;
        ASSERT_FALSE(d) << "slice pixel far from the segment at " << x << "," << y;
      }
      shellChanged += s;
      sliceChanged += d;
    }
  EXPECT_GT(shellChanged, 500);
  EXPECT_GT(sliceChanged, 200);
}

TEST_F(Headless, FloorAndShadowsLieBelowTheContent) {
  HeadlessRenderer renderer(replay_->meshes(), kW, kH);
  const Frame f = frame(0);
  const Image bare = renderer.render(f, view_, plain_);
  OverlaySettings floor;  // defaults: floor and shadows on
  const Image withFloor = renderer.render(f, view_, floor);
  // The top rows (sky above the content) do not change; rows at the bottom do.
  const CameraMatrices cam = renderer.renderer().camera(kW, kH, view_);
  const Box all = projectedBox(cam, f.positions[0]);
  long changedBelow = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const bool changed = !std::equal(bare.pixel(x, y), bare.pixel(x, y) + 3, withFloor.pixel(x, y));
      if (y < all.y0 - 2) {
        ASSERT_FALSE(changed) << "the floor shows above the content at " << x << "," << y;
      }
      if (y > all.y1) changedBelow += changed;
    }
  EXPECT_GT(changedBelow, kW * 5);
}

/// A square facing the camera (+Z), side `size`, centred at `centre`.
std::pair<MeshInfo, std::vector<Vec3>> square(const std::string& name, MeshRole role, const Vec3& centre, double size) {
  const double h = 0.5 * size;
  return {MeshInfo{name, role, 4, {{0, 1, 2}, {0, 2, 3}}},
          {centre + Vec3(-h, -h, 0), centre + Vec3(h, -h, 0), centre + Vec3(h, h, 0), centre + Vec3(-h, h, 0)}};
}

/// The view of the body tests: from the front, level, no floor.
ViewSettings frontView() {
  ViewSettings view;
  view.azimuthDeg = 0.0;
  view.elevationDeg = 0.0;
  return view;
}

/// The pixel at the centre of what `points` project to.
std::pair<int, int> centreOf(HeadlessRenderer& renderer, const std::vector<Vec3>& points) {
  const Box b = projectedBox(renderer.renderer().camera(kW, kH, frontView()), points);
  return {(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2};
}

/// Two squares facing the camera, of roles `leftRole` and `rightRole`, drawn as a run shows
/// its bodies and with the segments asked for; the pixels at their centres.
struct SideBySide {
  Image shown, segments;
  std::pair<int, int> left, right;
};

SideBySide renderSideBySide(MeshRole leftRole, MeshRole rightRole) {
  const auto [left, leftAt] = square("left", leftRole, Vec3(-0.3, 0, 0), 0.3);
  const auto [right, rightAt] = square("right", rightRole, Vec3(0.3, 0, 0), 0.3);
  HeadlessRenderer renderer({left, right}, kW, kH);
  Frame f;
  f.positions = {leftAt, rightAt};
  f.states = {{}, {}};
  OverlaySettings overlay;
  overlay.floor = false;
  SideBySide out;
  out.shown = renderer.render(f, frontView(), overlay);
  overlay.segments = true;
  out.segments = renderer.render(f, frontView(), overlay);
  out.left = centreOf(renderer, leftAt);
  out.right = centreOf(renderer, rightAt);
  return out;
}

TEST(HeadlessBody, TheSkinIsDrawnInsteadOfTheSegmentsUnlessTheyAreAskedFor) {
  // A segment on the left, the skin on the right: which one shows?
  const SideBySide r = renderSideBySide(MeshRole::Segment, MeshRole::Skin);
  const auto [lx, ly] = r.left;
  const auto [rx, ry] = r.right;
  EXPECT_TRUE(isBackground(r.shown, lx, ly)) << "the segment is drawn beside the skin";
  EXPECT_FALSE(isBackground(r.shown, rx, ry)) << "the skin is not drawn";
  EXPECT_FALSE(isBackground(r.segments, lx, ly)) << "asked for, the segment is not drawn";
  EXPECT_TRUE(isBackground(r.segments, rx, ry)) << "the skin is drawn with the segments";
  // Without a skin in the run the segments are the body.
  const auto [segment, segmentAt] = square("LeftUpLeg", MeshRole::Segment, Vec3(-0.3, 0, 0), 0.3);
  HeadlessRenderer segmentsOnly({segment}, kW, kH);
  Frame g;
  g.positions = {segmentAt};
  g.states = {{}};
  OverlaySettings overlay;
  overlay.floor = false;
  const Image bare = segmentsOnly.render(g, frontView(), overlay);
  const auto [ox, oy] = centreOf(segmentsOnly, segmentAt);
  EXPECT_FALSE(isBackground(bare, ox, oy));
}

TEST(HeadlessBody, DrawnMeshesShowWithTheSkinInADarkerClay) {
  // The skin on the left, a drawn mesh (hair, eyes) on the right: both show with the skin,
  // the drawn one darker; neither with the segments the overlay asks for.
  const SideBySide r = renderSideBySide(MeshRole::Skin, MeshRole::Drawn);
  const auto [lx, ly] = r.left;
  const auto [rx, ry] = r.right;
  const Image& shown = r.shown;
  ASSERT_FALSE(isBackground(shown, lx, ly));
  ASSERT_FALSE(isBackground(shown, rx, ry)) << "the drawn mesh is not drawn with the skin";
  const auto brightness = [](const Image& image, int x, int y) {
    return static_cast<int>(image.pixel(x, y)[0]) + image.pixel(x, y)[1] + image.pixel(x, y)[2];
  };
  EXPECT_LT(brightness(shown, rx, ry) + 100, brightness(shown, lx, ly)) << "the drawn mesh is not darker than the skin";
  EXPECT_TRUE(isBackground(r.segments, rx, ry)) << "the drawn mesh is drawn with the segments";
}

/// A coarse closed UV sphere (outward winding), as a skinned body: its smoothed normals lean
/// away from the camera on front faces near the silhouette.
std::pair<MeshInfo, std::vector<Vec3>> coarseSphere(const Vec3& centre, double radius, int slices, int stacks) {
  std::vector<Vec3> points;
  points.push_back(centre + Vec3(0, radius, 0));
  for (int j = 1; j < stacks; ++j) {
    const double polar = std::numbers::pi * j / stacks;
    for (int i = 0; i < slices; ++i) {
      const double around = 2 * std::numbers::pi * i / slices;
      points.push_back(centre + radius * Vec3(std::sin(polar) * std::sin(around), std::cos(polar),
                                              std::sin(polar) * std::cos(around)));
    }
  }
  points.push_back(centre - Vec3(0, radius, 0));
  const auto ring = [&](int j, int i) { return static_cast<std::uint32_t>(1 + (j - 1) * slices + (i % slices)); };
  const auto south = static_cast<std::uint32_t>(points.size() - 1);
  std::vector<mesh::Triangle> triangles;
  for (int i = 0; i < slices; ++i) {
    triangles.push_back({0, ring(1, i), ring(1, i + 1)});
    for (int j = 1; j + 1 < stacks; ++j) {
      triangles.push_back({ring(j, i), ring(j + 1, i), ring(j + 1, i + 1)});
      triangles.push_back({ring(j, i), ring(j + 1, i + 1), ring(j, i + 1)});
    }
    triangles.push_back({ring(stacks - 1, i), south, ring(stacks - 1, i + 1)});
  }
  return {MeshInfo{"body", MeshRole::Skin, points.size(), triangles}, points};
}

double luminance(const std::uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

TEST(HeadlessLight, TheUndersideOfABodyIsNoBrighterThanItsFrontAtTheSilhouette) {
  // The key light comes from above: the underside of a sphere is in its shade. Near the
  // lower silhouette the smoothed normals of the faces the camera sees lean away from it;
  // turned towards the camera by their own sign they would face the light, as bright
  // specks along every silhouette and crease.
  const auto [sphere, at] = coarseSphere(Vec3::Zero(), 0.3, 10, 6);
  HeadlessRenderer renderer({sphere}, kW, kH);
  Frame f;
  f.positions = {at};
  f.states = {{}};
  ViewSettings view;
  view.azimuthDeg = 0.0;
  view.elevationDeg = 0.0;
  OverlaySettings overlay;
  overlay.floor = false;
  overlay.shadows = false;
  const Image image = renderer.render(f, view, overlay);
  const Box disc = projectedBox(renderer.renderer().camera(kW, kH, view), at);
  const int cx = (disc.x0 + disc.x1) / 2, cy = (disc.y0 + disc.y1) / 2;
  ASSERT_FALSE(isBackground(image, cx, cy));
  const double front = luminance(image.pixel(cx, cy));
  double brightestBelow = 0;
  int drawnBelow = 0;
  for (int y = cy + (disc.y1 - cy) / 2; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (!isBackground(image, x, y)) {
        ++drawnBelow;
        brightestBelow = std::max(brightestBelow, luminance(image.pixel(x, y)));
      }
  ASSERT_GT(drawnBelow, 100) << "the sphere's lower part is drawn";
  EXPECT_LT(brightestBelow, front) << "a pixel of the underside is brighter than the front facing the camera";
}

TEST(HeadlessErrors, BadSizesAndTopologiesAreRefused) {
  MeshInfo bad{"bad", MeshRole::Garment, 3, {{0, 1, 7}}};
  EXPECT_THROW(HeadlessRenderer({bad}, 64, 64), Error);
  EXPECT_THROW(HeadlessRenderer({}, 4, 64), Error);
  HeadlessRenderer ok({MeshInfo{"tri", MeshRole::Garment, 3, {{0, 1, 2}}}}, 64, 64);
  Frame f;
  f.positions = {{Vec3::Zero(), Vec3::UnitX()}};  // one position short
  EXPECT_THROW((void)ok.render(f, ViewSettings{}, OverlaySettings{}), Error);
}

}  // namespace
}  // namespace drape::render
