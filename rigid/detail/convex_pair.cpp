#include "rigid/detail/convex_pair.h"

#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <new>

namespace dipper::rigid {

namespace {

/// GJK reports the closest points once, at its end: kept here, then handed to the manifold only if they are
/// within the contact breaking distance (Bullet's manifold result would drop them otherwise).
struct ClosestPoints : public btDiscreteCollisionDetectorInterface::Result {
    void setShapeIdentifiersA(int, int) override {}
    void setShapeIdentifiersB(int, int) override {}
    void addContactPoint(const btVector3& normal_on_b, const btVector3& point_on_b, btScalar distance_m) override
    {
        found = true;
        normal = normal_on_b;
        point = point_on_b;
        distance = distance_m;
    }
    bool found = false;
    btVector3 normal{0, 0, 0}, point{0, 0, 0};
    btScalar distance = 0;
};

/// The pair of two convex hulls. It differs from Bullet's convex-convex algorithm in two ways, both about the
/// many pairs of a pile whose boxes overlap but whose hulls are apart (four in five):
///  - a contact manifold (1.5 kB) exists only while the hulls are within the contact breaking distance; Bullet
///    keeps an empty one for every pair of overlapping boxes;
///  - a pair found apart is not searched again until it may have closed the gap. When GJK finds the hulls
///    apart, the gap along its separating direction n is measured with the hulls' support points (a plane
///    normal to n separates them by that gap). Each later step bounds how much of it the bodies' motion can
///    have closed: the origins' relative displacement along n, plus for each body its rotation since then
///    (|R - R0| as an operator norm, exactly |R - R0|_F / sqrt 2 for two rotations) times the radius of its
///    hull about its origin. GJK runs again only when that bound reaches the gap less the breaking distance;
///    until then no point of the pair can lie within the breaking distance, so nothing is skipped that Bullet
///    would have added. The test is a dozen products per pair and step, against a GJK search.
/// Contact points themselves are found exactly as Bullet finds them: the same GJK and EPA queries, one point
/// per step, into a persistent manifold.
class ConvexPair final : public btActivatingCollisionAlgorithm {
public:
    ConvexPair(const btCollisionAlgorithmConstructionInfo& info, const btCollisionObjectWrapper* body0,
               const btCollisionObjectWrapper* body1, btConvexPenetrationDepthSolver* penetration)
        : btActivatingCollisionAlgorithm(info, body0, body1), penetration_(penetration)
    {
    }
    ~ConvexPair() override
    {
        if (manifold_) m_dispatcher->releaseManifold(manifold_);
    }

    /// The search of the next processCollision: the gap bound of a pair found apart, else GJK (and EPA). It reads
    /// only this pair and the two hulls, so that the pairs of one step can be searched at the same time.
    /// `object0` and `object1` are the collision objects that hold the hulls (for the breaking distance).
    void search(const btConvexShape& a, const btTransform& ta, const btConvexShape& b, const btTransform& tb, const btCollisionObject& object0,
                const btCollisionObject& object1, btScalar distance_threshold, btIDebugDraw* draw, ConvexPairSearch& out) const
    {
        out = ConvexPairSearch{};
        out.still_apart = apart_ && still_apart(ta, tb);
        if (out.still_apart) return;
        out.breaking = breaking_distance(&object0, &object1);
        btGjkPairDetector::ClosestPointInput input;
        const btScalar reach = a.getMargin() + b.getMargin() + out.breaking + distance_threshold;
        input.m_maximumDistanceSquared = reach * reach;
        input.m_transformA = ta;
        input.m_transformB = tb;
        btVoronoiSimplexSolver simplex;
        btGjkPairDetector gjk(&a, &b, &simplex, penetration_);
        ClosestPoints closest;
        gjk.getClosestPoints(input, closest, draw);
        out.found = closest.found;
        out.axis = closest.found ? closest.normal : gjk.getCachedSeparatingAxis();
        out.point = closest.point;
        out.distance = closest.distance;
    }

    void clear_apart() { apart_ = false; }

    /// What is left of the gap of a pair found apart after the bound of the bodies' motion since then; the pair
    /// is still apart while it is positive. -inf for a pair not found apart.
    double apart_margin(const btTransform& ta, const btTransform& tb) const
    {
        if (!apart_) return -std::numeric_limits<double>::infinity();
        const btVector3 n(normal_[0], normal_[1], normal_[2]);
        const double approach = (n.dot(tb.getOrigin()) - along_b_) - (n.dot(ta.getOrigin()) - along_a_);
        const double turn = (radius_a_ * rotation_change(ta.getBasis(), rotation_a_) + radius_b_ * rotation_change(tb.getBasis(), rotation_b_)) *
                            0.70710678118654752;
        return gap_ - approach - turn;
    }

    /// The same for a pair of two whole bodies (the top-level pairs of a dispatch).
    void search(const btCollisionObject& body0, const btCollisionObject& body1, btIDebugDraw* draw, ConvexPairSearch& out) const
    {
        search(*static_cast<const btConvexShape*>(body0.getCollisionShape()), body0.getWorldTransform(),
               *static_cast<const btConvexShape*>(body1.getCollisionShape()), body1.getWorldTransform(), body0, body1, 0, draw, out);
    }

    void processCollision(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1, const btDispatcherInfo& info,
                          btManifoldResult* result) override
    {
        ConvexPairSearch s;
        search(*static_cast<const btConvexShape*>(body0->getCollisionShape()), body0->getWorldTransform(),
               *static_cast<const btConvexShape*>(body1->getCollisionShape()), body1->getWorldTransform(), *body0->getCollisionObject(),
               *body1->getCollisionObject(), result->m_closestPointDistanceThreshold, info.m_debugDraw, s);
        if (s.still_apart) return;
        apart_ = false;
        finish(take(body0, body1, s, result), body0, body1, s, result);
    }

    /// What processCollision does after its search, in two parts: first whatever touches only this pair's own
    /// manifold (its new point, the refresh of its points, the gap bound of a pair found apart); then, if
    /// that part returns a ManifoldChange, the making or releasing of the manifold (the dispatcher's shared
    /// list). In one call they are the steps of Bullet's convex-convex algorithm, in its order:
    ///  - near (within the breaking distance): a manifold (made if there is none), the point added, the points
    ///    refreshed, and the manifold released if none is left;
    ///  - not near: the points of a manifold refreshed, the manifold released if none is left, then the gap bound
    ///    started.
    ManifoldChange take(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1, const ConvexPairSearch& s,
                        btManifoldResult* result)
    {
        if (near(s)) {
            if (!manifold_) return ManifoldChange::make;
            result->setPersistentManifold(manifold_);
            result->addContactPoint(s.axis, s.point, s.distance);
        }
        if (manifold_) {
            result->setPersistentManifold(manifold_);
            result->refreshContactPoints();
            return manifold_->getNumContacts() > 0 ? ManifoldChange::none : ManifoldChange::release;
        }
        if (result->m_closestPointDistanceThreshold == 0) start_apart(body0, body1, s);
        return ManifoldChange::none;
    }

    void finish(ManifoldChange change, const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1, const ConvexPairSearch& s,
                btManifoldResult* result)
    {
        if (change == ManifoldChange::make) {
            manifold_ = m_dispatcher->getNewManifold(body0->getCollisionObject(), body1->getCollisionObject());
            result->setPersistentManifold(manifold_);
            result->addContactPoint(s.axis, s.point, s.distance);
            result->setPersistentManifold(manifold_);
            result->refreshContactPoints();
            if (manifold_->getNumContacts() > 0) return;
            change = ManifoldChange::release;
        }
        if (change != ManifoldChange::release) return;
        result->setPersistentManifold(nullptr);
        m_dispatcher->releaseManifold(manifold_);
        manifold_ = nullptr;
        if (!near(s) && result->m_closestPointDistanceThreshold == 0) start_apart(body0, body1, s);
    }

    ConvexPairState state() const
    {
        ConvexPairState s;
        std::memset(static_cast<void*>(&s), 0, sizeof s);  // the padding too: a checkpoint's bytes depend on the state only
        s.manifold = manifold_ ? 1 : 0;
        s.apart = apart_ ? 1 : 0;
        s.gap = gap_;
        for (int k = 0; k < 3; ++k) s.normal[k] = normal_[k];
        s.along_a = along_a_;
        s.along_b = along_b_;
        for (int k = 0; k < 9; ++k) {
            s.rotation_a[k] = rotation_a_[k];
            s.rotation_b[k] = rotation_b_[k];
        }
        s.radius_a = radius_a_;
        s.radius_b = radius_b_;
        return s;
    }

    void set_state(const ConvexPairState& s, const btCollisionObject* body0, const btCollisionObject* body1)
    {
        if (manifold_) m_dispatcher->releaseManifold(manifold_);
        manifold_ = s.manifold ? m_dispatcher->getNewManifold(body0, body1) : nullptr;
        apart_ = s.apart != 0;
        gap_ = s.gap;
        for (int k = 0; k < 3; ++k) normal_[k] = s.normal[k];
        along_a_ = s.along_a;
        along_b_ = s.along_b;
        for (int k = 0; k < 9; ++k) {
            rotation_a_[k] = s.rotation_a[k];
            rotation_b_[k] = s.rotation_b[k];
        }
        radius_a_ = s.radius_a;
        radius_b_ = s.radius_b;
    }

    btScalar calculateTimeOfImpact(btCollisionObject*, btCollisionObject*, const btDispatcherInfo&, btManifoldResult*) override
    {
        return 1;  // no continuous collision detection: the step is small against the rocks
    }

    void getAllContactManifolds(btManifoldArray& manifolds) override
    {
        if (manifold_) manifolds.push_back(manifold_);
    }

private:
    /// The contact breaking distance of this pair: its manifold's, or the one Bullet's dispatcher gives a new
    /// manifold of these two objects.
    btScalar breaking_distance(const btCollisionObject* body0, const btCollisionObject* body1) const
    {
        if (manifold_) return manifold_->getContactBreakingThreshold();
        const auto* dispatcher = static_cast<const btCollisionDispatcher*>(m_dispatcher);
        if (!(dispatcher->getDispatcherFlags() & btCollisionDispatcher::CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD))
            return gContactBreakingThreshold;
        return btMin(body0->getCollisionShape()->getContactBreakingThreshold(gContactBreakingThreshold),
                     body1->getCollisionShape()->getContactBreakingThreshold(gContactBreakingThreshold));
    }

    static bool near(const ConvexPairSearch& s) { return s.found && s.distance <= s.breaking; }

    void start_apart(const btCollisionObjectWrapper* body0, const btCollisionObjectWrapper* body1, const ConvexPairSearch& s)
    {
        start_apart(*static_cast<const btConvexShape*>(body0->getCollisionShape()), *static_cast<const btConvexShape*>(body1->getCollisionShape()),
                    body0->getWorldTransform(), body1->getWorldTransform(), s.axis, s.breaking);
    }

    void start_apart(const btConvexShape& a, const btConvexShape& b, const btTransform& ta, const btTransform& tb, const btVector3& axis,
                     btScalar breaking)
    {
        const btScalar length = axis.length();
        if (!(length > 0) || !std::isfinite(length)) return;
        const btVector3 n = axis / length;  // from b towards a
        // a lies on the +n side of b: its lowest point along n against b's highest
        const btVector3 low_a = ta * a.localGetSupportingVertex(-n * ta.getBasis());
        const btVector3 high_b = tb * b.localGetSupportingVertex(n * tb.getBasis());
        const btScalar gap = n.dot(low_a) - n.dot(high_b) - breaking;
        if (!(gap > 0)) return;
        gap_ = gap;
        for (int k = 0; k < 3; ++k) normal_[k] = n[k];
        along_a_ = n.dot(ta.getOrigin());
        along_b_ = n.dot(tb.getOrigin());
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                rotation_a_[3 * i + j] = static_cast<float>(ta.getBasis()[i][j]);
                rotation_b_[3 * i + j] = static_cast<float>(tb.getBasis()[i][j]);
            }
        // rounded up: the bound must not shrink
        radius_a_ = hull_motion_radius(a);
        radius_b_ = hull_motion_radius(b);
        apart_ = true;
    }

    /// |R - R0|_F, with R0 kept in single precision (each entry within 6e-8: the bound adds 1e-6)
    static double rotation_change(const btMatrix3x3& r, const float* r0)
    {
        double sum = 0.0;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                const double d = r[i][j] - static_cast<double>(r0[3 * i + j]);
                sum += d * d;
            }
        return std::sqrt(sum) + 1e-6;
    }

    bool still_apart(const btTransform& ta, const btTransform& tb) const { return apart_margin(ta, tb) > 0; }

    btConvexPenetrationDepthSolver* penetration_;
    btPersistentManifold* manifold_ = nullptr;
    bool apart_ = false;
    double gap_ = 0.0;  ///< separation along normal_ less the breaking distance, when the pair was found apart
    double normal_[3] = {0.0, 0.0, 0.0};
    double along_a_ = 0.0, along_b_ = 0.0;  ///< the origins along normal_ then
    float rotation_a_[9] = {}, rotation_b_[9] = {};
    float radius_a_ = 0.0f, radius_b_ = 0.0f;  ///< of each hull about its origin, margin included
};

}  // namespace

btCollisionAlgorithm* ConvexPairCreateFunc::CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo& info,
                                                                     const btCollisionObjectWrapper* body0,
                                                                     const btCollisionObjectWrapper* body1)
{
    void* memory = sizeof(ConvexPair) <= static_cast<std::size_t>(pool_element_size)
                       ? info.m_dispatcher1->allocateCollisionAlgorithm(static_cast<int>(sizeof(ConvexPair)))
                       : btAlignedAlloc(sizeof(ConvexPair), 16);
    return new (memory) ConvexPair(info, body0, body1, &penetration_solver);
}

double convex_pair_apart_margin(const btCollisionAlgorithm& pair, const btCollisionObject& body0, const btCollisionObject& body1)
{
    return static_cast<const ConvexPair&>(pair).apart_margin(body0.getWorldTransform(), body1.getWorldTransform());
}

bool is_convex_pair(const btCollisionAlgorithm& algorithm) { return dynamic_cast<const ConvexPair*>(&algorithm) != nullptr; }

ConvexPairState convex_pair_state(const btCollisionAlgorithm& pair) { return static_cast<const ConvexPair&>(pair).state(); }

void set_convex_pair_state(btCollisionAlgorithm& pair, const ConvexPairState& state, const btCollisionObject* body0, const btCollisionObject* body1)
{
    static_cast<ConvexPair&>(pair).set_state(state, body0, body1);
}

float hull_motion_radius(const btCollisionShape& shape)
{
    return std::nextafter(static_cast<float>(shape.getAngularMotionDisc()), std::numeric_limits<float>::infinity());
}

ManifoldChange take_convex_pair(btCollisionAlgorithm& pair, const btCollisionObjectWrapper& body0, const btCollisionObjectWrapper& body1,
                                const btDispatcherInfo& info, btManifoldResult& result, ConvexPairSearch& search)
{
    auto& p = static_cast<ConvexPair&>(pair);
    p.search(*body0.getCollisionObject(), *body1.getCollisionObject(), info.m_debugDraw, search);
    if (search.still_apart) return ManifoldChange::none;
    p.clear_apart();
    return p.take(&body0, &body1, search, &result);
}

void finish_convex_pair(btCollisionAlgorithm& pair, ManifoldChange change, const btCollisionObjectWrapper& body0,
                        const btCollisionObjectWrapper& body1, const ConvexPairSearch& search, btManifoldResult& result)
{
    static_cast<ConvexPair&>(pair).finish(change, &body0, &body1, search, &result);
}

}  // namespace dipper::rigid
