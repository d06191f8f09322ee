#include "rigid/rigid_world.h"

#include "rigid/detail/world_impl.h"

#include <algorithm>
#include <cmath>

namespace dipper::rigid {

namespace {

// Bullet calls this for every new contact point of a body with CF_CUSTOM_MATERIAL_CALLBACK: the pair's own
// friction and restitution replace Bullet's product rule, and contacts on triangle meshes get the face
// normal at internal edges instead of an edge normal.
bool pair_material_callback(btManifoldPoint& cp, const btCollisionObjectWrapper* w0, int part0, int index0,
                            const btCollisionObjectWrapper* w1, int part1, int index1)
{
    const btCollisionObject* a = w0->getCollisionObject();
    const btCollisionObject* b = w1->getCollisionObject();
    const auto* pairs = static_cast<const MaterialPairs*>(a->getUserPointer() ? a->getUserPointer() : b->getUserPointer());
    if (!pairs) return false;
    const std::size_t k = pairs->index(a->getUserIndex(), b->getUserIndex());
    cp.m_combinedFriction = pairs->friction[k];
    cp.m_combinedRestitution = pairs->restitution[k];
    if (w0->getCollisionShape()->getShapeType() == TRIANGLE_SHAPE_PROXYTYPE)
        btAdjustInternalEdgeContacts(cp, w0, w1, part0, index0);
    else if (w1->getCollisionShape()->getShapeType() == TRIANGLE_SHAPE_PROXYTYPE)
        btAdjustInternalEdgeContacts(cp, w1, w0, part1, index1);
    return true;
}

/// The force of a contact point on body A over a step of dt: normal and friction impulses / dt (B gets its
/// opposite).
Vec3 point_force_on_a(const btManifoldPoint& p, double dt)
{
    return (from_bt(p.m_normalWorldOnB) * p.m_appliedImpulse + from_bt(p.m_lateralFrictionDir1) * p.m_appliedImpulseLateral1 +
            from_bt(p.m_lateralFrictionDir2) * p.m_appliedImpulseLateral2) * (1.0 / dt);
}

}  // namespace

RigidWorld::RigidWorld(RigidSettings settings)
{
    if (settings.solver_iterations < 1 || settings.solver_iterations > 1000)
        throw InputError(concat("rigid settings: solver_iterations is ", settings.solver_iterations, "; expected 1..1000"));
    require_non_negative(settings.split_impulse_threshold_m, "split_impulse_threshold_m", "rigid settings");
    require_positive(settings.rock_margin_m, "rock_margin_m", "rigid settings");
    require_in_range(settings.rock_margin_fraction, 1e-3, 0.5, "rock_margin_fraction", "rigid settings");
    if (settings.contact_pool_size < 16 || settings.contact_pool_size > (1 << 22))
        throw InputError(concat("rigid settings: contact_pool_size is ", settings.contact_pool_size, "; expected 16..4194304"));
    if (!is_finite(settings.gravity_m_per_s2)) throw InputError("rigid settings: gravity is not finite");
    if (settings.threads < 1 || settings.threads > 1024)
        throw InputError(concat("rigid settings: threads is ", settings.threads, "; expected 1..1024"));
    impl_ = std::make_unique<Impl>(settings);
    gContactAddedCallback = pair_material_callback;
}

RigidWorld::~RigidWorld() = default;
RigidWorld::RigidWorld(RigidWorld&&) noexcept = default;
RigidWorld& RigidWorld::operator=(RigidWorld&&) noexcept = default;

int RigidWorld::add_material(const std::string& name)
{
    MaterialPairs& p = impl_->pairs;
    if (std::find(p.names.begin(), p.names.end(), name) != p.names.end())
        throw InputError(concat("rigid material '", name, "' defined twice"));
    const std::size_t old = p.names.size(), n = old + 1;
    std::vector<double> f(n * n, 0.0), e(n * n, 0.0);
    std::vector<bool> set(n * n, false);
    for (std::size_t i = 0; i < old; ++i)
        for (std::size_t j = 0; j < old; ++j) {
            f[i * n + j] = p.friction[i * old + j];
            e[i * n + j] = p.restitution[i * old + j];
            set[i * n + j] = p.set[i * old + j];
        }
    p.names.push_back(name);
    p.friction = std::move(f);
    p.restitution = std::move(e);
    p.set = std::move(set);
    return static_cast<int>(old);
}

const std::string& RigidWorld::material_name(int material) const
{
    impl_->check_material(material, "material_name");
    return impl_->pairs.names[static_cast<std::size_t>(material)];
}

int RigidWorld::material_index(const std::string& name) const
{
    const auto& m = impl_->pairs.names;
    const auto it = std::find(m.begin(), m.end(), name);
    if (it == m.end()) {
        std::string known;
        for (const auto& n : m) known += (known.empty() ? "" : ", ") + n;
        throw InputError(concat("rigid material '", name, "' is not defined; defined: ", known.empty() ? "(none)" : known));
    }
    return static_cast<int>(it - m.begin());
}

void RigidWorld::set_pair(const std::string& a, const std::string& b, double friction, double restitution)
{
    const std::string where = concat("rigid pair ", a, "-", b);
    require_non_negative(friction, "friction", where);
    require_in_range(restitution, 0.0, 1.0, "restitution", where);
    MaterialPairs& p = impl_->pairs;
    const int i = material_index(a), j = material_index(b);
    for (const std::size_t k : {p.index(i, j), p.index(j, i)}) {
        p.friction[k] = friction;
        p.restitution[k] = restitution;
        p.set[k] = true;
    }
}

double RigidWorld::pair_friction(int a, int b) const { return impl_->pairs.friction[impl_->pairs.index(a, b)]; }
double RigidWorld::pair_restitution(int a, int b) const { return impl_->pairs.restitution[impl_->pairs.index(a, b)]; }

BodyId RigidWorld::add_ground_plane(double height_m, int material, const std::string& name)
{
    impl_->check_material(material, concat("ground '", name, "'"));
    auto b = std::make_unique<Impl::Body>();
    b->name = name;
    b->material = material;
    b->shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1), height_m);
    return impl_->insert(std::move(b), 0.0, btVector3(0, 0, 0), btTransform::getIdentity());
}

void RigidWorld::set_blocks_machine(BodyId body, bool blocks)
{
    Impl::Body& b = impl_->body(body, "set_blocks_machine");
    if (!b.body || !(b.body->isStaticObject() || b.body->isKinematicObject()))
        throw InputError(concat("set_blocks_machine: body '", b.name, "' is not fixed or kinematic"));
    btBroadphaseProxy* proxy = b.body->getBroadphaseHandle();
    if (blocks) proxy->m_collisionFilterMask |= Impl::kMachineFilter;
    else proxy->m_collisionFilterMask &= ~Impl::kMachineFilter;
}

BodyId RigidWorld::add_static_mesh(const meshes::TriangleMesh& mesh, int material, const std::string& name,
                                   const Mat3& rotation, const Vec3& translation_m)
{
    return impl_->insert_mesh(mesh, material, name, false, rotation, translation_m);
}

BodyId RigidWorld::add_kinematic_mesh(const meshes::TriangleMesh& mesh, int material, const std::string& name,
                                      const Mat3& rotation, const Vec3& translation_m)
{
    return impl_->insert_mesh(mesh, material, name, true, rotation, translation_m);
}

void add_plate_hulls(btCompoundShape& compound, std::vector<std::unique_ptr<btCollisionShape>>& children,
                     const std::vector<meshes::Plate>& plates, const btTransform& transform, double max_margin_m,
                     const std::string& name)
{
    for (std::size_t k = 0; k < plates.size(); ++k) {
        const ConvexPolyhedron solid = ConvexPolyhedron::hull_of(plates[k].solid_corners_m(), concat("part '", name, "', plate ", k));
        const double margin = std::min(max_margin_m, 0.25 * plates[k].thickness_m);
        auto hull = std::make_unique<btConvexHullShape>();
        const ConvexPolyhedron core = solid.shrunk(margin);
        for (const Vec3& v : core.vertices_m()) hull->addPoint(to_bt(v), false);
        hull->recalcLocalAabb();
        hull->setMargin(margin);
        compound.addChildShape(transform, hull.get());
        children.push_back(std::move(hull));
    }
}

BodyId RigidWorld::add_plates(const std::vector<meshes::Plate>& plates, int material, const std::string& name,
                              bool kinematic, const Mat3& rotation, const Vec3& translation_m)
{
    impl_->check_material(material, concat("part '", name, "'"));
    if (plates.empty()) throw InputError(concat("part '", name, "' has no plates: a body needs a collision shape"));
    auto b = std::make_unique<Impl::Body>();
    b->name = name;
    b->material = material;
    b->kinematic = kinematic;
    auto compound = std::make_unique<btCompoundShape>();
    add_plate_hulls(*compound, b->children, plates, btTransform::getIdentity(), impl_->settings.rock_margin_m, name);
    b->shape = std::move(compound);
    return impl_->insert(std::move(b), 0.0, btVector3(0, 0, 0), btTransform(to_bt(rotation), to_bt(translation_m)));
}

void RigidWorld::set_kinematic_pose(BodyId id, const Mat3& rotation, const Vec3& translation_m)
{
    Impl::Body& b = impl_->body(id, "set_kinematic_pose");
    if (!b.kinematic) throw InputError(concat("set_kinematic_pose: body '", b.name, "' is not a kinematic mesh"));
    b.motion->setWorldTransform(btTransform(to_bt(rotation), to_bt(translation_m)));
}

BodyId RigidWorld::add_rock(const ConvexPolyhedron& shape, double density, int material, const Vec3& position_m,
                            const Mat3& rotation, const Vec3& velocity, const Vec3& angular_velocity)
{
    const std::string where = concat("rock ", impl_->bodies.size(), " (", shape.source(), ")");
    impl_->check_material(material, where);
    require_positive(density, "density_kg_per_m3", where);
    if (!is_finite(position_m) || !is_finite(velocity) || !is_finite(angular_velocity))
        throw InputError(concat(where, ": position or velocity is not finite"));
    const double size = shape.equivalent_diameter_m();
    const Mat3 inertia = shape.inertia_about_centroid(density);
    const double scale = std::max({inertia.m[0][0], inertia.m[1][1], inertia.m[2][2]});
    const double off = std::max({std::abs(inertia.m[0][1]), std::abs(inertia.m[0][2]), std::abs(inertia.m[1][2])});
    if (norm(shape.centroid_m()) > 1e-9 * size || off > 1e-9 * scale)
        throw InputError(concat(where, ": the shape is not in its principal frame (centroid ", norm(shape.centroid_m()),
                                " m from the origin, largest product of inertia ", off / scale,
                                " of the moments); pass shape.in_principal_frame()"));

    auto b = std::make_unique<Impl::Body>();
    b->name = concat("rock ", impl_->bodies.size());
    b->material = material;
    b->margin_m = std::min(impl_->settings.rock_margin_m, impl_->settings.rock_margin_fraction * shape.inner_radius_m());
    const std::vector<Vec3> core = shape.shrunk(b->margin_m).vertices_m();
    auto hull = std::make_unique<btConvexHullShape>();
    for (const Vec3& v : core) hull->addPoint(to_bt(v), false);
    hull->recalcLocalAabb();
    hull->setMargin(b->margin_m);
    b->shape = std::move(hull);
    const double mass = density * shape.volume_m3();
    const btVector3 moments(inertia.m[0][0], inertia.m[1][1], inertia.m[2][2]);
    b->rock_mass_kg = mass;
    b->rock_inertia = moments;
    const BodyId id = impl_->insert(std::move(b), mass, moments, btTransform(to_bt(rotation), to_bt(position_m)));
    btRigidBody* body = impl_->bodies.back()->body.get();
    body->setLinearVelocity(to_bt(velocity));
    body->setAngularVelocity(to_bt(angular_velocity));
    return id;
}

std::size_t RigidWorld::body_count() const { return impl_->bodies.size(); }
const std::string& RigidWorld::body_name(BodyId id) const { return impl_->body(id, "body_name").name; }

double RigidWorld::mass_kg(BodyId id) const
{
    const Impl::Body& b = impl_->body(id, "mass_kg");
    if (b.multibody) return b.link < 0 ? b.multibody->getBaseMass() : b.multibody->getLinkMass(b.link);
    if (b.is_rock()) return b.mass();
    return b.body->getInvMass() > 0.0 ? 1.0 / b.body->getInvMass() : 0.0;
}

double RigidWorld::margin_m(BodyId id) const { return impl_->body(id, "margin_m").margin_m; }

BodyState RigidWorld::state(BodyId id) const
{
    const Impl::Body& body = impl_->body(id, "state");
    if (body.multibody) {  // a link: pose from its collider, velocity by finite difference over the last step
        const btTransform& t = body.link_collider->getWorldTransform();
        const double dt = impl_->step_s;
        if (dt == 0.0) return {from_bt(t.getOrigin()), from_bt(t.getBasis()), {}, {}};  // before the first step
        const btVector3 v = (t.getOrigin() - body.previous_pose.getOrigin()) / dt;
        btVector3 axis;
        btScalar angle;
        btTransformUtil::calculateDiffAxisAngle(body.previous_pose, t, axis, angle);
        return {from_bt(t.getOrigin()), from_bt(t.getBasis()), from_bt(v), from_bt(axis * (angle / dt))};
    }
    const btRigidBody* b = body.body.get();
    const btTransform& t = b->getWorldTransform();
    return {from_bt(t.getOrigin()), from_bt(t.getBasis()), from_bt(b->getLinearVelocity()), from_bt(b->getAngularVelocity())};
}

Vec3 RigidWorld::position_m(BodyId id) const
{
    return from_bt(impl_->body(id, "position_m").object()->getWorldTransform().getOrigin());
}

void RigidWorld::apply_force(BodyId id, const Vec3& force, const Vec3& point)
{
    Impl::Body& b = impl_->body(id, "apply_force");
    if (!is_finite(force) || !is_finite(point))
        throw SimulationError(concat("apply_force on '", b.name, "': force or point is not finite at t = ", impl_->time_s, " s"));
    if (b.multibody) {
        const btVector3 f = to_bt(force), arm = to_bt(point) - b.link_collider->getWorldTransform().getOrigin();
        if (b.link < 0) {
            b.multibody->addBaseForce(f);
            b.multibody->addBaseTorque(arm.cross(f));
        } else {
            b.multibody->addLinkForce(b.link, f);
            b.multibody->addLinkTorque(b.link, arm.cross(f));
        }
        return;
    }
    if (b.body->getInvMass() == 0.0) return;  // static and kinematic bodies do not respond to forces
    b.body->applyForce(to_bt(force), to_bt(point) - b.body->getCenterOfMassPosition());
}

void RigidWorld::apply_force_and_torque(BodyId id, const Vec3& force, const Vec3& torque)
{
    Impl::Body& b = impl_->body(id, "apply_force_and_torque");
    if (!is_finite(force) || !is_finite(torque))
        throw SimulationError(concat("apply_force_and_torque on '", b.name, "': force or torque is not finite at t = ",
                                     impl_->time_s, " s"));
    if (b.multibody) {
        if (b.link < 0) {
            b.multibody->addBaseForce(to_bt(force));
            b.multibody->addBaseTorque(to_bt(torque));
        } else {
            b.multibody->addLinkForce(b.link, to_bt(force));
            b.multibody->addLinkTorque(b.link, to_bt(torque));
        }
        return;
    }
    if (b.body->getInvMass() == 0.0) return;
    b.body->applyCentralForce(to_bt(force));
    b.body->applyTorque(to_bt(torque));
}

void RigidWorld::part_pose(BodyId id, Mat3& rotation, Vec3& origin_m) const
{
    const Impl::Body& b = impl_->body(id, "part_pose");
    const btTransform t = b.object()->getWorldTransform() * b.part_in_object;
    rotation = from_bt(t.getBasis());
    origin_m = from_bt(t.getOrigin());
}

void RigidWorld::set_frozen(BodyId id, bool frozen)
{
    Impl::Body& b = impl_->body(id, "set_frozen");
    if (!b.is_rock()) throw InputError(concat("set_frozen: '", b.name, "' is not a rock"));
    if (b.frozen == frozen) return;
    b.frozen = frozen;
    btRigidBody& r = *b.body;
    // at rest either way: a frozen rock is a fixed body (no integration, no solver rows against other fixed
    // bodies), and one let go starts from rest
    const btVector3 zero(0.0, 0.0, 0.0);
    r.setLinearVelocity(zero);
    r.setAngularVelocity(zero);
    r.setInterpolationLinearVelocity(zero);
    r.setInterpolationAngularVelocity(zero);
    r.clearForces();
    if (frozen)
        r.setMassProps(0.0, zero);
    else
        r.setMassProps(b.rock_mass_kg, b.rock_inertia);
    r.updateInertiaTensor();
}

bool RigidWorld::frozen(BodyId id) const { return impl_->body(id, "frozen").frozen; }

void RigidWorld::set_rock_motion(BodyId id, const BodyState& s)
{
    Impl::Body& b = impl_->body(id, "set_rock_motion");
    if (!b.is_rock() || b.frozen) throw InputError(concat("set_rock_motion: '", b.name, "' is not a free rock"));
    if (!is_finite(s.position_m) || !is_finite(s.velocity_m_per_s) || !is_finite(s.angular_velocity_rad_per_s))
        throw SimulationError(concat("rock '", b.name, "' was given a pose or velocity that is not finite at t = ", impl_->time_s, " s"));
    btRigidBody& r = *b.body;
    r.setLinearVelocity(to_bt(s.velocity_m_per_s));
    r.setAngularVelocity(to_bt(s.angular_velocity_rad_per_s));
    // the pose, the interpolation pose and velocities with it, and the inertia tensor in the world frame
    r.setCenterOfMassTransform(btTransform(to_bt(s.rotation), to_bt(s.position_m)));
}

bool RigidWorld::is_dynamic(BodyId id) const
{
    const Impl::Body& b = impl_->body(id, "is_dynamic");
    return b.multibody != nullptr || b.is_rock();
}

void RigidWorld::step(double step_s)
{
    require_positive(step_s, "step_s", "rigid world step");
    impl_->step_s = step_s;
    const double dt = step_s;
    if (impl_->checked_bodies != impl_->bodies.size()) impl_->check_pairs();
    impl_->velocity_before.resize(impl_->bodies.size());
    impl_->spin_before.resize(impl_->bodies.size());
    for (std::size_t k = 0; k < impl_->bodies.size(); ++k) {
        Impl::Body& b = *impl_->bodies[k];
        if (b.multibody) b.previous_pose = b.link_collider->getWorldTransform();
        if (b.is_rock()) {
            impl_->velocity_before[k] = b.body->getLinearVelocity();
            impl_->spin_before[k] = b.body->getAngularVelocity();
        }
    }
    if (impl_->shovel) shovel_before_step(*impl_, impl_->time_s + dt);
    impl_->world.stepSimulation(dt, 0);  // maxSubSteps = 0: exactly one step of dt, no interpolation
    impl_->time_s += dt;
    ++impl_->step_count;
    if (impl_->shovel) shovel_after_step(*impl_);

    std::fill(impl_->contact_force.begin(), impl_->contact_force.end(), Vec3{});
    btDispatcher& d = impl_->dispatcher;
    for (int q = 0; q < d.getNumManifolds(); ++q) {
        const btPersistentManifold* m = d.getManifoldByIndexInternal(q);
        const int a = m->getBody0()->getUserIndex2(), b = m->getBody1()->getUserIndex2();
        for (int k = 0; k < m->getNumContacts(); ++k) {
            const Vec3 on_a = point_force_on_a(m->getContactPoint(k), dt);
            impl_->contact_force[static_cast<std::size_t>(a)] += on_a;
            impl_->contact_force[static_cast<std::size_t>(b)] -= on_a;
        }
    }
    for (const auto& b : impl_->bodies) {
        const btVector3 x = b->object()->getWorldTransform().getOrigin();
        const btVector3 v = b->body ? b->body->getLinearVelocity() : btVector3(0, 0, 0);
        if (!is_finite(from_bt(x)) || !is_finite(from_bt(v)))
            throw SimulationError(concat("rigid body '", b->name, "' has a non-finite position or velocity at t = ",
                                         impl_->time_s, " s; try a smaller step than ", dt, " s"));
    }
}

double RigidWorld::time_s() const { return impl_->time_s; }

namespace {

/// A pose as the checkpoint holds it: the basis row by row, then the origin.
template <class IO>
void transform_field(IO& io, btTransform& t)
{
    Mat3 basis;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) basis.m[i][j] = t.getBasis()[i][j];
    Vec3 origin = from_bt(t.getOrigin());
    io(basis, origin);
    if constexpr (IO::reading) {
        btMatrix3x3 b;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) b[i][j] = basis.m[i][j];
        t = btTransform(b, to_bt(origin));
    }
}

/// Bullet's vectors as the checkpoint holds them.
template <class IO, class Vectors>
void vectors_field(IO& io, Vectors& v)
{
    std::vector<Vec3> plain;
    for (const btVector3& x : v) plain.push_back(from_bt(x));
    io(plain);
    if constexpr (IO::reading) {
        v.clear();
        for (const Vec3& x : plain) v.push_back(to_bt(x));
    }
}

/// The rigid world's checkpoint fields, listed once for writing and reading (core/state_io.h): time and
/// step, each body's pose and velocities (a kinematic part's last pose), the frozen flags, the contact
/// forces, the velocities before the last step and the shovel. Reading checks each body's name and
/// sets the poses; the frozen flags are returned for read_state to apply.
template <class IO, class Impl>
void rigid_state_fields(IO& io, Impl& w, std::vector<std::uint8_t>& frozen)
{
    io.tag("rigid world");
    io.count(w.bodies.size(), "rigid bodies");
    io(w.time_s, w.step_count, w.step_s);
    for (auto& b : w.bodies) {
        std::string name = b->name;
        io(name);
        if constexpr (IO::reading)
            if (name != b->name) io.fail(concat("rigid body '", name, "' where the world has '", b->name, "'"));
        if (b->body) {
            btTransform t = b->body->getWorldTransform();
            transform_field(io, t);
            Vec3 v = from_bt(b->body->getLinearVelocity()), omega = from_bt(b->body->getAngularVelocity());
            io(v, omega);
            if constexpr (IO::reading) {
                b->body->setWorldTransform(t);
                b->body->setInterpolationWorldTransform(t);
                if (b->motion) b->motion->setWorldTransform(t);
                b->body->setLinearVelocity(to_bt(v));
                b->body->setAngularVelocity(to_bt(omega));
                b->body->setInterpolationLinearVelocity(to_bt(v));
                b->body->setInterpolationAngularVelocity(to_bt(omega));
                b->body->updateInertiaTensor();  // the world inertia follows the orientation read (a rock is made upright)
            }
        } else {
            btTransform t = b->previous_pose;
            transform_field(io, t);
            if constexpr (IO::reading) b->previous_pose = t;
        }
    }
    io(frozen, w.contact_force);
    vectors_field(io, w.velocity_before);
    vectors_field(io, w.spin_before);
    bool shovel = w.shovel != nullptr;
    io(shovel);
    if constexpr (IO::reading)
        if (shovel != (w.shovel != nullptr)) io.fail("the checkpoint and the world differ in having a rope shovel");
}

}  // namespace

void RigidWorld::write_state(StateWriter& out) const
{
    const Impl& w = *impl_;
    std::vector<std::uint8_t> frozen;
    for (const auto& b : w.bodies) frozen.push_back(b->frozen ? 1 : 0);
    rigid_state_fields(out, w, frozen);
    if (w.shovel) write_shovel_state(*w.shovel, out);
    for (const auto& b : w.bodies) out(b->touching, b->touching_step);
    write_contact_state(w, out);
}

void RigidWorld::read_state(StateReader& in)
{
    Impl& w = *impl_;
    std::vector<std::uint8_t> frozen;
    rigid_state_fields(in, w, frozen);
    if (!(w.step_s >= 0.0) || !std::isfinite(w.step_s)) in.fail(concat("a last rigid step of ", w.step_s, " s"));
    if (frozen.size() != w.bodies.size()) in.fail("a frozen flag for each rigid body");
    for (std::size_t k = 0; k < frozen.size(); ++k) {
        if (frozen[k] > 1 || (frozen[k] && !w.bodies[k]->is_rock()))
            in.fail(concat("rigid body '", w.bodies[k]->name, "' frozen; only rocks can be"));
        if (frozen[k] != (w.bodies[k]->frozen ? 1 : 0)) {
            // the flag, with the pose and velocities read above (zero for a frozen rock)
            const btVector3 v = w.bodies[k]->body->getLinearVelocity(), omega = w.bodies[k]->body->getAngularVelocity();
            set_frozen(static_cast<BodyId>(k), frozen[k] != 0);
            w.bodies[k]->body->setLinearVelocity(v);
            w.bodies[k]->body->setAngularVelocity(omega);
            w.bodies[k]->body->setInterpolationLinearVelocity(v);
            w.bodies[k]->body->setInterpolationAngularVelocity(omega);
        }
    }
    if (w.shovel) read_shovel_state(*w.shovel, in, w.step_s);
    if (w.contact_force.size() != w.bodies.size()) in.fail("rigid contact forces of another number of bodies");
    for (auto& b : w.bodies) in(b->touching, b->touching_step);
    read_contact_state(w, in);
}

double RigidWorld::last_step_s() const { return impl_->step_s; }
const RigidSettings& RigidWorld::settings() const { return impl_->settings; }

Vec3 RigidWorld::contact_force_N(BodyId id) const
{
    impl_->body(id, "contact_force_N");
    return impl_->contact_force[static_cast<std::size_t>(id)];
}

std::vector<RigidWorld::PointForce> RigidWorld::contact_point_forces(BodyId id) const
{
    impl_->body(id, "contact_point_forces");
    const double dt = impl_->step_s;
    std::vector<PointForce> out;
    if (dt == 0.0) return out;  // no step, no contact impulses
    btDispatcher& d = impl_->dispatcher;
    for (int q = 0; q < d.getNumManifolds(); ++q) {
        const btPersistentManifold* m = d.getManifoldByIndexInternal(q);
        const bool is_a = m->getBody0()->getUserIndex2() == id, is_b = m->getBody1()->getUserIndex2() == id;
        if (!is_a && !is_b) continue;
        for (int k = 0; k < m->getNumContacts(); ++k) {
            const btManifoldPoint& p = m->getContactPoint(k);
            const Vec3 on_a = point_force_on_a(p, dt);  // as contact_force_N sums it
            if (is_a) out.push_back({from_bt(p.getPositionWorldOnA()), on_a});
            if (is_b) out.push_back({from_bt(p.getPositionWorldOnB()), -on_a});
        }
    }
    return out;
}

std::size_t RigidWorld::contact_point_count() const { return pair_counts().contact_points; }

RigidWorld::PairCounts RigidWorld::pair_counts() const
{
    PairCounts c;
    c.broadphase_pairs = static_cast<std::size_t>(impl_->broadphase.getOverlappingPairCache()->getNumOverlappingPairs());
    c.manifolds = static_cast<std::size_t>(impl_->dispatcher.getNumManifolds());
    for (int q = 0; q < impl_->dispatcher.getNumManifolds(); ++q) {
        const int points = impl_->dispatcher.getManifoldByIndexInternal(q)->getNumContacts();
        c.contact_points += static_cast<std::size_t>(points);
        c.touching_manifolds += points > 0 ? 1 : 0;
    }
    return c;
}

double RigidWorld::max_penetration_m() const
{
    double deepest = 0.0;
    for (int q = 0; q < impl_->dispatcher.getNumManifolds(); ++q) {
        const btPersistentManifold* m = impl_->dispatcher.getManifoldByIndexInternal(q);
        for (int k = 0; k < m->getNumContacts(); ++k) deepest = std::max(deepest, -m->getContactPoint(k).getDistance());
    }
    return deepest;
}

Vec3 RigidWorld::linear_momentum_kg_m_per_s() const
{
    Vec3 p;
    for (const auto& b : impl_->bodies)
        if (b->is_rock() && !b->frozen) p += from_bt(b->body->getLinearVelocity()) * (1.0 / b->body->getInvMass());
    return p;
}

Vec3 RigidWorld::angular_momentum_kg_m2_per_s() const
{
    Vec3 l;
    for (const auto& b : impl_->bodies) {
        if (!b->is_rock() || b->frozen) continue;  // a frozen rock is at rest
        const btRigidBody* body = b->body.get();
        const btMatrix3x3& basis = body->getWorldTransform().getBasis();
        const btVector3 local_w = basis.transpose() * body->getAngularVelocity();
        const btVector3 inv = body->getInvInertiaDiagLocal();
        btVector3 local_l;
        for (int k = 0; k < 3; ++k) local_l[k] = inv[k] > 0.0 ? local_w[k] / inv[k] : 0.0;
        const Vec3 c = from_bt(body->getCenterOfMassPosition());
        l += cross(c, from_bt(body->getLinearVelocity()) * (1.0 / body->getInvMass())) + from_bt(basis * local_l);
    }
    return l;
}

double RigidWorld::kinetic_energy_J() const
{
    double e = 0.0;
    for (const auto& b : impl_->bodies) {
        if (!b->is_rock() || b->frozen) continue;
        const btRigidBody* body = b->body.get();
        const btVector3 v = body->getLinearVelocity(), w = body->getAngularVelocity();
        const btVector3 local_w = body->getWorldTransform().getBasis().transpose() * w;
        const btVector3 inv = body->getInvInertiaDiagLocal();
        double rot = 0.0;
        for (int k = 0; k < 3; ++k) rot += (inv[k] > 0.0 ? local_w[k] * local_w[k] / inv[k] : 0.0);
        e += 0.5 * v.length2() / body->getInvMass() + 0.5 * rot;
    }
    return e;
}

std::vector<ContactRecord> RigidWorld::surface_contacts(BodyId surface, std::int32_t surface_id,
                                                        const meshes::TriangleMesh* wear_mesh) const
{
    Impl::Body& part = impl_->body(surface, "surface_contacts");
    if (wear_mesh && part.located_mesh != wear_mesh) {
        part.locator = std::make_unique<meshes::TriangleLocator>(*wear_mesh);
        part.located_mesh = wear_mesh;
    }
    const btTransform to_part = (part.object()->getWorldTransform() * part.part_in_object).inverse();
    const double dt = impl_->step_s;
    std::vector<ContactRecord> out;
    if (dt == 0.0) return out;
    std::vector<int> now_touching;
    const bool continues = part.touching_step + 1 == impl_->step_count;  // reported for the step before too
    btDispatcher& d = impl_->dispatcher;
    for (int q = 0; q < d.getNumManifolds(); ++q) {
        const btPersistentManifold* m = d.getManifoldByIndexInternal(q);
        const bool surface_is_a = m->getBody0()->getUserIndex2() == surface;
        const bool surface_is_b = m->getBody1()->getUserIndex2() == surface;
        if (!surface_is_a && !surface_is_b) continue;
        const auto* other = btRigidBody::upcast(surface_is_a ? m->getBody1() : m->getBody0());
        if (!other || other->getInvMass() == 0.0) continue;  // rocks only
        // An impact is the start of contact between the rock and the part: the first touching point of a rock
        // that touched none of the part's manifolds in the previous step. (Bullet keeps points a little apart
        // in its manifolds, and adds a landing face's points over several steps; neither is a new impact. A
        // rock across two plates of a part has a manifold on each: still one impact. Rocks, not manifolds,
        // are remembered: a manifold released in one step can be handed to another pair in the next.)
        const auto touches = [](const btManifoldPoint& p) { return p.getDistance() <= 0.0 || p.m_appliedImpulse > 0.0; };
        bool touching = false;
        for (int k = 0; k < m->getNumContacts(); ++k) touching = touching || touches(m->getContactPoint(k));
        if (!touching) continue;
        const int rock = other->getUserIndex2();
        const bool seen = std::find(now_touching.begin(), now_touching.end(), rock) != now_touching.end();
        if (!seen) now_touching.push_back(rock);
        const bool new_contact = !seen && (!continues || !std::binary_search(part.touching.begin(), part.touching.end(), rock));
        bool impact_given = false;
        for (int k = 0; k < m->getNumContacts(); ++k) {
            const btManifoldPoint& p = m->getContactPoint(k);
            if (!touches(p)) continue;
            const double sign = surface_is_b ? 1.0 : -1.0;  // the normal points from B to A
            const Vec3 n = from_bt(p.m_normalWorldOnB) * sign;
            const Vec3 friction_on_a = (from_bt(p.m_lateralFrictionDir1) * p.m_appliedImpulseLateral1 +
                                        from_bt(p.m_lateralFrictionDir2) * p.m_appliedImpulseLateral2) * (1.0 / dt);
            ContactRecord r;
            r.point_world = from_bt(surface_is_b ? p.getPositionWorldOnB() : p.getPositionWorldOnA());
            r.normal_world = n;
            r.normal_force_N = p.m_appliedImpulse / dt;
            r.tangential_force_N = friction_on_a * sign;
            const btVector3 at = surface_is_b ? p.getPositionWorldOnA() : p.getPositionWorldOnB();
            r.first_step = new_contact && !impact_given;
            impact_given = impact_given || r.first_step;
            // Bullet resolves an impact within one step, so the velocity after it is the rebound: an impact's
            // record takes the rock's velocity from the start of the step (the approach)
            const auto o = static_cast<std::size_t>(other->getUserIndex2());
            const btVector3 arm = at - other->getCenterOfMassPosition();
            const btVector3 v_other = r.first_step && o < impl_->velocity_before.size()
                                          ? impl_->velocity_before[o] + impl_->spin_before[o].cross(arm)
                                          : other->getVelocityInLocalPoint(arm);
            const btVector3 v_self = part.velocity_at(to_bt(r.point_world), dt);
            r.relative_displacement_m = from_bt(v_other - v_self) * dt;
            r.overlap_m = std::max(0.0, -p.getDistance());
            r.surface_id = surface_id;
            r.triangle_id = surface_is_b ? p.m_index1 : p.m_index0;
            if (part.object()->getCollisionShape()->getShapeType() != TRIANGLE_MESH_SHAPE_PROXYTYPE) r.triangle_id = -1;
            if (wear_mesh) r.triangle_id = part.locator->nearest(from_bt(to_part * to_bt(r.point_world))).triangle;
            r.particle_index = other->getUserIndex2();
            r.particle_mass_kg = 1.0 / other->getInvMass();
            out.push_back(r);
        }
    }
    std::sort(now_touching.begin(), now_touching.end());
    part.touching.swap(now_touching);
    part.touching_step = impl_->step_count;
    return out;
}

void add_aitik_copper_ore_materials(RigidWorld& w)
{
    w.add_material("rock");
    w.add_material("ground");
    w.add_material("bucket");
    w.set_pair("rock", "rock", kTable2RockFriction.rock, 0.0);
    w.set_pair("rock", "ground", kTable2RockFriction.ground, 0.0);
    w.set_pair("rock", "bucket", kTable2RockFriction.bucket, 0.0);
}

}  // namespace dipper::rigid
