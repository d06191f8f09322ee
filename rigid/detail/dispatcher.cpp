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
// A hull and a fixed plane or triangle mesh with an empty manifold keep -T the same way (the sign tells the two
// kinds apart), with m what the hull must travel before Bullet's algorithm could add a point (note_surface_gap).
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
    const double stored = threshold(pair);
    if (stored == 0.0) return false;
    const bool hulls = stored > 0.0;
    const double t = hulls ? stored : -stored;
    const auto u0 = static_cast<std::size_t>(pair.m_pProxy0->m_uniqueId), u1 = static_cast<std::size_t>(pair.m_pProxy1->m_uniqueId);
    const double sum = odometer_[u0] + odometer_[u1];
    // A hull pair's own bound adds 1e-6 r per body and keeps the first rotation in single precision (within 2e-7
    // in norm): twice that. The sums carry round-off of about 1e-16 per step: 1e-8 of them, for both kinds.
    const double slack = (hulls ? 2e-6 * (radius_[u0] + radius_[u1]) : 0.0) + 1e-8 * (sum + t) + 1e-12;
    return sum + slack < t;
}

void Dispatcher::note_gap(btBroadphasePair& pair) const
{
    const double m = convex_pair_apart_margin(*pair.m_algorithm, *object(pair.m_pProxy0), *object(pair.m_pProxy1));
    set_threshold(pair, m > 0.0 ? moved(pair) + m : 0.0);
}

namespace {

/// The least, over the triangles near [lo, hi], of how far apart a triangle's box and [lo, hi] are along the axis
/// that separates them most (<= 0 for a box that overlaps); `nearest` starts at the farthest it looks.
struct NearestTriangleBox : public btTriangleCallback {
    NearestTriangleBox(const btVector3& l, const btVector3& h, double reach) : lo(l), hi(h), nearest(reach) {}
    void processTriangle(btVector3* t, int, int) override
    {
        double apart = -std::numeric_limits<double>::infinity();
        for (int k = 0; k < 3; ++k) {
            const double t_lo = std::min({t[0][k], t[1][k], t[2][k]}), t_hi = std::max({t[0][k], t[1][k], t[2][k]});
            apart = std::max({apart, t_lo - hi[k], lo[k] - t_hi});
        }
        nearest = std::min(nearest, apart);
    }
    btVector3 lo, hi;
    double nearest;
};

}  // namespace

void Dispatcher::note_surface_gap(btBroadphasePair& pair) const
{
    // A hull against a fixed plane or triangle mesh, just processed. While its manifold is empty, Bullet's
    // algorithm adds a point only where the hull (with its margin) comes within the contact breaking distance of
    // the surface: for a plane, when the hull's lowest point along the normal does; for a mesh, only if a
    // triangle's box meets the hull's box grown by the triangles' margin and the breaking distance (the hull lies
    // in its box). Any point of the hull moves no farther than the growth of its odometer, so neither does any
    // face of its box, and a fixed surface does not move. So the pair can be passed over while that growth
    // stays below the gap measured now, and nothing is skipped that Bullet's algorithm would have added.
    set_threshold(pair, 0.0);
    const btCollisionObject* a = object(pair.m_pProxy0);
    const btCollisionObject* b = object(pair.m_pProxy1);
    const bool a_hull = is_hull(a->getCollisionShape()->getShapeType());
    const btCollisionObject& hull = a_hull ? *a : *b;
    const btCollisionObject& surface = a_hull ? *b : *a;
    if (!surface.isStaticObject() || surface.isKinematicObject()) return;
    thread_local btManifoldArray manifolds;
    manifolds.resize(0);
    pair.m_algorithm->getAllContactManifolds(manifolds);
    if (manifolds.size() != 1 || manifolds[0]->getNumContacts() != 0) return;
    const double breaking = manifolds[0]->getContactBreakingThreshold();
    const auto& shape = *static_cast<const btConvexShape*>(hull.getCollisionShape());
    const btTransform& th = hull.getWorldTransform();
    const btTransform& ts = surface.getWorldTransform();
    double gap = 0.0;
    if (surface.getCollisionShape()->getShapeType() == STATIC_PLANE_PROXYTYPE) {
        const auto& plane = *static_cast<const btStaticPlaneShape*>(surface.getCollisionShape());
        const btVector3 n = ts.getBasis() * plane.getPlaneNormal();
        const btVector3 on_plane = ts * (plane.getPlaneNormal() * plane.getPlaneConstant());
        const btVector3 lowest = th * shape.localGetSupportingVertex(-n * th.getBasis());
        gap = n.dot(lowest - on_plane) - breaking;
    } else {
        const auto& mesh = *static_cast<const btConcaveShape*>(surface.getCollisionShape());
        // the hull's own box in the mesh's frame, from its support points along the axes (Bullet's getAabb adds
        // the margin twice: a looser box, re-checked more often)
        const btTransform in_mesh = ts.inverse() * th;
        btVector3 lo, hi;
        for (int k = 0; k < 3; ++k) {
            const btVector3 axis = in_mesh.getBasis().getRow(k);  // the mesh's axis k in the hull's frame
            hi[k] = (in_mesh * shape.localGetSupportingVertex(axis))[k];
            lo[k] = (in_mesh * shape.localGetSupportingVertex(-axis))[k];
        }
        const btScalar grow = mesh.getMargin() + breaking;
        lo -= btVector3(grow, grow, grow);
        hi += btVector3(grow, grow, grow);
        const double reach = hull_motion_radius(shape);  // look as far as the hull's size
        NearestTriangleBox nearest(lo, hi, reach);
        mesh.processAllTriangles(&nearest, lo - btVector3(reach, reach, reach), hi + btVector3(reach, reach, reach));
        gap = nearest.nearest;
    }
    if (gap > 0.0) set_threshold(pair, -(moved(pair) + gap));
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
    thresholds_set_ = true;
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
            note_surface_gap(pair);
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

void Dispatcher::write_odometers(StateWriter& out) const
{
    out.tag("odometers");
    std::vector<std::uint8_t> known;
    std::vector<double> previous;
    for (std::size_t u = 0; u < shape_.size(); ++u) {
        known.push_back(shape_[u] ? 1 : 0);
        const btTransform& t = previous_[u];
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) previous.push_back(t.getBasis()[r][c]);
        for (int c = 0; c < 3; ++c) previous.push_back(t.getOrigin()[c]);
    }
    out(odometer_, known, previous, thresholds_set_);
}

void Dispatcher::read_odometers(StateReader& in)
{
    in.tag("odometers");
    std::vector<double> odometer, previous;
    std::vector<std::uint8_t> known;
    bool thresholds = false;
    in(odometer, known, previous, thresholds);
    if (known.size() != odometer.size() || previous.size() != 12 * odometer.size()) in.fail("odometers of another number of bodies");
    // each known proxy's shape is its object's now (a shape, once given, is never changed)
    std::vector<const btCollisionShape*> shape(odometer.size(), nullptr);
    if (objects_)
        for (int i = 0; i < objects_->size(); ++i) {
            const btCollisionObject* o = (*objects_)[i];
            const btBroadphaseProxy* h = o->getBroadphaseHandle();
            if (!h || h->m_uniqueId < 0 || static_cast<std::size_t>(h->m_uniqueId) >= odometer.size()) continue;
            if (known[static_cast<std::size_t>(h->m_uniqueId)]) shape[static_cast<std::size_t>(h->m_uniqueId)] = o->getCollisionShape();
        }
    for (std::size_t u = 0; u < known.size(); ++u)
        if (known[u] && !shape[u]) in.fail(concat("an odometer of body proxy ", u, ", which the world does not have"));
    odometer_ = std::move(odometer);
    shape_ = std::move(shape);
    radius_.assign(shape_.size(), 0.0);
    previous_.assign(shape_.size(), btTransform::getIdentity());
    for (std::size_t u = 0; u < shape_.size(); ++u) {
        if (shape_[u]) radius_[u] = hull_motion_radius(*shape_[u]);
        const double* p = &previous[12 * u];
        previous_[u] = btTransform(btMatrix3x3(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8]), btVector3(p[9], p[10], p[11]));
    }
    thresholds_set_ = thresholds;
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
