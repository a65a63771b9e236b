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

BulletSheetRun runBulletSheet(int cellsU, int cellsV, long frames) {
  using S = SheetScenario;
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btSequentialImpulseConstraintSolver solver;
  btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
  world.setGravity(btVector3(0, -9.81f, 0));
  btSoftBodyWorldInfo& info = world.getWorldInfo();
  info.m_gravity = btVector3(0, -9.81f, 0);
  info.air_density = 0;
  info.m_sparsesdf.Initialize();

  btSphereShape sphereShape(static_cast<btScalar>(S::kSphereRadius));
  btTransform at;
  at.setIdentity();
  const Vec3 c = S::sphereCentre();
  at.setOrigin(btVector3(static_cast<btScalar>(c.x()), static_cast<btScalar>(c.y()), static_cast<btScalar>(c.z())));
  btDefaultMotionState motion(at);
  btRigidBody sphere(btRigidBody::btRigidBodyConstructionInfo(0, &motion, &sphereShape));
  world.addRigidBody(&sphere);

  // corner00 and corner10 (fixeds 1 + 2) are the two pinned corners of the z = 0 edge.
  btSoftBody* sheet = btSoftBodyHelpers::CreatePatch(info, btVector3(0, 0, 0), btVector3(1, 0, 0), btVector3(0, 0, 1),
                                                     btVector3(1, 0, 1), cellsU + 1, cellsV + 1, 1 + 2, true);
  sheet->m_materials[0]->m_kLST = 1.0;
  // Two position iterations per substep: with Bullet's default of one, the 10k and 40k
  // sheets explode within the first frame (node speeds of 1e8 m/s).
  sheet->m_cfg.piterations = 2;
  sheet->m_cfg.kDF = 0.3;
  sheet->setTotalMass(1.0);
  world.addSoftBody(sheet);

  // Bullet keeps running past a speed excess (it rarely reaches NaN); the run is then
  // reported diverged with the first frame and speed, and timed over all frames.
  BulletSheetRun r;
  const double start = threadCpuSeconds();
  long f = 0;
  bool nan = false;
  for (; f < frames && !nan; ++f) {
    world.stepSimulation(static_cast<btScalar>(1.0 / S::kFrameRate), S::kSubsteps,
                         static_cast<btScalar>(1.0 / (S::kFrameRate * S::kSubsteps)));
    for (int i = 0; i < sheet->m_nodes.size(); ++i) {
      const btVector3& v = sheet->m_nodes[i].m_v;
      const btVector3& x = sheet->m_nodes[i].m_x;
      nan = nan || !std::isfinite(x.x() + x.y() + x.z() + v.x() + v.y() + v.z());
      if (!r.diverged && (nan || v.length() > S::kSpeedBound_m_s)) {
        r.diverged = true;
        r.why = fmt::format("node {} reached {:.4g} m/s in frame {}", i, v.length(), f + 1);
      }
    }
  }
  r.msPerFrame = 1e3 * (threadCpuSeconds() - start) / static_cast<double>(std::max<long>(1, f));
  for (int i = 0; i < sheet->m_links.size(); ++i) {
    const btSoftBody::Link& l = sheet->m_links[i];
    const double length = (l.m_n[1]->m_x - l.m_n[0]->m_x).length();
    r.maxStrain = std::max(r.maxStrain, std::abs(length - l.m_rl) / l.m_rl);
  }
  world.removeSoftBody(sheet);
  delete sheet;
  world.removeRigidBody(&sphere);
  return r;
}

std::string bulletVersion() { return fmt::format("{}", btGetVersion()); }

}  // namespace drape::cli
