#include "rigid/detail/dispatcher.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace dipper::rigid {

namespace {

bool is_hull(int shape_type) { return shape_type == CONVEX_HULL_SHAPE_PROXYTYPE; }
/// Shapes whose pair with a hull has an algorithm that works on its own manifold only, made with the pair:
/// Bullet's convex-plane and convex-concave algorithms (the latter makes and frees a convex-triangle algorithm
/// per triangle, sharing its manifold).
bool is_plane_or_mesh(int shape_type) { return shape_type == STATIC_PLANE_PROXYTYPE || shape_type == TRIANGLE_MESH_SHAPE_PROXYTYPE; }

btCollisionObject* object(const btBroadphaseProxy* proxy) { return static_cast<btCollisionObject*>(proxy->m_clientObject); }

// A hull pair found apart keeps, in its broad-phase pair's spare word (m_internalInfo1, zero in a new pair and
// moved with the pair when the pair array is compacted), the threshold T = O_a + O_b + m of the step where
// it was last checked: the two bodies' odometers then, plus what was left of its gap. While O_a + O_b stays
// below T (less a slack for round-off), the bodies cannot have closed the gap, and the pair's own gap
// bound would say the same, so the pair is passed over unread. 0: no threshold.
static_assert(sizeof(void*) == sizeof(double), "a threshold is kept in a pointer's place");
double threshold(const btBroadphasePair& pair)
{
    double t;
    std::memcpy(&t, &pair.m_internalInfo1, sizeof t);
    return t;
}
void set_threshold(btBroadphasePair& pair, double t) { std::memcpy(&pair.m_internalInfo1, &t, sizeof t); }

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

void Dispatcher::update_odometers()
{
    if (!objects_) return;
    const int n = objects_->size();
    int top = -1;
    for (int i = 0; i < n; ++i)
        if (const btBroadphaseProxy* h = (*objects_)[i]->getBroadphaseHandle()) top = std::max(top, h->m_uniqueId);
    const auto size = static_cast<std::size_t>(top + 1);
    if (odometer_.size() < size) {
        odometer_.resize(size, 0.0);
        radius_.resize(size, 0.0);
        previous_.resize(size, btTransform::getIdentity());
        shape_.resize(size, nullptr);
    }
#pragma omp parallel for schedule(static) num_threads(threads_)
    for (int i = 0; i < n; ++i) {
        const btCollisionObject* o = (*objects_)[i];
        const btBroadphaseProxy* h = o->getBroadphaseHandle();
        if (!h) continue;
        const auto u = static_cast<std::size_t>(h->m_uniqueId);
        const btTransform& t = o->getWorldTransform();
        if (shape_[u] != o->getCollisionShape()) {
            // a proxy seen for the first time starts from here; one whose shape changed is never passed over
            if (shape_[u]) odometer_[u] = std::numeric_limits<double>::infinity();
            shape_[u] = o->getCollisionShape();
            radius_[u] = hull_motion_radius(*shape_[u]);
            previous_[u] = t;
            continue;
        }
        double turn = 0.0;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                const double d = t.getBasis()[r][c] - previous_[u].getBasis()[r][c];
                turn += d * d;
            }
        odometer_[u] += (t.getOrigin() - previous_[u].getOrigin()).length() + radius_[u] * std::sqrt(turn);
        previous_[u] = t;
    }
}

double Dispatcher::moved(const btBroadphasePair& pair) const
{
    return odometer_[static_cast<std::size_t>(pair.m_pProxy0->m_uniqueId)] + odometer_[static_cast<std::size_t>(pair.m_pProxy1->m_uniqueId)];
}

bool Dispatcher::clear_by_odometers(const btBroadphasePair& pair) const
{
    const double t = threshold(pair);
    if (!(t > 0.0)) return false;
    const auto u0 = static_cast<std::size_t>(pair.m_pProxy0->m_uniqueId), u1 = static_cast<std::size_t>(pair.m_pProxy1->m_uniqueId);
    const double sum = odometer_[u0] + odometer_[u1];
    // The pair's own bound adds 1e-6 r per body and keeps the first rotation in single precision (within 2e-7
    // in norm); the sums carry round-off of about 1e-16 per step. Twice the first, and 1e-8 of the sums.
    const double slack = 2e-6 * (radius_[u0] + radius_[u1]) + 1e-8 * (sum + t) + 1e-12;
    return sum + slack < t;
}

void Dispatcher::note_gap(btBroadphasePair& pair) const
{
    const double m = convex_pair_apart_margin(*pair.m_algorithm, *object(pair.m_pProxy0), *object(pair.m_pProxy1));
    set_threshold(pair, m > 0.0 ? moved(pair) + m : 0.0);
}

void Dispatcher::clear_thresholds(btOverlappingPairCache* pairs)
{
    if (!thresholds_set_) return;
    btBroadphasePairArray& list = pairs->getOverlappingPairArray();
    for (int i = 0; i < list.size(); ++i) set_threshold(list[i], 0.0);
    thresholds_set_ = false;
}

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
        getNearCallback() != &btCollisionDispatcher::defaultNearCallback || !objects_) {
        clear_thresholds(pairs);  // Bullet's dispatch keeps no thresholds up to date
        btCollisionDispatcher::dispatchAllCollisionPairs(pairs, info, dispatcher);
        return;
    }
    update_odometers();
    thresholds_set_ = dipper_pairs_;
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
        if (clear_by_odometers(pair)) {  // most pairs of a pile: apart, and their bodies have hardly moved
            work = Work::none;
            continue;
        }
        if (!needsCollision(object(pair.m_pProxy0), object(pair.m_pProxy1))) {
            work = Work::none;
            continue;
        }
        work = kind(pair);
        if (work == Work::done) {
            process(pair, info);
        } else if (work == Work::hulls) {
            work = Work::none;
            // a pair still apart by its own gap bound: a new threshold from what is left of the gap
            if (convex_pair_apart_margin(*pair.m_algorithm, *object(pair.m_pProxy0), *object(pair.m_pProxy1)) > 0.0) {
                note_gap(pair);
                continue;
            }
            PairWrappers w(pair);
            btManifoldResult result(&w.wa, &w.wb);
            const ManifoldChange change = take_convex_pair(*pair.m_algorithm, w.wa, w.wb, info, result, searches_[k]);
            if (change == ManifoldChange::make) work = Work::make_manifold;
            if (change == ManifoldChange::release) work = Work::release_manifold;
            note_gap(pair);
        }
    }
    parallel_ = false;

    // 2. one thread, in the pairs' order: whatever makes or releases manifolds
    for (int i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const Work work = work_[k];
        if (work == Work::serial) {
            process(list[i], info);
            if (list[i].m_algorithm && kind(list[i]) == Work::hulls) note_gap(list[i]);
        } else if (work == Work::make_manifold || work == Work::release_manifold) {
            PairWrappers w(list[i]);
            btManifoldResult result(&w.wa, &w.wb);
            finish_convex_pair(*list[i].m_algorithm, work == Work::make_manifold ? ManifoldChange::make : ManifoldChange::release, w.wa, w.wb,
                               searches_[k], result);
            note_gap(list[i]);
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
