// Bullet's multibody world with its per-body loops and, for free bodies with fixed and kinematic parts, its
// constraint solver spread over threads. Not installed; nothing outside rigid/ includes it.
#pragma once

#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>

#include <memory>
#include <vector>

namespace dipper::rigid {

/// btMultiBodyDynamicsWorld whose two loops over the rigid bodies that touch only one body each (the damping
/// and predicted pose before the collision search, the integration of the poses after the solver) run on
/// `threads` threads, each body exactly as Bullet's loop treats it: the same bits on any number of threads.
/// Continuous collision detection, which those loops start and which shares the dispatcher, is not used by
/// dipper; a body with it switched on sends its loop back to Bullet's own. Without it the predictive-contact
/// pass has nothing to do but reset the hit fractions, and does only that.
///
/// The constraint solver runs on the threads too, for a world of free bodies that never sleep, fixed parts and
/// kinematic parts (no multibody, no joint). Bullet solves the simulation islands in batches, one after the
/// other; an island joins every body whose boxes overlap, so a bed of rocks is one island, and building the
/// islands each step is work on one thread. Here the islands are not built: the bodies are split into the
/// groups that touch through contact points (a kinematic part joins the groups it touches, as only one thread
/// may write its velocity back), and the groups are solved at the same time, each by its thread's own solver,
/// with each group's rows in the order of the dispatcher's manifolds. A row moves only its two bodies, and a
/// fixed or kinematic part is not moved by its rows, so each group's bodies receive the same operations in the
/// same order on any number of threads: the same bits (dynamics_world.cpp).
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
    void calculateSimulationIslands() override;

public:
    void solveConstraints(btContactSolverInfo& solverInfo) override;

private:
    /// Whether the loops may run on threads: more than one thread, and no body with continuous collision
    /// detection (whose sweep makes manifolds in the shared dispatcher).
    bool parallel() const;
    /// Whether the solver's groups replace Bullet's islands: no multibody or joint, no body that may sleep (the
    /// islands decide that), rows swept in order with no residual threshold. On any number of threads.
    bool grouped(const btContactSolverInfo& info) const;

    int threads_;
    std::vector<std::unique_ptr<btMultiBodyConstraintSolver>> solvers_;  ///< one per thread
    // the moving bodies, then the kinematic parts; the manifolds with points; the groups they fall into
    std::vector<btCollisionObject*> island_bodies_;
    std::vector<btPersistentManifold*> island_manifolds_;
    std::vector<int> parent_;  ///< union-find over the places in island_bodies_
    std::vector<int> local_;   ///< place in island_bodies_ of each body, by its user index 2 (dipper's body id)
    std::vector<int> group_of_root_;
    std::vector<int> group_points_;   ///< contact points of each group, at its root's place
    std::vector<long> chunk_points_;  ///< contact points given to each chunk so far
    std::vector<std::vector<btCollisionObject*>> group_bodies_;
    std::vector<std::vector<btPersistentManifold*>> group_manifolds_;
};

}  // namespace dipper::rigid
