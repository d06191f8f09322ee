#include "rigid/detail/dynamics_world.h"

#include <algorithm>

#include <omp.h>

namespace dipper::rigid {

bool DynamicsWorld::parallel() const
{
    if (threads_ <= 1 || m_nonStaticRigidBodies.size() < 2 * threads_) return false;
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
        if (m_nonStaticRigidBodies[i]->getCcdSquareMotionThreshold() != 0) return false;
    return true;
}

bool DynamicsWorld::grouped(const btContactSolverInfo& info) const
{
    // the groups give the same bits on any number of threads only while the rows are swept in order and to the
    // last iteration unless none changed (a residual threshold would stop a chunk on the sum over its groups)
    if ((info.m_solverMode & SOLVER_RANDMIZE_ORDER) || info.m_leastSquaresResidualThreshold > 0) return false;
    if (m_multiBodies.size() > 0 || m_constraints.size() > 0 || m_multiBodyConstraints.size() > 0) return false;
    for (int i = 0; i < m_collisionObjects.size(); ++i) {
        const btCollisionObject* o = m_collisionObjects[i];
        if (!o->isStaticOrKinematicObject() && o->getActivationState() != DISABLE_DEACTIVATION) return false;  // it may sleep
    }
    return true;
}

void DynamicsWorld::calculateSimulationIslands()
{
    // Bullet's islands join every two bodies whose boxes overlap, for its solver's batches and for putting
    // bodies to sleep; the solver's groups below take their place where no body may sleep
    if (grouped(getSolverInfo())) return;
    btMultiBodyDynamicsWorld::calculateSimulationIslands();
}

void DynamicsWorld::solveConstraints(btContactSolverInfo& solverInfo)
{
    if (!grouped(solverInfo)) {
        btMultiBodyDynamicsWorld::solveConstraints(solverInfo);
        return;
    }
    // Bullet's steps (btMultiBodyDynamicsWorld::solveConstraints) with the solving of the islands in between
    // done here: first the external forces and the set-up of Bullet's own batch list, which stays empty; last
    // its empty remainder, allSolved and the multibodies' velocities (none here).
    solveExternalForces(solverInfo);
    // every moving body (each passes through the solver, which adds its external forces to its velocity), then
    // the kinematic parts; every manifold with points between bodies that respond to contact, in the
    // dispatcher's order. A manifold without points gives no row; handed to a group that does not own its
    // bodies, Bullet's solver would still write their velocities back from a second thread, so it is left out.
    island_bodies_.clear();
    island_manifolds_.clear();
    for (int i = 0; i < m_collisionObjects.size(); ++i)
        if (!m_collisionObjects[i]->isStaticOrKinematicObject()) island_bodies_.push_back(m_collisionObjects[i]);
    const int body_count = static_cast<int>(island_bodies_.size());
    for (int i = 0; i < m_collisionObjects.size(); ++i)
        if (m_collisionObjects[i]->isKinematicObject()) island_bodies_.push_back(m_collisionObjects[i]);
    const int node_count = static_cast<int>(island_bodies_.size());
    btDispatcher* dispatcher = getCollisionWorld()->getDispatcher();
    for (int i = 0; i < dispatcher->getNumManifolds(); ++i) {
        btPersistentManifold* m = dispatcher->getManifoldByIndexInternal(i);
        if (m->getNumContacts() > 0 && dispatcher->needsResponse(m->getBody0(), m->getBody1())) island_manifolds_.push_back(m);
    }

    // Groups of bodies that touch through contact points. Bullet's solver turns the points of a batch's
    // manifolds into rows and sweeps them in order; a row reads and moves only the velocities of its two bodies
    // (a fixed part has zero inverse mass and stays at rest), and a body's external forces are added on its own.
    // So the rows of one group, swept in the same order without the others', give its bodies the same bits. The
    // sweeps stop early only when no row changed at all (the residual threshold is 0), which then holds for
    // every group. Each body without a contact point is a group of its own.
    // A kinematic part joins the groups it touches into one: it is not moved by its rows (zero inverse mass), but
    // the solver writes its velocity back, which only one thread may do. A fixed part joins nothing.
    parent_.resize(static_cast<std::size_t>(node_count));
    bool known = true;  // every body carries dipper's body id (else all of them form one group)
    for (int k = 0; k < node_count; ++k) {
        const int id = island_bodies_[static_cast<std::size_t>(k)]->getUserIndex2();
        known = known && id >= 0;
        if (!known) break;
        if (static_cast<int>(local_.size()) <= id) local_.resize(static_cast<std::size_t>(id) + 1, -1);
        local_[static_cast<std::size_t>(id)] = k;
    }
    // each manifold's moving and kinematic bodies are listed (else, which the world does not allow, one group)
    auto fixed = [](const btCollisionObject* o) { return o->isStaticOrKinematicObject() && !o->isKinematicObject(); };
    auto listed = [&](const btCollisionObject* o) {
        if (fixed(o)) return true;
        const int id = o->getUserIndex2();
        if (id < 0 || id >= static_cast<int>(local_.size())) return false;
        const int k = local_[static_cast<std::size_t>(id)];
        return k >= 0 && k < node_count && island_bodies_[static_cast<std::size_t>(k)] == o;
    };
    for (std::size_t q = 0; q < island_manifolds_.size() && known; ++q)
        known = listed(island_manifolds_[q]->getBody0()) && listed(island_manifolds_[q]->getBody1());
    for (int k = 0; k < node_count; ++k) parent_[static_cast<std::size_t>(k)] = known ? k : 0;
    auto root = [&](int k) {
        while (parent_[static_cast<std::size_t>(k)] != k) k = parent_[static_cast<std::size_t>(k)] = parent_[static_cast<std::size_t>(parent_[static_cast<std::size_t>(k)])];
        return k;
    };
    auto place = [&](const btCollisionObject* o) {
        if (fixed(o)) return -1;
        return known ? local_[static_cast<std::size_t>(o->getUserIndex2())] : 0;
    };
    for (const btPersistentManifold* m : island_manifolds_) {
        const int a = place(m->getBody0()), b = place(m->getBody1());
        if (a >= 0 && b >= 0) parent_[static_cast<std::size_t>(root(a))] = root(b);
    }
    // groups in the order of their first body; each into the chunk with the fewest contact points so far
    const int chunks = 4 * threads_;
    group_bodies_.resize(static_cast<std::size_t>(chunks));
    group_manifolds_.resize(static_cast<std::size_t>(chunks));
    for (int c = 0; c < chunks; ++c) {
        group_bodies_[static_cast<std::size_t>(c)].clear();
        group_manifolds_[static_cast<std::size_t>(c)].clear();
    }
    std::vector<int>& points = group_points_;  // contact points of each group, at its root
    points.assign(static_cast<std::size_t>(node_count), 0);
    for (const btPersistentManifold* m : island_manifolds_) {
        const int a = place(m->getBody0());
        const int k = a >= 0 ? a : place(m->getBody1());
        if (k >= 0) points[static_cast<std::size_t>(root(k))] += m->getNumContacts();
    }
    group_of_root_.assign(static_cast<std::size_t>(node_count), -1);
    std::vector<long>& load = chunk_points_;
    load.assign(static_cast<std::size_t>(chunks), 0);
    for (int k = 0; k < body_count; ++k) {
        const int r = root(k);
        int& chunk = group_of_root_[static_cast<std::size_t>(r)];
        if (chunk < 0) {
            chunk = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
            load[static_cast<std::size_t>(chunk)] += points[static_cast<std::size_t>(r)] + 1;
        }
        group_bodies_[static_cast<std::size_t>(chunk)].push_back(island_bodies_[static_cast<std::size_t>(k)]);
    }
    // each manifold to its group's chunk
    for (btPersistentManifold* m : island_manifolds_) {
        const int a = place(m->getBody0());
        const int k = a >= 0 ? a : place(m->getBody1());
        const int chunk = k < 0 ? -1 : group_of_root_[static_cast<std::size_t>(root(k))];
        if (chunk >= 0) group_manifolds_[static_cast<std::size_t>(chunk)].push_back(m);  // (a kinematic part alone has no row)
    }

    while (static_cast<int>(solvers_.size()) < threads_) solvers_.push_back(std::make_unique<btMultiBodyConstraintSolver>());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_)
    for (int c = 0; c < chunks; ++c) {
        auto& bodies = group_bodies_[static_cast<std::size_t>(c)];
        auto& manifolds = group_manifolds_[static_cast<std::size_t>(c)];
        if (bodies.empty()) continue;
        btMultiBodyConstraintSolver& solver = *solvers_[static_cast<std::size_t>(omp_get_thread_num())];
        solver.solveMultiBodyGroup(bodies.data(), static_cast<int>(bodies.size()), manifolds.empty() ? nullptr : manifolds.data(),
                                   static_cast<int>(manifolds.size()), nullptr, 0, nullptr, 0, solverInfo, m_debugDrawer, dispatcher);
    }
    solveInternalConstraints(solverInfo);
}

void DynamicsWorld::predictUnconstraintMotion(btScalar timeStep)
{
    if (!parallel()) {
        btMultiBodyDynamicsWorld::predictUnconstraintMotion(timeStep);
        return;
    }
    // Bullet's loop (btDiscreteDynamicsWorld::predictUnconstraintMotion), each body on its own
    const int n = m_nonStaticRigidBodies.size();
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (int i = 0; i < n; ++i) {
        btRigidBody* body = m_nonStaticRigidBodies[i];
        if (body->isStaticOrKinematicObject()) continue;
        body->applyDamping(timeStep);
        body->predictIntegratedTransform(timeStep, body->getInterpolationWorldTransform());
    }
    predictMultiBodyTransforms(timeStep);
}

void DynamicsWorld::createPredictiveContacts(btScalar timeStep)
{
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
        if (m_nonStaticRigidBodies[i]->getCcdSquareMotionThreshold() != 0) {
            btMultiBodyDynamicsWorld::createPredictiveContacts(timeStep);
            return;
        }
    // Without continuous collision detection Bullet's pass (createPredictiveContactsInternal) predicts each
    // body's pose only to compare its motion with a zero threshold: what is left is the hit fractions it resets
    releasePredictiveContacts();
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) m_nonStaticRigidBodies[i]->setHitFraction(1);
}

void DynamicsWorld::integrateTransforms(btScalar timeStep)
{
    if (!parallel() || m_applySpeculativeContactRestitution) {
        btMultiBodyDynamicsWorld::integrateTransforms(timeStep);
        return;
    }
    const int n = m_nonStaticRigidBodies.size();
#pragma omp parallel num_threads(threads_)
    {
        const int t = omp_get_thread_num(), count = omp_get_num_threads();
        const int begin = n * t / count, end = n * (t + 1) / count;
        if (end > begin) integrateTransformsInternal(&m_nonStaticRigidBodies[begin], end - begin, timeStep);
    }
    integrateMultiBodyTransforms(timeStep);
}

}  // namespace dipper::rigid
