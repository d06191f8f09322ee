// Narrow phase of two convex hulls (rocks, and rocks against the plates of machine parts), in place of
// Bullet's own convex-convex algorithm. Not installed; nothing outside rigid/ includes it.
#pragma once

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>

namespace dipper::rigid {

/// Creates ConvexPair algorithms for the hull-hull pairs of one dispatcher. Register it with
/// `registerCollisionCreateFunc(CONVEX_HULL_SHAPE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE, ...)`.
/// `pool_element_size` is the collision configuration's algorithm pool element size: a ConvexPair is placed in
/// the pool when it fits and on the heap otherwise (the dispatcher frees either kind).
struct ConvexPairCreateFunc : public btCollisionAlgorithmCreateFunc {
    explicit ConvexPairCreateFunc(int element_size) : pool_element_size(element_size) {}
    btCollisionAlgorithm* CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& info, const btCollisionObjectWrapper* body0,
                                                   const btCollisionObjectWrapper* body1) override;
    int pool_element_size;
    btGjkEpaPenetrationDepthSolver penetration_solver;  ///< stateless: shared by the pairs
};

}  // namespace dipper::rigid
