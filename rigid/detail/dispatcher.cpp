#include "rigid/detail/dispatcher.h"

namespace dipper::rigid {

namespace {

bool is_hull(int shape_type) { return shape_type == CONVEX_HULL_SHAPE_PROXYTYPE; }
/// Shapes whose pair with a hull has an algorithm that works on its own manifold only, made with the pair:
/// Bullet's convex-plane and convex-concave algorithms (the latter makes and frees a convex-triangle algorithm
/// per triangle, sharing its manifold).
bool is_plane_or_mesh(int shape_type) { return shape_type == STATIC_PLANE_PROXYTYPE || shape_type == TRIANGLE_MESH_SHAPE_PROXYTYPE; }

btCollisionObject* object(const btBroadphaseProxy* proxy) { return static_cast<btCollisionObject*>(proxy->m_clientObject); }

}  // namespace

Dispatcher::Work Dispatcher::kind(const btBroadphasePair& pair) const
{
    if (!pair.m_algorithm) return Work::serial;  // a new pair: its algorithm may make a manifold
    const int a = object(pair.m_pProxy0)->getCollisionShape()->getShapeType();
    const int b = object(pair.m_pProxy1)->getCollisionShape()->getShapeType();
    if (is_hull(a) && is_hull(b)) return dipper_pairs_ ? Work::hulls : Work::serial;
    if ((is_hull(a) && is_plane_or_mesh(b)) || (is_plane_or_mesh(a) && is_hull(b))) return Work::done;
    return Work::serial;
}

namespace {

/// The two objects of a pair as Bullet's default near callback wraps them
struct PairWrappers {
    explicit PairWrappers(const btBroadphasePair& pair)
        : a(object(pair.m_pProxy0)), b(object(pair.m_pProxy1)), wa(nullptr, a->getCollisionShape(), a, a->getWorldTransform(), -1, -1),
          wb(nullptr, b->getCollisionShape(), b, b->getWorldTransform(), -1, -1)
    {
    }
    btCollisionObject* a;
    btCollisionObject* b;
    btCollisionObjectWrapper wa, wb;
};

}  // namespace

void Dispatcher::process(btBroadphasePair& pair, const btDispatcherInfo& info)
{
    // Bullet's default near callback, less its needsCollision test (made in pass 1)
    PairWrappers w(pair);
    if (!pair.m_algorithm) pair.m_algorithm = findAlgorithm(&w.wa, &w.wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
    if (!pair.m_algorithm) return;
    btManifoldResult result(&w.wa, &w.wb);
    pair.m_algorithm->processCollision(&w.wa, &w.wb, info, &result);
}

void Dispatcher::dispatchAllCollisionPairs(btOverlappingPairCache* pairs, const btDispatcherInfo& info, btDispatcher* dispatcher)
{
    if (threads_ <= 1 || info.m_dispatchFunc != btDispatcherInfo::DISPATCH_DISCRETE || info.m_deterministicOverlappingPairs ||
        getNearCallback() != &btCollisionDispatcher::defaultNearCallback) {
        btCollisionDispatcher::dispatchAllCollisionPairs(pairs, info, dispatcher);
        return;
    }
    btBroadphasePairArray& list = pairs->getOverlappingPairArray();
    const int n = list.size();
    work_.resize(static_cast<std::size_t>(n));
    searches_.resize(static_cast<std::size_t>(n));

    // 1. every thread: the checks, and the work of each pair on its own manifold
    parallel_ = true;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads_)
    for (int i = 0; i < n; ++i) {
        btBroadphasePair& pair = list[i];
        const auto k = static_cast<std::size_t>(i);
        Work& work = work_[k];
        if (!needsCollision(object(pair.m_pProxy0), object(pair.m_pProxy1))) {
            work = Work::none;
            continue;
        }
        work = kind(pair);
        if (work == Work::done) {
            process(pair, info);
        } else if (work == Work::hulls) {
            work = Work::none;
            // most hull pairs of a pile are apart, and their gap bound says so without a search
            if (convex_pair_still_apart(*pair.m_algorithm, *object(pair.m_pProxy0), *object(pair.m_pProxy1))) continue;
            PairWrappers w(pair);
            btManifoldResult result(&w.wa, &w.wb);
            const ManifoldChange change = take_convex_pair(*pair.m_algorithm, w.wa, w.wb, info, result, searches_[k]);
            if (change == ManifoldChange::make) work = Work::make_manifold;
            if (change == ManifoldChange::release) work = Work::release_manifold;
        }
    }
    parallel_ = false;

    // 2. one thread, in the pairs' order: whatever makes or releases manifolds
    for (int i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const Work work = work_[k];
        if (work == Work::serial) {
            process(list[i], info);
        } else if (work == Work::make_manifold || work == Work::release_manifold) {
            PairWrappers w(list[i]);
            btManifoldResult result(&w.wa, &w.wb);
            finish_convex_pair(*list[i].m_algorithm, work == Work::make_manifold ? ManifoldChange::make : ManifoldChange::release, w.wa, w.wb,
                               searches_[k], result);
        }
    }
}

void* Dispatcher::allocateCollisionAlgorithm(int size)
{
    if (!parallel_) return btCollisionDispatcher::allocateCollisionAlgorithm(size);
    std::lock_guard<std::mutex> lock(pool_);
    return btCollisionDispatcher::allocateCollisionAlgorithm(size);
}

void Dispatcher::freeCollisionAlgorithm(void* ptr)
{
    if (!parallel_) {
        btCollisionDispatcher::freeCollisionAlgorithm(ptr);
        return;
    }
    std::lock_guard<std::mutex> lock(pool_);
    btCollisionDispatcher::freeCollisionAlgorithm(ptr);
}

}  // namespace dipper::rigid
