// Bullet's multibody world with its per-body loops spread over threads. Not installed; nothing outside rigid/
// includes it.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>

namespace dipper::rigid {

/// btMultiBodyDynamicsWorld whose three loops over the rigid bodies that touch only one body each (the damping
/// and predicted pose before the collision search, the predictive-contact pass, the integration of the poses
/// after the solver) run on `threads` threads, each body exactly as Bullet's loop treats it: the same bits on
/// any number of threads. Continuous collision detection, which those loops start and which shares the
/// dispatcher, is not used by dipper; a body with it switched on sends its loop back to Bullet's own.
class DynamicsWorld final : public btMultiBodyDynamicsWorld {
public:
    DynamicsWorld(btDispatcher* dispatcher, btBroadphaseInterface* broadphase, btMultiBodyConstraintSolver* solver,
                  btCollisionConfiguration* config, int threads)
        : btMultiBodyDynamicsWorld(dispatcher, broadphase, solver, config), threads_(threads)
    {
    }

protected:
    void predictUnconstraintMotion(btScalar timeStep) override;
    void createPredictiveContacts(btScalar timeStep) override;
    void integrateTransforms(btScalar timeStep) override;

private:
    /// Whether the loops may run on threads: more than one thread, and no body with continuous collision
    /// detection (whose sweep makes manifolds in the shared dispatcher).
    bool parallel() const;

    int threads_;
};

}  // namespace dipper::rigid
