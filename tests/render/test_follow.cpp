// The follow camera: what it frames on walks with known answers (a steady walk is followed
// without lag), on random wobbling walks (every frame inside its framing, one size, less
// jitter than the frames), and what the picture gains (a person fills more of it).

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "drape/core/error.hpp"
#include "drape/render/follow.hpp"
#include "drape/render/renderer.hpp"

namespace drape::render {
namespace {

constexpr double kRate = 30.0;

/// A person-sized box (0.6 x 1.8 x 0.4 m, feet on y = 0) centred horizontally at (x, z).
Aabb person(double x, double z) {
  Aabb b;
  b.min = Vec3(x - 0.3, 0.0, z - 0.2);
  b.max = Vec3(x + 0.3, 1.8, z + 0.2);
  return b;
}

bool inside(const Aabb& inner, const Aabb& outer, double tol = 1e-9) {
  return (inner.min.array() >= outer.min.array() - tol).all() && (inner.max.array() <= outer.max.array() + tol).all();
}

TEST(FollowFraming, ASteadyWalkIsFollowedWithoutLag) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 150; ++i) boxes.push_back(person(1.3 * i / kRate, 0.02 * i / kRate));
  const std::vector<Aabb> framing = followFraming(boxes, kRate);
  ASSERT_EQ(framing.size(), boxes.size());
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    EXPECT_NEAR(framing[i].center().x(), boxes[i].center().x(), 1e-9) << i;
    EXPECT_NEAR(framing[i].center().z(), boxes[i].center().z(), 1e-9) << i;
    EXPECT_TRUE(inside(boxes[i], framing[i])) << i;
    // Square horizontally, just wide enough for the person; the run's heights.
    EXPECT_NEAR(framing[i].size().x(), 0.6, 1e-9);
    EXPECT_NEAR(framing[i].size().z(), 0.6, 1e-9);
    EXPECT_DOUBLE_EQ(framing[i].min.y(), 0.0);
    EXPECT_DOUBLE_EQ(framing[i].max.y(), 1.8);
  }
}

TEST(FollowFraming, RandomWobblingWalksStayInsideOneSizeAndSmoother) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> wobble(-0.05, 0.05), speed(0.5, 2.0), heading(0.0, 6.283185307179586);
  for (int walk = 0; walk < 50; ++walk) {
    const double v = speed(rng), a = heading(rng);
    const int n = 20 + walk * 7;
    std::vector<Aabb> boxes;
    for (int i = 0; i < n; ++i) {
      const double t = i / kRate;
      Aabb b = person(v * t * std::cos(a) + wobble(rng), v * t * std::sin(a) + wobble(rng));
      b.max.y() += 0.1 * std::abs(wobble(rng));  // arms up now and then
      boxes.push_back(b);
    }
    const std::vector<Aabb> framing = followFraming(boxes, kRate);
    double rawStep = 0, framedStep = 0;
    for (int i = 0; i < n; ++i) {
      const std::size_t k = static_cast<std::size_t>(i);
      EXPECT_TRUE(inside(boxes[k], framing[k])) << "walk " << walk << " frame " << i;
      EXPECT_NEAR(framing[k].size().x(), framing[0].size().x(), 1e-9);
      EXPECT_NEAR(framing[k].size().y(), framing[0].size().y(), 1e-9);
      if (i > 15 && i + 15 < n) {  // where the window is whole
        rawStep = std::max(rawStep, std::abs(boxes[k].center().x() - boxes[k - 1].center().x()));
        framedStep = std::max(framedStep, std::abs(framing[k].center().x() - framing[k - 1].center().x()));
      }
    }
    // The wobble (up to 10 cm from frame to frame) is averaged out of the camera's path;
    // what is left is the walk itself (at most 6.7 cm per frame) and a trace of the wobble.
    if (n > 40) {
      EXPECT_LT(framedStep, 2.0 / kRate * std::abs(std::cos(a)) + 0.1 / 31 + 1e-9) << "walk " << walk;
      EXPECT_LT(framedStep, rawStep + 1e-12) << "walk " << walk;
    }
  }
}

TEST(FollowFraming, EmptyFramesTakeTheLastBoxAndNothingToFrameIsAnError) {
  std::vector<Aabb> boxes = {Aabb{}, person(0, 0), Aabb{}, person(0.1, 0)};
  const std::vector<Aabb> framing = followFraming(boxes, kRate, 0.0);  // no smoothing
  ASSERT_EQ(framing.size(), 4u);
  EXPECT_NEAR(framing[0].center().x(), 0.0, 1e-12);  // the first non-empty box
  EXPECT_NEAR(framing[2].center().x(), 0.0, 1e-12);  // its predecessor's
  EXPECT_NEAR(framing[3].center().x(), 0.1, 1e-12);
  EXPECT_THROW((void)followFraming({Aabb{}, Aabb{}}, kRate), Error);
  EXPECT_THROW((void)followFraming({person(0, 0)}, 0.0), Error);
  EXPECT_THROW((void)followFraming({person(0, 0)}, std::nan("")), Error);
}

TEST(FollowCamera, HoldsEveryFrameSeenAndSettlesOnAStandingPerson) {
  FollowCamera camera(0.25);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> step(-0.05, 0.05);
  double x = 0, z = 0;
  Aabb framing;
  for (int i = 0; i < 200; ++i) {
    x += 0.04 + step(rng);
    z += step(rng);
    const double before = framing.empty() ? 0.0 : framing.size().x();
    framing = camera.update(person(x, z), 1.0 / kRate);
    EXPECT_TRUE(inside(person(x, z), framing)) << i;
    EXPECT_GE(framing.size().x(), before - 1e-12) << "the framing never shrinks (no zoom pumping)";
    EXPECT_NEAR(framing.size().x(), framing.size().z(), 1e-12);
  }
  // Standing still: after 5 time constants the centre is within exp(-5) of the person's.
  const double gap = std::abs(framing.center().x() - x);
  for (int i = 0; i < 38; ++i) framing = camera.update(person(x, z), 1.0 / kRate);  // 1.27 s
  EXPECT_LT(std::abs(framing.center().x() - x), std::exp(-5.0) * gap + 1e-12);
  // An empty frame changes nothing.
  const Aabb kept = camera.update(Aabb{}, 1.0 / kRate);
  EXPECT_EQ(kept.min, framing.min);
  EXPECT_EQ(kept.max, framing.max);
}

/// Height on the picture (a fraction of it) of a box seen by the camera framing `framing`.
double pictureHeight(const Aabb& box, const Aabb& framing) {
  ViewSettings view;  // the renderer's defaults: azimuth 30, elevation 12
  const CameraMatrices cam = cameraFor(framing, view, 16.0 / 9.0);
  double lo = 1e9, hi = -1e9;
  for (int c = 0; c < 8; ++c) {
    const Vec3 p((c & 1) ? box.max.x() : box.min.x(), (c & 2) ? box.max.y() : box.min.y(),
                 (c & 4) ? box.max.z() : box.min.z());
    const Eigen::Vector4f q = cam.viewProjection() * Eigen::Vector4f(float(p.x()), float(p.y()), float(p.z()), 1.0f);
    EXPECT_LE(std::abs(q.x() / q.w()), 1.0f) << "a corner is off the picture";
    EXPECT_LE(std::abs(q.y() / q.w()), 1.0f) << "a corner is off the picture";
    lo = std::min(lo, double(q.y() / q.w()));
    hi = std::max(hi, double(q.y() / q.w()));
  }
  return 0.5 * (hi - lo);
}

TEST(FollowFraming, APersonWalkingSixMetresFillsThePictureInsteadOfCrossingIt) {
  std::vector<Aabb> boxes;
  Aabb whole;
  for (int i = 0; i < 180; ++i) {
    boxes.push_back(person(6.0 * i / 179.0, 0.0));
    whole.extend(boxes.back().min);
    whole.extend(boxes.back().max);
  }
  const std::vector<Aabb> framing = followFraming(boxes, kRate);
  for (std::size_t i = 0; i < boxes.size(); i += 30) {
    const double followed = pictureHeight(boxes[i], framing[i]);
    const double fixed = pictureHeight(boxes[i], whole);
    EXPECT_GT(followed, 0.6) << i;
    EXPECT_LT(fixed, 0.4) << i;
  }
}

TEST(CameraFor, AimsAtTheHeightItIsToldAsAFractionOfWhatItFrames) {
  const Aabb framing{Vec3(-0.4, 0.0, -0.3), Vec3(0.6, 1.8, 0.5)};
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-60.0, 60.0), fraction(0.0, 1.0), zoom(0.5, 4.0);
  for (int i = 0; i < 50; ++i) {
    ViewSettings view;
    view.azimuthDeg = 3.0 * angle(rng);
    view.elevationDeg = angle(rng);
    view.zoom = zoom(rng);
    view.aimHeight = fraction(rng);
    const CameraMatrices cam = cameraFor(framing, view, 16.0 / 9.0);
    const Vec3 c = framing.center();
    const double y = framing.min.y() + view.aimHeight * framing.size().y();
    const Eigen::Vector4f q = cam.viewProjection() * Eigen::Vector4f(float(c.x()), float(y), float(c.z()), 1.0f);
    EXPECT_NEAR(q.x() / q.w(), 0.0, 1e-4) << i;
    EXPECT_NEAR(q.y() / q.w(), 0.0, 1e-4) << i << ": the aimed height is at the picture's centre";
    // The camera keeps its distance: the aim moves it, it does not turn it closer or further.
    ViewSettings centred = view;
    centred.aimHeight = 0.5;
    const CameraMatrices base = cameraFor(framing, centred, 16.0 / 9.0);
    EXPECT_NEAR((cam.eye - base.eye).norm(), std::abs(view.aimHeight - 0.5) * framing.size().y(), 1e-4) << i;
  }
}

}  // namespace
}  // namespace drape::render
