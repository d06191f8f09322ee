#include "rigid/detail/dynamics_world.h"

#include <omp.h>

namespace dipper::rigid {

bool DynamicsWorld::parallel() const
{
    if (threads_ <= 1 || m_nonStaticRigidBodies.size() < 2 * threads_) return false;
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
        if (m_nonStaticRigidBodies[i]->getCcdSquareMotionThreshold() != 0) return false;
    return true;
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
    if (!parallel()) {
        btMultiBodyDynamicsWorld::createPredictiveContacts(timeStep);
        return;
    }
    releasePredictiveContacts();
    const int n = m_nonStaticRigidBodies.size();
#pragma omp parallel num_threads(threads_)
    {
        // Bullet marks this loop as one that may run on parts of the body list at once
        const int t = omp_get_thread_num(), count = omp_get_num_threads();
        const int begin = n * t / count, end = n * (t + 1) / count;
        if (end > begin) createPredictiveContactsInternal(&m_nonStaticRigidBodies[begin], end - begin, timeStep);
    }
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
