// Bullet's collision dispatcher with the narrow phase of one step spread over threads. Not installed; nothing
// outside rigid/ includes it.
#pragma once

#include "core/state_io.h"
#include "rigid/detail/convex_pair.h"

#include <btBulletCollisionCommon.h>

#include <cstdint>
#include <mutex>
#include <vector>

namespace dipper::rigid {

/// Runs the narrow phase of a step in two passes over the overlapping pairs, so that most of it runs on
/// several threads and the step still gives the same bits as Bullet's own one-pass dispatch:
///  1. on `threads` threads, each pair on its own: the needsCollision check; whole pairs whose work touches
///     only their own persistent manifold (a hull against a triangle mesh or a plane: Bullet's convex-concave
///     and convex-plane algorithms, whose manifold exists from the pair's start); for hull-hull pairs of
///     dipper's ConvexPair, the gap bound, the search and the pair's own manifold's points;
///  2. on one thread, in the pair array's order, as Bullet's dispatch does: whatever makes or releases a
///     manifold (a hull pair coming into or out of contact, a new pair, compound shapes, every other kind).
/// Before both, a hull pair found apart is passed over unread while its bodies' odometers show too little motion
/// to have closed its gap (dispatcher.cpp).
/// Each manifold receives the same points as in Bullet's dispatch, and the dispatcher's manifold list changes
/// in the same order, so the solver sees the same rows in the same order: the same bits on any number of
/// threads. One thread: Bullet's own dispatch.
class Dispatcher final : public btCollisionDispatcher {
public:
    /// `dipper_pairs`: hull-hull pairs are dipper's ConvexPair (RigidSettings::bullet_convex_pairs false).
    Dispatcher(btCollisionConfiguration* config, int threads, bool dipper_pairs)
        : btCollisionDispatcher(config), threads_(threads), dipper_pairs_(dipper_pairs)
    {
    }

    /// The collision objects whose motion the odometers follow (the world's; set once the world exists).
    void watch(const btCollisionObjectArray* objects) { objects_ = objects; }

    void dispatchAllCollisionPairs(btOverlappingPairCache* pairs, const btDispatcherInfo& info, btDispatcher* dispatcher) override;
    /// Bullet's test, and two fixed bodies never: a rock frozen in place (RigidWorld::set_frozen) keeps its pairs
    /// with the ground and other frozen rocks, manifolds included, untouched until it is let go.
    bool needsCollision(const btCollisionObject* body0, const btCollisionObject* body1) override
    {
        auto fixed = [](const btCollisionObject* o) { return o->isStaticObject() && !o->isKinematicObject(); };
        if (fixed(body0) && fixed(body1) && !restoring_) return false;
        return btCollisionDispatcher::needsCollision(body0, body1);
    }

    /// While a checkpoint's contacts are put back (rigid/detail/contact_state.cpp), the pairs of two fixed bodies
    /// are made as when one of them was still free: a frozen rock's algorithms and manifolds as it left them.
    void set_restoring(bool restoring) { restoring_ = restoring; }
    /// The odometers and whether thresholds are kept, for checkpoints: the proxies' unique ids are the same in a
    /// world built the same way, so they are kept by id.
    void write_odometers(StateWriter& out) const;
    void read_odometers(StateReader& in);

    // the algorithm pool is shared: locked while pass 1 runs (a hull against a mesh makes one per triangle)
    void* allocateCollisionAlgorithm(int size) override;
    void freeCollisionAlgorithm(void* ptr) override;

private:
    /// What a pair needs this step: nothing; nothing more (done in pass 1); hull-hull (dipper's ConvexPair);
    /// a manifold made or released in pass 2; all of it in pass 2.
    enum class Work : std::uint8_t { none, done, hulls, make_manifold, release_manifold, serial };
    void process(btBroadphasePair& pair, const btDispatcherInfo& info);
    Work kind(const btBroadphasePair& pair) const;
    void update_odometers();
    double moved(const btBroadphasePair& pair) const;
    bool clear_by_odometers(const btBroadphasePair& pair) const;
    void note_gap(btBroadphasePair& pair) const;
    void note_surface_gap(btBroadphasePair& pair) const;
    void clear_thresholds(btOverlappingPairCache* pairs);

    int threads_;
    bool dipper_pairs_;
    bool parallel_ = false;  ///< pass 1 is running
    std::mutex pool_;
    std::vector<Work> work_;                   ///< of each pair, this step
    std::vector<ConvexPairSearch> searches_;  ///< of each hull pair searched in pass 1, for pass 2

    // Odometers: for each broad-phase proxy (by its unique id), the distance its origin has travelled plus its
    // hull's radius times the Frobenius norm of each step's change of rotation, summed over the steps. The
    // motion of two bodies between two steps is bounded by the growth of their odometers, so a hull pair found
    // apart can be passed over while that growth stays below what is left of its gap, without reading the pair
    // (rigid/detail/dispatcher.cpp).
    const btCollisionObjectArray* objects_ = nullptr;
    std::vector<double> odometer_, radius_;
    std::vector<btTransform> previous_;
    std::vector<const btCollisionShape*> shape_;
    bool thresholds_set_ = false;  ///< some pair holds a threshold (the two-pass dispatch ran)
    bool restoring_ = false;
};

}  // namespace dipper::rigid
