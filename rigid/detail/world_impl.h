// The inside of RigidWorld, shared by the files of rigid/ that talk to Bullet (rigid_world.cpp,
// rope_shovel.cpp). Not installed; nothing outside rigid/ includes it.
#pragma once

#include "core/errors.h"
#include "meshes/triangle_locator.h"
#include "rigid/rigid_world.h"
#include "rigid/detail/convex_pair.h"
#include "rigid/detail/dispatcher.h"
#include "rigid/detail/dynamics_world.h"

#include <btBulletDynamicsCommon.h>
#include <BulletCollision/CollisionDispatch/btInternalEdgeUtility.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <LinearMath/btPoolAllocator.h>

#include <deque>
#include <memory>
#include <string>
#include <vector>

static_assert(sizeof(btScalar) == sizeof(double), "dipper links Bullet's double-precision build (BT_USE_DOUBLE_PRECISION)");

namespace dipper::rigid {

inline btVector3 to_bt(const Vec3& v) { return {v.x, v.y, v.z}; }
inline Vec3 from_bt(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
inline btMatrix3x3 to_bt(const Mat3& m)
{
    return {m.m[0][0], m.m[0][1], m.m[0][2], m.m[1][0], m.m[1][1], m.m[1][2], m.m[2][0], m.m[2][1], m.m[2][2]};
}
inline Mat3 from_bt(const btMatrix3x3& b)
{
    Mat3 m;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.m[i][j] = b[i][j];
    return m;
}

/// Friction and restitution per material pair; Bullet's contact callback reads it through the bodies'
/// user pointer.
struct MaterialPairs {
    std::vector<std::string> names;
    std::vector<double> friction, restitution;  // names x names
    std::vector<bool> set;
    std::size_t index(int a, int b) const { return static_cast<std::size_t>(a) * names.size() + static_cast<std::size_t>(b); }
};

struct ShovelState;  // rope_shovel.cpp
struct ShovelDeleter {
    void operator()(ShovelState* s) const;
};

struct RigidWorld::Impl {
    struct Body {
        std::string name;
        int material = 0;
        bool kinematic = false;
        double margin_m = 0.0;
        std::vector<int> indices;
        std::vector<btScalar> vertices;
        std::unique_ptr<btTriangleIndexVertexArray> mesh_data;
        std::unique_ptr<btTriangleInfoMap> edge_info;
        std::unique_ptr<btCollisionShape> shape;
        std::vector<std::unique_ptr<btCollisionShape>> children;  // of a compound shape
        std::unique_ptr<meshes::TriangleLocator> locator;          // of the last wear mesh asked for
        const meshes::TriangleMesh* located_mesh = nullptr;
        std::unique_ptr<btDefaultMotionState> motion;  ///< of static and kinematic bodies only
        std::unique_ptr<btRigidBody> body;  ///< rocks, static and kinematic parts
        // a link of a multibody (the shovel's dipper and door) instead of a rigid body
        std::unique_ptr<btMultiBodyLinkCollider> link_collider;
        btMultiBody* multibody = nullptr;
        int link = -1;
        btTransform previous_pose = btTransform::getIdentity();  ///< for link velocities by finite difference
        btTransform part_in_object = btTransform::getIdentity();  ///< the part's own frame in the object's frame
        std::vector<int> touching;  ///< rocks (body ids) that touched this part in the last reported step
        std::uint64_t touching_step = 0;

        btCollisionObject* object() const { return body ? static_cast<btCollisionObject*>(body.get()) : link_collider.get(); }
        double rock_mass_kg = 0.0;  ///< a rock's mass and principal moments, kept while it is frozen
        btVector3 rock_inertia{0.0, 0.0, 0.0};
        bool frozen = false;        ///< a rock held as a fixed body (RigidWorld::set_frozen)

        bool is_rock() const { return body && (body->getInvMass() > 0.0 || frozen); }
        /// A rock's mass: Bullet's, or the one kept while it is frozen.
        double mass() const { return frozen ? rock_mass_kg : 1.0 / body->getInvMass(); }
        /// Velocity of the material point of this body that is at `point` now.
        btVector3 velocity_at(const btVector3& point, double dt) const
        {
            if (body) return body->getVelocityInLocalPoint(point - body->getCenterOfMassPosition());
            const btVector3 local = link_collider->getWorldTransform().inverse() * point;
            return (point - previous_pose * local) / dt;
        }
    };

    static btDefaultCollisionConstructionInfo pools(const RigidSettings& s)
    {
        btDefaultCollisionConstructionInfo info;
        info.m_defaultMaxPersistentManifoldPoolSize = s.contact_pool_size;
        info.m_defaultMaxCollisionAlgorithmPoolSize = s.contact_pool_size;
        return info;
    }

    explicit Impl(const RigidSettings& s) : settings(s), config(pools(s))
    {
        world.setGravity(to_bt(s.gravity_m_per_s2));
        btContactSolverInfo& info = world.getSolverInfo();
        info.m_numIterations = s.solver_iterations;
        info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
        info.m_splitImpulse = 1;
        info.m_splitImpulsePenetrationThreshold = -s.split_impulse_threshold_m;
        if (!s.bullet_convex_pairs)
            dispatcher.registerCollisionCreateFunc(CONVEX_HULL_SHAPE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE, &convex_pairs);
        dispatcher.watch(&world.getCollisionObjectArray());
    }
    ~Impl();  // rope_shovel.cpp: the shovel's multibody goes first

    RigidSettings settings;
    btDefaultCollisionConfiguration config;
    ConvexPairCreateFunc convex_pairs{config.getCollisionAlgorithmPool()->getElementSize()};  // outlives the world's pairs
    Dispatcher dispatcher{&config, settings.threads, !settings.bullet_convex_pairs};
    btDbvtBroadphase broadphase;
    btMultiBodyConstraintSolver solver;
    DynamicsWorld world{&dispatcher, &broadphase, &solver, &config, settings.threads};
    std::unique_ptr<ShovelState, ShovelDeleter> shovel;
    std::vector<std::unique_ptr<Body>> bodies;
    MaterialPairs pairs;
    std::size_t checked_bodies = 0;  // bodies whose material pairs have been checked
    double time_s = 0.0;
    double step_s = 0.0;  ///< length of the last step (RigidWorld::last_step_s)
    std::uint64_t step_count = 0;
    std::vector<Vec3> contact_force;
    std::vector<btVector3> velocity_before, spin_before;  // of each rock at the start of the last step

    Body& body(BodyId id, const char* what)
    {
        if (id < 0 || static_cast<std::size_t>(id) >= bodies.size())
            throw InputError(concat(what, ": no body ", id, "; the world has bodies 0..", static_cast<int>(bodies.size()) - 1));
        return *bodies[static_cast<std::size_t>(id)];
    }
    void check_material(int m, const std::string& where) const
    {
        if (m < 0 || static_cast<std::size_t>(m) >= pairs.names.size())
            throw InputError(concat(where, ": material index ", m, " is not defined; the world has ", pairs.names.size(), " materials"));
    }
    /// Every pair a rock can meet must have coefficients: checked before the first step with new bodies. A pair
    /// of bodies is checked unless both were checked before. Per material the first two bodies and the first new
    /// one stand for all of that material, so a pile of 20,000 rocks costs bodies x materials, not bodies^2.
    void check_pairs()
    {
        constexpr std::size_t kNone = static_cast<std::size_t>(-1);
        struct Seen {
            std::size_t first = kNone, second = kNone, first_new = kNone;
        };
        std::vector<Seen> seen(pairs.names.size());
        for (std::size_t j = 0; j < bodies.size(); ++j) {
            Seen& m = seen[static_cast<std::size_t>(bodies[j]->material)];
            if (m.first == kNone) m.first = j;
            else if (m.second == kNone) m.second = j;
            if (j >= checked_bodies && m.first_new == kNone) m.first_new = j;
        }
        for (std::size_t i = 0; i < bodies.size(); ++i) {
            if (!bodies[i]->is_rock()) continue;
            const int a = bodies[i]->material;
            for (std::size_t b = 0; b < seen.size(); ++b) {
                // a body of material b that rock i meets and that makes the pair new: any other one if the rock
                // is new, else a new one (never the rock itself: it is old)
                const Seen& m = seen[b];
                const std::size_t j = i >= checked_bodies ? (m.first != i ? m.first : m.second) : m.first_new;
                if (j == kNone || pairs.set[pairs.index(a, static_cast<int>(b))]) continue;
                throw InputError(concat("rigid bodies '", bodies[i]->name, "' and '", bodies[j]->name,
                                        "': no friction and restitution for the material pair ", pairs.names[static_cast<std::size_t>(a)],
                                        "-", pairs.names[b], "; set it with set_pair"));
            }
        }
        checked_bodies = bodies.size();
    }

    /// Broadphase group of the rope shovel's links: fixed and kinematic bodies can leave it out of their mask.
    static constexpr int kMachineFilter = 64;

    BodyId insert(std::unique_ptr<Body> b, double mass, const btVector3& inertia, const btTransform& pose)
    {
        // A kinematic body is moved through its motion state. A dynamic one has none: Bullet would write each
        // step's interpolated pose into it for a renderer, and nothing here reads it (its pose is the body's).
        if (mass == 0.0) b->motion = std::make_unique<btDefaultMotionState>(pose);
        btRigidBody::btRigidBodyConstructionInfo info(mass, b->motion.get(), b->shape.get(), inertia);
        info.m_startWorldTransform = pose;
        info.m_friction = 0.5;  // replaced per pair in the contact callback
        b->body = std::make_unique<btRigidBody>(info);
        b->body->setActivationState(DISABLE_DEACTIVATION);  // a resting rock must still feel new loads
        b->body->setCollisionFlags(b->body->getCollisionFlags() | btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK |
                                   (b->kinematic ? btCollisionObject::CF_KINEMATIC_OBJECT : 0));
        b->body->setUserPointer(&pairs);
        b->body->setUserIndex(b->material);
        const BodyId id = static_cast<BodyId>(bodies.size());
        b->body->setUserIndex2(id);
        world.addRigidBody(b->body.get());
        bodies.push_back(std::move(b));
        contact_force.resize(bodies.size());
        return id;
    }

    BodyId insert_mesh(const meshes::TriangleMesh& mesh, int material, const std::string& name, bool kinematic,
                       const Mat3& rotation, const Vec3& translation)
    {
        check_material(material, concat("mesh '", name, "'"));
        if (mesh.triangle_count() == 0) throw InputError(concat("mesh '", name, "' has no triangles"));
        auto b = std::make_unique<Body>();
        b->name = name;
        b->material = material;
        b->kinematic = kinematic;
        for (const auto& t : mesh.triangles()) b->indices.insert(b->indices.end(), {int(t[0]), int(t[1]), int(t[2])});
        for (const Vec3& v : mesh.vertices_m()) b->vertices.insert(b->vertices.end(), {v.x, v.y, v.z});
        b->mesh_data = std::make_unique<btTriangleIndexVertexArray>(
            static_cast<int>(mesh.triangle_count()), b->indices.data(), static_cast<int>(3 * sizeof(int)),
            static_cast<int>(mesh.vertex_count()), b->vertices.data(), static_cast<int>(3 * sizeof(btScalar)));
        auto shape = std::make_unique<btBvhTriangleMeshShape>(b->mesh_data.get(), true);
        b->edge_info = std::make_unique<btTriangleInfoMap>();
        btGenerateInternalEdgeInfo(shape.get(), b->edge_info.get());
        b->shape = std::move(shape);
        return insert(std::move(b), 0.0, btVector3(0, 0, 0), btTransform(to_bt(rotation), to_bt(translation)));
    }
};


/// Adds each plate as a convex hull child of `compound` at `transform` (plate coordinates to the compound's
/// frame), shrunk by its margin (at most max_margin_m and a quarter of its thickness) so its faces are exact.
void add_plate_hulls(btCompoundShape& compound, std::vector<std::unique_ptr<btCollisionShape>>& children,
                     const std::vector<meshes::Plate>& plates, const btTransform& transform, double max_margin_m,
                     const std::string& name);

/// The shovel's part of a checkpoint (rope_shovel.cpp).
void write_shovel_state(const ShovelState& s, StateWriter& out);
void read_shovel_state(ShovelState& s, StateReader& in, double last_step_s);

// The rope shovel's share of a step (rope_shovel.cpp): motor targets and rope forces before Bullet steps,
// drive forces read after.
void shovel_before_step(RigidWorld::Impl& world, double time_after_step_s);
void shovel_after_step(RigidWorld::Impl& world);

/// Bullet's contact history (broad phase, pairs, algorithms, manifolds, odometers) into a checkpoint and back
/// into a world built the same way, so that a resumed run takes the same steps (contact_state.cpp).
void write_contact_state(const RigidWorld::Impl& w, StateWriter& out);
void read_contact_state(RigidWorld::Impl& w, StateReader& in);

}  // namespace dipper::rigid
