// Bullet's contact history in a checkpoint: what a resumed run needs to take the same steps as the run that
// was not stopped, bit for bit.
//
// Bullet carries from one step to the next more than the bodies' poses and velocities: the broad phase's trees
// (whose shape decides the order in which new pairs are found), its stage lists and cleanup cursor, the pair
// array in its order (the narrow phase and the making of manifolds follow it), each pair's collision algorithm
// (a compound's child algorithms, dipper's ConvexPair's gap bound), the dispatcher's manifold list in its order
// (the solver sweeps its rows in that order), every manifold's points with their warm-starting impulses and
// friction directions, and the dispatcher's odometers. All of it is written here and put back exactly: the
// trees node by node, the pairs in their order, the algorithms made again as the dispatcher makes them and then
// given their state, the manifolds matched to their algorithms and put in their order. Pointers are written as
// body ids (dipper's, in each collision object's user index 2).
#include "rigid/detail/world_impl.h"

#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletCollision/CollisionDispatch/btCompoundCollisionAlgorithm.h>
#include <BulletCollision/CollisionDispatch/btCompoundCompoundCollisionAlgorithm.h>

#include <map>
#include <optional>
#include <tuple>

namespace dipper::rigid {

namespace {

/// A compound's child algorithms (protected in Bullet): its children are made and dropped as their boxes meet.
struct CompoundAccess : btCompoundCollisionAlgorithm {
    static btAlignedObjectArray<btCollisionAlgorithm*>& children(btCompoundCollisionAlgorithm& a)
    {
        return a.*(&CompoundAccess::m_childCollisionAlgorithms);
    }
};

/// A compound against a single shape (not Bullet's compound-compound algorithm, which keeps its children apart)
btCompoundCollisionAlgorithm* as_compound(btCollisionAlgorithm* a)
{
    if (dynamic_cast<btCompoundCompoundCollisionAlgorithm*>(a)) return nullptr;
    return dynamic_cast<btCompoundCollisionAlgorithm*>(a);
}

/// How a pair's algorithm is written: none, dipper's ConvexPair, one of Bullet's that makes its manifold with
/// itself (convex-plane, convex-concave), a compound followed by its child count and each child's code.
enum Code : std::int32_t { kNone = 0, kConvexPair = 1, kOther = 2, kCompound = 3 };

int body_id(const btCollisionObject* o) { return o ? o->getUserIndex2() : -1; }

struct SavedNode {
    double lo[4], hi[4];
    std::int32_t body;  ///< -1: an inner node, its two children follow
    std::int32_t unused = 0;
};

struct SavedPair {
    std::int32_t body0, body1;
    std::uint64_t info;  ///< the pair's spare word (the dispatcher's threshold)
};

/// A manifold: where it hangs (pair, child or -1, its place among that algorithm's manifolds), its bodies, its
/// thresholds and its number of points.
struct SavedManifold {
    std::int32_t pair, child, ordinal, body0, body1, points;
    double breaking, processing;
};

struct SavedPoint {
    double vectors[7][4];  // local A, local B, world on B, world on A, normal on B, friction directions 1 and 2
    double distance, friction, rolling, spinning, restitution, impulse, previous_rhs, lateral1, lateral2, motion1, motion2, cfm, erp,
        friction_cfm;
    std::int32_t part0, part1, index0, index1, flags, life;
};

SavedPoint save_point(const btManifoldPoint& p)
{
    SavedPoint s{};
    const btVector3* v[7] = {&p.m_localPointA, &p.m_localPointB, &p.m_positionWorldOnB, &p.m_positionWorldOnA, &p.m_normalWorldOnB,
                             &p.m_lateralFrictionDir1, &p.m_lateralFrictionDir2};
    for (int k = 0; k < 7; ++k)
        for (int c = 0; c < 4; ++c) s.vectors[k][c] = v[k]->m_floats[c];
    s.distance = p.m_distance1;
    s.friction = p.m_combinedFriction;
    s.rolling = p.m_combinedRollingFriction;
    s.spinning = p.m_combinedSpinningFriction;
    s.restitution = p.m_combinedRestitution;
    s.impulse = p.m_appliedImpulse;
    s.previous_rhs = p.m_prevRHS;
    s.lateral1 = p.m_appliedImpulseLateral1;
    s.lateral2 = p.m_appliedImpulseLateral2;
    s.motion1 = p.m_contactMotion1;
    s.motion2 = p.m_contactMotion2;
    s.cfm = p.m_contactCFM;
    s.erp = p.m_contactERP;
    s.friction_cfm = p.m_frictionCFM;
    s.part0 = p.m_partId0;
    s.part1 = p.m_partId1;
    s.index0 = p.m_index0;
    s.index1 = p.m_index1;
    s.flags = p.m_contactPointFlags;
    s.life = p.m_lifeTime;
    return s;
}

void load_point(const SavedPoint& s, btManifoldPoint& p)
{
    p = btManifoldPoint();
    btVector3* v[7] = {&p.m_localPointA, &p.m_localPointB, &p.m_positionWorldOnB, &p.m_positionWorldOnA, &p.m_normalWorldOnB,
                       &p.m_lateralFrictionDir1, &p.m_lateralFrictionDir2};
    for (int k = 0; k < 7; ++k)
        for (int c = 0; c < 4; ++c) v[k]->m_floats[c] = s.vectors[k][c];
    p.m_distance1 = s.distance;
    p.m_combinedFriction = s.friction;
    p.m_combinedRollingFriction = s.rolling;
    p.m_combinedSpinningFriction = s.spinning;
    p.m_combinedRestitution = s.restitution;
    p.m_appliedImpulse = s.impulse;
    p.m_prevRHS = s.previous_rhs;
    p.m_appliedImpulseLateral1 = s.lateral1;
    p.m_appliedImpulseLateral2 = s.lateral2;
    p.m_contactMotion1 = s.motion1;
    p.m_contactMotion2 = s.motion2;
    p.m_contactCFM = s.cfm;
    p.m_contactERP = s.erp;
    p.m_frictionCFM = s.friction_cfm;
    p.m_partId0 = s.part0;
    p.m_partId1 = s.part1;
    p.m_index0 = s.index0;
    p.m_index1 = s.index1;
    p.m_contactPointFlags = s.flags;
    p.m_lifeTime = s.life;
}

void save_tree(const btDbvtNode* node, std::vector<SavedNode>& out)
{
    if (!node) return;
    SavedNode s{};
    for (int c = 0; c < 4; ++c) {
        s.lo[c] = node->volume.Mins().m_floats[c];
        s.hi[c] = node->volume.Maxs().m_floats[c];
    }
    s.body = node->isleaf() ? body_id(static_cast<const btCollisionObject*>(static_cast<btDbvtProxy*>(node->data)->m_clientObject)) : -1;
    if (node->isleaf() && s.body < 0) s.body = -2;  // a proxy of no body: refused when read
    out.push_back(s);
    if (!node->isleaf()) {
        save_tree(node->childs[0], out);
        save_tree(node->childs[1], out);
    }
}

/// The manifolds of a pair's algorithm, each with its child (-1 for the algorithm itself) and its place there.
template <class Visit>
void each_manifold(btCollisionAlgorithm* algorithm, Visit visit)
{
    if (!algorithm) return;
    btManifoldArray found;
    if (btCompoundCollisionAlgorithm* compound = as_compound(algorithm)) {
        auto& children = CompoundAccess::children(*compound);
        for (int c = 0; c < children.size(); ++c) {
            if (!children[c]) continue;
            found.resize(0);
            children[c]->getAllContactManifolds(found);
            for (int k = 0; k < found.size(); ++k) visit(found[k], c, k);
        }
        return;
    }
    algorithm->getAllContactManifolds(found);
    for (int k = 0; k < found.size(); ++k) visit(found[k], -1, k);
}

/// The broad phase's counters between steps, listed once for writing, reading and putting back.
auto counters(btDbvtBroadphase& bp)
{
    return std::tie(bp.m_stageCurrent, bp.m_fupdates, bp.m_dupdates, bp.m_cupdates, bp.m_newpairs, bp.m_fixedleft, bp.m_updates_call,
                    bp.m_updates_done, bp.m_updates_ratio, bp.m_pid, bp.m_cid, bp.m_gid, bp.m_needcleanup);
}

std::int32_t code_of(btCollisionAlgorithm* a) { return !a ? kNone : is_convex_pair(*a) ? kConvexPair : as_compound(a) ? kCompound : kOther; }

}  // namespace

void write_contact_state(const RigidWorld::Impl& impl, StateWriter& out)
{
    auto& w = const_cast<RigidWorld::Impl&>(impl);  // Bullet's readers are not const; nothing is changed
    out.tag("rigid contacts");
    btDbvtBroadphase& bp = w.broadphase;

    // the broad phase: each body's proxy (unique id, box, stage), the two trees node by node, the stage lists
    std::vector<std::int32_t> ids, stages;
    std::vector<double> boxes;
    for (const auto& b : w.bodies) {
        const auto* p = static_cast<const btDbvtProxy*>(b->object()->getBroadphaseHandle());
        ids.push_back(p ? p->m_uniqueId : -1);  // every body is in the world: -1 is refused when read
        stages.push_back(p ? p->stage : -1);
        for (int c = 0; c < 8; ++c) boxes.push_back(p ? (c < 4 ? p->m_aabbMin : p->m_aabbMax).m_floats[c % 4] : 0.0);
    }
    out(ids, stages, boxes);
    for (const btDbvt& tree : bp.m_sets) {
        std::vector<SavedNode> nodes;
        save_tree(tree.m_root, nodes);
        out(nodes, tree.m_lkhd, tree.m_leaves, tree.m_opath);
    }
    for (const btDbvtProxy* root : bp.m_stageRoots) {
        std::vector<std::int32_t> list;
        for (const btDbvtProxy* p = root; p; p = p->links[1]) list.push_back(body_id(static_cast<const btCollisionObject*>(p->m_clientObject)));
        out(list);
    }
    std::apply([&](const auto&... c) { out(c...); }, counters(bp));

    // the pairs in their order, each with its algorithm; ConvexPairs' states in the order met
    btBroadphasePairArray& pairs = bp.getOverlappingPairCache()->getOverlappingPairArray();
    std::vector<SavedPair> saved_pairs;
    std::vector<std::int32_t> codes;
    std::vector<ConvexPairState> convex;
    std::map<const btPersistentManifold*, std::tuple<int, int, int>> place;
    for (int i = 0; i < pairs.size(); ++i) {
        const btBroadphasePair& pair = pairs[i];
        SavedPair s{body_id(static_cast<const btCollisionObject*>(pair.m_pProxy0->m_clientObject)),
                    body_id(static_cast<const btCollisionObject*>(pair.m_pProxy1->m_clientObject)), 0};
        std::memcpy(&s.info, &pair.m_internalInfo1, sizeof s.info);
        saved_pairs.push_back(s);
        btCollisionAlgorithm* a = pair.m_algorithm;
        codes.push_back(code_of(a));
        if (codes.back() == kConvexPair) convex.push_back(convex_pair_state(*a));
        if (codes.back() == kCompound) {
            auto& children = CompoundAccess::children(*as_compound(a));
            codes.push_back(children.size());
            for (int c = 0; c < children.size(); ++c) {
                const std::int32_t code = code_of(children[c]);
                codes.push_back(code == kCompound ? kOther : code);  // a compound in a compound: not dipper's shapes
                if (code == kConvexPair) convex.push_back(convex_pair_state(*children[c]));
            }
        }
        each_manifold(a, [&](btPersistentManifold* m, int child, int k) { place[m] = {i, child, k}; });
    }
    out(saved_pairs, codes, convex);

    // the manifolds in the dispatcher's order, with their points
    std::vector<SavedManifold> manifolds;
    std::vector<SavedPoint> points;
    for (int i = 0; i < w.dispatcher.getNumManifolds(); ++i) {
        const btPersistentManifold* m = w.dispatcher.getManifoldByIndexInternal(i);
        const auto at = place.find(m);
        SavedManifold s{-1, -1, -1, body_id(m->getBody0()), body_id(m->getBody1()), m->getNumContacts(), m->getContactBreakingThreshold(),
                        m->getContactProcessingThreshold()};
        if (at != place.end()) std::tie(s.pair, s.child, s.ordinal) = at->second;
        manifolds.push_back(s);
        for (int k = 0; k < m->getNumContacts(); ++k) points.push_back(save_point(m->getContactPoint(k)));
    }
    out(manifolds, points);
    w.dispatcher.write_odometers(out);
}

void read_contact_state(RigidWorld::Impl& w, StateReader& in)
{
    // Everything is read and checked first, so that a checkpoint refused leaves Bullet's structures whole
    in.tag("rigid contacts");
    btDbvtBroadphase& bp = w.broadphase;
    btOverlappingPairCache* cache = bp.getOverlappingPairCache();
    const auto n = w.bodies.size();
    auto proxy_of = [&](std::int32_t id, const char* what) {
        if (id < 0 || static_cast<std::size_t>(id) >= n) in.fail(concat(what, " of rigid body ", id, "; the world has ", n));
        auto* p = static_cast<btDbvtProxy*>(w.bodies[static_cast<std::size_t>(id)]->object()->getBroadphaseHandle());
        if (!p) in.fail(concat("rigid body '", w.bodies[static_cast<std::size_t>(id)]->name, "' is not in the world"));
        return p;
    };

    // the broad phase: proxies, trees (each a preorder: a node, then its two subtrees), stage lists, counters
    std::vector<std::int32_t> ids, stages;
    std::vector<double> boxes;
    in(ids, stages, boxes);
    if (ids.size() != n || stages.size() != n || boxes.size() != 8 * n) in.fail("broad-phase proxies of another number of rigid bodies");
    for (std::size_t b = 0; b < n; ++b) {
        const btDbvtProxy* p = proxy_of(static_cast<std::int32_t>(b), "a proxy");
        if (p->m_uniqueId != ids[b])
            in.fail(concat("rigid body '", w.bodies[b]->name, "' has proxy ", p->m_uniqueId, " where the checkpoint has ", ids[b],
                           ": a world built in another order"));
        if (stages[b] < 0 || stages[b] > btDbvtBroadphase::STAGECOUNT) in.fail(concat("a broad-phase stage of ", stages[b]));
    }
    struct Tree {
        std::vector<SavedNode> nodes;
        int lookahead = 0, leaves = 0;
        unsigned path = 0;
    };
    Tree trees[2];
    std::vector<int> tree_of(n, -1);
    for (int t = 0; t < 2; ++t) {
        Tree& tree = trees[t];
        in(tree.nodes, tree.lookahead, tree.leaves, tree.path);
        std::size_t open = tree.nodes.empty() ? 0 : 1;  // subtrees still to come
        int leaf_count = 0;
        for (const SavedNode& node : tree.nodes) {
            if (open == 0) in.fail("a broad-phase tree with nodes left over");
            --open;
            if (node.body == -1) {
                open += 2;
                continue;
            }
            proxy_of(node.body, "a tree leaf");
            int& where = tree_of[static_cast<std::size_t>(node.body)];
            if (where >= 0) in.fail(concat("rigid body ", node.body, " twice in the broad phase's trees"));
            where = t;
            ++leaf_count;
        }
        if (open != 0 || leaf_count != tree.leaves) in.fail("a broad-phase tree whose nodes do not add up");
    }
    for (std::size_t b = 0; b < n; ++b)
        if (tree_of[b] != (stages[b] == btDbvtBroadphase::STAGECOUNT ? 1 : 0))
            in.fail(concat("rigid body '", w.bodies[b]->name, "' in the wrong broad-phase tree, or in none"));
    std::vector<std::int32_t> lists[btDbvtBroadphase::STAGECOUNT + 1];
    std::vector<int> listed(n, 0);
    for (int stage = 0; stage <= btDbvtBroadphase::STAGECOUNT; ++stage) {
        in(lists[stage]);
        for (std::int32_t id : lists[stage]) {
            proxy_of(id, "a stage list");
            if (stages[static_cast<std::size_t>(id)] != stage || listed[static_cast<std::size_t>(id)]++)
                in.fail(concat("rigid body ", id, " in the wrong broad-phase stage list, or twice"));
        }
    }
    for (std::size_t b = 0; b < n; ++b)
        if (!listed[b]) in.fail(concat("rigid body '", w.bodies[b]->name, "' in no broad-phase stage list"));
    // the counters read into copies, put back once everything is checked
    auto read = std::apply([](const auto&... c) { return std::make_tuple(c...); }, counters(bp));
    std::apply([&](auto&... c) { in(c...); }, read);
    const auto& [stage_current, fixed_updates, dynamic_updates, cleanup_updates, new_pairs, fixed_left, calls, done, ratio, parse, cleanup,
                 generation, need_cleanup] = read;
    (void)calls, (void)done, (void)ratio, (void)parse, (void)need_cleanup;  // statistics and flags: any value will do
    if (stage_current < 0 || stage_current >= btDbvtBroadphase::STAGECOUNT) in.fail(concat("a broad-phase stage of ", stage_current));
    for (int percent : {fixed_updates, dynamic_updates, cleanup_updates})
        if (percent < 0 || percent > 100) in.fail(concat("a broad-phase update share of ", percent, " %"));
    if (new_pairs < 0 || fixed_left < 0 || cleanup < 0 || generation < 0) in.fail("a negative broad-phase counter");

    std::vector<SavedPair> saved_pairs;
    std::vector<std::int32_t> codes;
    std::vector<ConvexPairState> convex;
    in(saved_pairs, codes, convex);
    for (const SavedPair& p : saved_pairs) {
        proxy_of(p.body0, "a pair");
        proxy_of(p.body1, "a pair");
        if (p.body0 == p.body1) in.fail(concat("a pair of rigid body ", p.body0, " with itself"));
    }
    std::vector<SavedManifold> manifolds;
    std::vector<SavedPoint> points;
    in(manifolds, points);
    std::map<std::tuple<int, int, int>, const SavedManifold*> saved_place;
    for (const SavedManifold& m : manifolds) {
        proxy_of(m.body0, "a manifold");
        proxy_of(m.body1, "a manifold");
        saved_place[{m.pair, m.child, m.ordinal}] = &m;
    }

    // what the world holds now goes: its pairs, with their algorithms and manifolds
    while (cache->getNumOverlappingPairs() > 0) {
        const btBroadphasePair& last = cache->getOverlappingPairArray()[cache->getNumOverlappingPairs() - 1];
        cache->removeOverlappingPair(last.m_pProxy0, last.m_pProxy1, &w.dispatcher);
    }
    if (w.dispatcher.getNumManifolds() != 0) in.fail("contact manifolds that belong to no pair");

    // the broad phase as it was
    for (std::size_t b = 0; b < n; ++b) {
        btDbvtProxy* p = proxy_of(static_cast<std::int32_t>(b), "a proxy");
        p->stage = stages[b];
        for (int c = 0; c < 4; ++c) {
            p->m_aabbMin.m_floats[c] = boxes[8 * b + static_cast<std::size_t>(c)];
            p->m_aabbMax.m_floats[c] = boxes[8 * b + 4 + static_cast<std::size_t>(c)];
        }
    }
    for (int t = 0; t < 2; ++t) {
        btDbvt& tree = bp.m_sets[t];
        tree.clear();
        std::vector<btDbvtNode**> slots{&tree.m_root};  // where the next node goes
        std::vector<btDbvtNode*> parents{nullptr};
        for (const SavedNode& s : trees[t].nodes) {
            btDbvtNode** slot = slots.back();
            btDbvtNode* parent = parents.back();
            slots.pop_back();
            parents.pop_back();
            auto* node = new (btAlignedAlloc(sizeof(btDbvtNode), 16)) btDbvtNode();
            node->parent = parent;
            node->volume = btDbvtVolume::FromMM(btVector3(s.lo[0], s.lo[1], s.lo[2]), btVector3(s.hi[0], s.hi[1], s.hi[2]));
            node->volume.tMins().m_floats[3] = s.lo[3];
            node->volume.tMaxs().m_floats[3] = s.hi[3];
            node->childs[0] = node->childs[1] = nullptr;
            *slot = node;
            if (s.body >= 0) {
                btDbvtProxy* p = proxy_of(s.body, "a tree leaf");
                node->data = p;
                p->leaf = node;
            } else {
                slots.push_back(&node->childs[1]);
                parents.push_back(node);
                slots.push_back(&node->childs[0]);
                parents.push_back(node);
            }
        }
        tree.m_leaves = trees[t].leaves;
        tree.m_lkhd = trees[t].lookahead;
        tree.m_opath = trees[t].path;
    }
    for (int stage = 0; stage <= btDbvtBroadphase::STAGECOUNT; ++stage) {
        btDbvtProxy*& root = bp.m_stageRoots[stage];
        root = nullptr;
        btDbvtProxy* previous = nullptr;
        for (std::int32_t id : lists[stage]) {
            btDbvtProxy* p = proxy_of(id, "a stage list");
            p->links[0] = previous;
            p->links[1] = nullptr;
            if (previous) previous->links[1] = p;
            else root = p;
            previous = p;
        }
    }
    counters(bp) = read;

    // the pairs in their order, and their algorithms as the dispatcher makes them (a frozen rock's as when it
    // was free), given their state
    std::size_t code_at = 0, convex_at = 0;
    auto next_code = [&]() {
        if (code_at >= codes.size()) in.fail("pair algorithms cut short");
        return codes[code_at++];
    };
    auto next_convex = [&]() -> const ConvexPairState& {
        if (convex_at >= convex.size()) in.fail("pair states cut short");
        return convex[convex_at++];
    };
    auto object_of = [&](std::int32_t id) -> const btCollisionObject* {
        return id >= 0 && static_cast<std::size_t>(id) < n ? w.bodies[static_cast<std::size_t>(id)]->object() : nullptr;
    };
    auto give_state = [&](btCollisionAlgorithm* a, int pair, int child) {
        const ConvexPairState& s = next_convex();
        const auto m = saved_place.find({pair, child, 0});
        if (s.manifold && m == saved_place.end()) in.fail("a pair's manifold missing from the manifold list");
        set_convex_pair_state(*a, s, s.manifold ? object_of(m->second->body0) : nullptr, s.manifold ? object_of(m->second->body1) : nullptr);
    };
    // Bullet's convex-convex algorithm (a hull against a box of the shovel's links) makes its manifold in its
    // first processCollision: one call makes it, and the points it adds are replaced by the checkpoint's below
    auto prime = [&](btCollisionAlgorithm* a, int pair, int child, const btCollisionObjectWrapper& wa, const btCollisionObjectWrapper& wb) {
        if (!saved_place.count({pair, child, 0})) return;
        btManifoldArray found;
        a->getAllContactManifolds(found);
        if (found.size() > 0) return;
        btManifoldResult result(&wa, &wb);
        a->processCollision(&wa, &wb, w.world.getDispatchInfo(), &result);
    };
    struct Restoring {
        Dispatcher& d;
        explicit Restoring(Dispatcher& dispatcher) : d(dispatcher) { d.set_restoring(true); }
        ~Restoring() { d.set_restoring(false); }
    };
    std::optional<Restoring> restoring(std::in_place, w.dispatcher);
    for (std::size_t i = 0; i < saved_pairs.size(); ++i) {
        const SavedPair& s = saved_pairs[i];
        btBroadphasePair* pair = cache->addOverlappingPair(proxy_of(s.body0, "a pair"), proxy_of(s.body1, "a pair"));
        if (!pair || cache->getNumOverlappingPairs() != static_cast<int>(i) + 1 || &cache->getOverlappingPairArray()[static_cast<int>(i)] != pair)
            in.fail(concat("the pair of rigid bodies ", s.body0, " and ", s.body1, " is not one the world makes"));
        std::memcpy(&pair->m_internalInfo1, &s.info, sizeof s.info);
        const std::int32_t code = next_code();
        if (code == kNone) continue;
        auto* a = static_cast<btCollisionObject*>(pair->m_pProxy0->m_clientObject);
        auto* b = static_cast<btCollisionObject*>(pair->m_pProxy1->m_clientObject);
        btCollisionObjectWrapper wa(nullptr, a->getCollisionShape(), a, a->getWorldTransform(), -1, -1);
        btCollisionObjectWrapper wb(nullptr, b->getCollisionShape(), b, b->getWorldTransform(), -1, -1);
        pair->m_algorithm = w.dispatcher.findAlgorithm(&wa, &wb, nullptr, BT_CONTACT_POINT_ALGORITHMS);
        if (code_of(pair->m_algorithm) != code) in.fail(concat("the pair of rigid bodies ", s.body0, " and ", s.body1, " has another algorithm"));
        if (code == kConvexPair) give_state(pair->m_algorithm, static_cast<int>(i), -1);
        if (code == kOther) prime(pair->m_algorithm, static_cast<int>(i), -1, wa, wb);
        if (code != kCompound) continue;
        // a compound's children as its processCollision makes them: each child shape with the other object
        btCompoundCollisionAlgorithm& compound = *as_compound(pair->m_algorithm);
        auto& children = CompoundAccess::children(compound);
        const std::int32_t count = next_code();
        const bool swapped = !a->getCollisionShape()->isCompound();
        const btCollisionObjectWrapper& whole = swapped ? wb : wa;
        const btCollisionObjectWrapper& other = swapped ? wa : wb;
        const auto* shape = static_cast<const btCompoundShape*>(whole.getCollisionShape());
        if (count != shape->getNumChildShapes() || count != children.size()) in.fail("a compound pair of another number of children");
        for (int c = 0; c < count; ++c) {
            const std::int32_t child_code = next_code();
            if (children[c]) {
                children[c]->~btCollisionAlgorithm();
                w.dispatcher.freeCollisionAlgorithm(children[c]);
                children[c] = nullptr;
            }
            if (child_code == kNone) continue;
            const btTransform pose = whole.getWorldTransform() * shape->getChildTransform(c);
            btCollisionObjectWrapper part(&whole, shape->getChildShape(c), whole.getCollisionObject(), pose, -1, c);
            children[c] = w.dispatcher.findAlgorithm(&part, &other, nullptr, BT_CONTACT_POINT_ALGORITHMS);
            const std::int32_t made = code_of(children[c]);
            if ((made == kCompound ? kOther : made) != child_code) in.fail("a compound's child with another algorithm");
            if (child_code == kConvexPair) give_state(children[c], static_cast<int>(i), c);
            if (child_code == kOther) prime(children[c], static_cast<int>(i), c, part, other);
        }
    }
    restoring.reset();
    if (code_at != codes.size() || convex_at != convex.size()) in.fail("pair algorithms left over");

    // the manifolds: each matched to its algorithm, put in the checkpoint's order and given its points. Bullet's
    // compound-compound algorithm (a part of plates against another) makes its children's manifolds only as it
    // steps: those few start empty, after the others (docs/limits.md).
    std::map<std::tuple<int, int, int>, btPersistentManifold*> made;
    btBroadphasePairArray& pairs = cache->getOverlappingPairArray();
    for (int i = 0; i < pairs.size(); ++i)
        each_manifold(pairs[i].m_algorithm, [&](btPersistentManifold* m, int child, int k) { made[{i, child, k}] = m; });
    const int count = w.dispatcher.getNumManifolds();
    btPersistentManifold** list = w.dispatcher.getInternalManifoldPointer();
    std::vector<btPersistentManifold*> order;
    std::map<const btPersistentManifold*, bool> placed;
    std::size_t point_at = 0;
    for (const SavedManifold& s : manifolds) {
        if (s.points < 0 || s.points > MANIFOLD_CACHE_SIZE || points.size() - point_at < static_cast<std::size_t>(s.points))
            in.fail(concat("a contact manifold of ", s.points, " points"));
        const std::size_t first = point_at;
        point_at += static_cast<std::size_t>(s.points);
        const auto m = made.find({s.pair, s.child, s.ordinal});
        if (m == made.end() || placed[m->second]) continue;
        btPersistentManifold* manifold = m->second;
        if (body_id(manifold->getBody0()) != s.body0 || body_id(manifold->getBody1()) != s.body1)
            in.fail(concat("a contact manifold of rigid bodies ", s.body0, " and ", s.body1, " made for others"));
        placed[manifold] = true;
        order.push_back(manifold);
        manifold->setContactBreakingThreshold(s.breaking);
        manifold->setContactProcessingThreshold(s.processing);
        manifold->setNumContacts(s.points);
        for (int k = 0; k < s.points; ++k) load_point(points[first + static_cast<std::size_t>(k)], manifold->getContactPoint(k));
    }
    for (int i = 0; i < count; ++i)
        if (!placed[list[i]]) order.push_back(list[i]);
    for (int i = 0; i < count; ++i) {
        list[i] = order[static_cast<std::size_t>(i)];
        list[i]->m_index1a = i;
    }
    if (point_at != points.size()) in.fail("contact points left over");
    w.dispatcher.read_odometers(in);
}

}  // namespace dipper::rigid