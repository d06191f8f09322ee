// Narrow phase of two convex hulls (rocks, and rocks against the plates of machine parts), in place of
// Bullet's own convex-convex algorithm. Not installed; nothing outside rigid/ includes it.
#pragma once

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>

#include <cstdint>

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

/// What the search of a hull pair found: the part of its processCollision that touches no manifold.
struct ConvexPairSearch {
    bool still_apart = false;  ///< the pair's gap bound still clears it: nothing to do this step
    bool found = false;        ///< GJK found closest points within reach
    btVector3 axis{0, 0, 0};   ///< the normal on b when found, else GJK's separating axis
    btVector3 point{0, 0, 0};  ///< closest point on b
    btScalar distance = 0;
    btScalar breaking = 0;     ///< the pair's contact breaking distance (not set when still apart)
};

/// For the pair of two whole bodies (a top-level pair whose algorithm a ConvexPairCreateFunc made): what is left
/// of the gap of a pair found apart once the bound of the bodies' motion since then is taken off. The pair is
/// still apart, and its next processCollision would return at once, while it is positive; -inf when the pair
/// is not in that state. It reads only the pair and the bodies' poses.
double convex_pair_apart_margin(const btCollisionAlgorithm& pair, const btCollisionObject& body0, const btCollisionObject& body1);
/// The radius a ConvexPair's gap bound turns a hull by: its angular motion disc, rounded up to a float.
float hull_motion_radius(const btCollisionShape& shape);

/// A ConvexPair between steps, as a checkpoint keeps it: whether it holds a manifold (whose points are kept with
/// the manifold), and the gap bound of a pair found apart.
struct ConvexPairState {
    std::uint8_t manifold = 0, apart = 0;
    double gap = 0.0, normal[3] = {0.0, 0.0, 0.0}, along_a = 0.0, along_b = 0.0;
    float rotation_a[9] = {}, rotation_b[9] = {}, radius_a = 0.0f, radius_b = 0.0f;
};
/// Whether a collision algorithm is a ConvexPair.
bool is_convex_pair(const btCollisionAlgorithm& algorithm);
ConvexPairState convex_pair_state(const btCollisionAlgorithm& pair);
/// Gives a ConvexPair made for the same two bodies the state another one had; with a manifold, a new empty one
/// of body0 and body1 (as the pair's own making gives it), for the caller to fill.
void set_convex_pair_state(btCollisionAlgorithm& pair, const ConvexPairState& state, const btCollisionObject* body0, const btCollisionObject* body1);

/// What is left of a pair's processCollision after the part that touches only its own manifold.
enum class ManifoldChange { none, make, release };

/// A top-level pair's processCollision in two parts. take_convex_pair does the search and whatever touches only
/// the pair's own manifold; it may run for many pairs at once. finish_convex_pair then makes or releases the
/// manifold where take_convex_pair returned that (the dispatcher's manifold list: one thread, in the pairs'
/// order). The two in a row are processCollision; `search` carries what the first found to the second.
ManifoldChange take_convex_pair(btCollisionAlgorithm& pair, const btCollisionObjectWrapper& body0, const btCollisionObjectWrapper& body1,
                                const btDispatcherInfo& info, btManifoldResult& result, ConvexPairSearch& search);
void finish_convex_pair(btCollisionAlgorithm& pair, ManifoldChange change, const btCollisionObjectWrapper& body0,
                        const btCollisionObjectWrapper& body1, const ConvexPairSearch& search, btManifoldResult& result);

}  // namespace dipper::rigid
