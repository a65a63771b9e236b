// Bullet's soft-body sheet (bullet_sheet.hpp).

#include "bullet_sheet.hpp"

#include <algorithm>
#include <cmath>

#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>
#include <fmt/format.h>

#include "measure.hpp"

namespace drape::cli {

/// The world and its bodies; members in construction order (each refers to those before it).
struct BulletSheet::World {
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher{&config};
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &config};
  btSphereShape sphereShape{static_cast<btScalar>(SheetScenario::kSphereRadius)};
  btDefaultMotionState motion;
  std::unique_ptr<btRigidBody> sphere;
  std::unique_ptr<btSoftBody> sheet;

  World(int cellsU, int cellsV) : motion(sphereAt()) {
    world.setGravity(btVector3(0, -9.81f, 0));
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    info.m_gravity = btVector3(0, -9.81f, 0);
    info.air_density = 0;
    info.m_sparsesdf.Initialize();
    sphere = std::make_unique<btRigidBody>(btRigidBody::btRigidBodyConstructionInfo(0, &motion, &sphereShape));
    world.addRigidBody(sphere.get());
    // corner00 and corner10 (fixeds 1 + 2) are the two pinned corners of the z = 0 edge.
    sheet.reset(btSoftBodyHelpers::CreatePatch(info, btVector3(0, 0, 0), btVector3(1, 0, 0), btVector3(0, 0, 1),
                                               btVector3(1, 0, 1), cellsU + 1, cellsV + 1, 1 + 2, true));
    sheet->m_materials[0]->m_kLST = 1.0;
    // Two position iterations per substep: with Bullet's default of one, the 10k and 40k
    // sheets explode within the first frame (node speeds of 1e8 m/s).
    sheet->m_cfg.piterations = 2;
    sheet->m_cfg.kDF = 0.3;
    sheet->setTotalMass(1.0);
    world.addSoftBody(sheet.get());
  }
  ~World() {
    world.removeSoftBody(sheet.get());
    world.removeRigidBody(sphere.get());
  }
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  static btTransform sphereAt() {
    btTransform at;
    at.setIdentity();
    const Vec3 c = SheetScenario::sphereCentre();
    at.setOrigin(btVector3(static_cast<btScalar>(c.x()), static_cast<btScalar>(c.y()), static_cast<btScalar>(c.z())));
    return at;
  }
};

BulletSheet::BulletSheet(int cellsU, int cellsV) : world_(std::make_unique<World>(cellsU, cellsV)) {}

BulletSheet::~BulletSheet() = default;

void BulletSheet::stepTo(long frames) {
  using S = SheetScenario;
  const btSoftBody& sheet = *world_->sheet;
  // Bullet keeps running past a speed excess (it rarely reaches NaN); the run is then
  // reported diverged with the first frame and speed, and timed over all frames.
  const double start = threadCpuSeconds();
  for (; frames_ < frames && !nan_; ++frames_) {
    world_->world.stepSimulation(static_cast<btScalar>(1.0 / S::kFrameRate), S::kSubsteps,
                                 static_cast<btScalar>(1.0 / (S::kFrameRate * S::kSubsteps)));
    for (int i = 0; i < sheet.m_nodes.size(); ++i) {
      const btVector3& v = sheet.m_nodes[i].m_v;
      const btVector3& x = sheet.m_nodes[i].m_x;
      nan_ = nan_ || !std::isfinite(x.x() + x.y() + x.z() + v.x() + v.y() + v.z());
      if (!run_.diverged && (nan_ || v.length() > S::kSpeedBound_m_s)) {
        run_.diverged = true;
        run_.why = fmt::format("node {} reached {:.4g} m/s in frame {}", i, v.length(), frames_ + 1);
      }
    }
  }
  cpuSeconds_ += threadCpuSeconds() - start;
}

BulletSheetRun BulletSheet::result() const {
  BulletSheetRun r = run_;
  r.msPerFrame = 1e3 * cpuSeconds_ / static_cast<double>(std::max<long>(1, frames_));
  const btSoftBody& sheet = *world_->sheet;
  for (int i = 0; i < sheet.m_links.size(); ++i) {
    const btSoftBody::Link& l = sheet.m_links[i];
    const double length = (l.m_n[1]->m_x - l.m_n[0]->m_x).length();
    r.maxStrain = std::max(r.maxStrain, std::abs(length - l.m_rl) / l.m_rl);
  }
  return r;
}

BulletSheetRun runBulletSheet(int cellsU, int cellsV, long frames) {
  BulletSheet sheet(cellsU, cellsV);
  sheet.stepTo(frames);
  return sheet.result();
}

std::string bulletVersion() { return fmt::format("{}", btGetVersion()); }

}  // namespace drape::cli
