// The rope shovel as a Bullet multibody (reduced coordinates: joints cannot drift apart, and the drive
// motors' impulses are the drive forces). Links, in order from the fixed crawlers:
//   0 upper body with boom   revolute about z at the swing axis      motor: swing angle
//   1 saddle block           revolute about y at the shipper shaft   free
//   2 dipper handle + dipper prismatic along the handle              motor: crowd extension
//   3 door                   revolute about y at the dipper's hinge  motor: door angle
// The two hoist ropes are tension-only spring-dampers from the boom-point sheave (link 0) to the bail pins
// (link 2) with the prescribed paid-out length, applied as forces on both links before each step.
#include "rigid/rope_shovel.h"

#include "rigid/detail/world_impl.h"

#include <algorithm>
#include <cmath>

namespace dipper::rigid {

namespace {

constexpr double kDeg = M_PI / 180.0;

Mat3 rot_y(double angle_rad) { return rotation_about_axis({0.0, 1.0, 0.0}, angle_rad); }

/// Volume and centroid of a set of plates (the steel).
std::pair<double, Vec3> steel(const std::vector<meshes::Plate>& plates)
{
    double volume = 0.0;
    Vec3 moment;
    for (const meshes::Plate& p : plates) {
        const auto& c = p.corners_m;
        const double a1 = 0.5 * norm(cross(c[1] - c[0], c[2] - c[0])), a2 = 0.5 * norm(cross(c[2] - c[0], c[3] - c[0]));
        const Vec3 centroid = ((c[0] + c[1] + c[2]) * (a1 / 3.0) + (c[0] + c[2] + c[3]) * (a2 / 3.0)) * (1.0 / (a1 + a2));
        const double v = (a1 + a2) * p.thickness_m;
        volume += v;
        moment += (centroid - p.normal() * (p.thickness_m / 2.0)) * v;
    }
    return {volume, moment * (1.0 / volume)};
}

/// Centroid of the struck volume: the trapezoid (0,0), (Lb,0), (Lt,H), (0,H) in x-z, extruded across y.
Vec3 struck_centroid(const meshes::DipperParameters& p)
{
    const double xs[4] = {0.0, p.bottom_length_m, p.top_length_m, 0.0}, zs[4] = {0.0, 0.0, p.height_m, p.height_m};
    double a = 0.0, cx = 0.0, cz = 0.0;
    for (int i = 0; i < 4; ++i) {
        const int j = (i + 1) % 4;
        const double cr = xs[i] * zs[j] - xs[j] * zs[i];
        a += cr / 2.0;
        cx += (xs[i] + xs[j]) * cr;
        cz += (zs[i] + zs[j]) * cr;
    }
    return {cx / (6.0 * a), 0.0, cz / (6.0 * a)};
}

/// Diagonal inertia of a uniform box about its centre, plus a point mass shift, in machine axes.
Vec3 box_inertia(double m, double lx, double ly, double lz)
{
    return {m * (ly * ly + lz * lz) / 12.0, m * (lx * lx + lz * lz) / 12.0, m * (lx * lx + ly * ly) / 12.0};
}

Vec3 shifted(const Vec3& inertia, double m, const Vec3& offset)
{
    return {inertia.x + m * (offset.y * offset.y + offset.z * offset.z), inertia.y + m * (offset.x * offset.x + offset.z * offset.z),
            inertia.z + m * (offset.x * offset.x + offset.y * offset.y)};
}

void check_geometry(const ShovelGeometry& g)
{
    const std::string w = "rope shovel";
    if (!is_finite(g.boom_foot_m)) throw InputError(w + ": boom_foot_m is not finite");
    require_positive(g.boom_length_m, "boom_length_m", w);
    require_in_range(g.boom_angle_deg, 10.0, 80.0, "boom_angle_deg", w);
    require_in_range(g.shipper_shaft_fraction, 0.1, 0.9, "shipper_shaft_fraction", w);
    require_positive(g.handle_length_m, "handle_length_m", w);
    require_positive(g.handle_section_m, "handle_section_m", w);
    for (const auto& [value, name] : {std::pair{g.upper_body_mass_kg, "upper_body_mass_kg"}, {g.saddle_mass_kg, "saddle_mass_kg"},
                                      {g.handle_mass_kg, "handle_mass_kg"}, {g.dipper_mass_kg, "dipper_mass_kg"},
                                      {g.door_mass_kg, "door_mass_kg"}, {g.rope_axial_stiffness_N, "rope_axial_stiffness_N"},
                                      {g.max_crowd_force_N, "max_crowd_force_N"}, {g.force_filter_window_s, "force_filter_window_s"}})
        require_positive(value, name, w);
    require_non_negative(g.payload_kg, "payload_kg", w);
    require_in_range(g.rope_damping_ratio, 0.0, 2.0, "rope_damping_ratio", w);
}

}  // namespace

ShovelPose pose_shovel(const ShovelGeometry& g, const meshes::Dipper& d, double handle_angle_deg, double s)
{
    ShovelPose p;
    const double boom = g.boom_angle_deg * kDeg;
    const Vec3 along{std::cos(boom), 0.0, std::sin(boom)};
    p.shipper_shaft_m = g.boom_foot_m + along * (g.shipper_shaft_fraction * g.boom_length_m);
    p.sheave_m = g.boom_foot_m + along * g.boom_length_m;
    const double a = handle_angle_deg * kDeg;
    p.handle_axis = {std::cos(a), 0.0, -std::sin(a)};
    p.handle_pin_m = p.shipper_shaft_m + p.handle_axis * s;
    // turn the dipper about y so that its handle direction (pin towards saddle) lies along -handle_axis
    const Vec3& h = d.handle_direction;
    const double beta = std::atan2(h.z, h.x) - std::atan2(-p.handle_axis.z, -p.handle_axis.x);
    p.dipper_rotation = rot_y(beta);
    p.dipper_origin_m = p.handle_pin_m - p.dipper_rotation * d.handle_pin_m;
    for (int k = 0; k < 2; ++k) p.bail_m[k] = p.dipper_origin_m + p.dipper_rotation * d.bail_pins_m[k];
    p.rope_length_m = norm(p.sheave_m - p.bail_m[0]);
    return p;
}

namespace {
/// The steepest handle angle up to 75 deg below horizontal at 8.5 m of crowd that keeps the dipper's
/// lowest point (teeth, lip) 0.1 m above the ground (z = 0): where each dig starts.
double toe_handle_angle_deg(const ShovelGeometry& g, const meshes::Dipper& d)
{
    const auto lowest = [&](double angle) {
        const ShovelPose p = pose_shovel(g, d, angle, 8.5);
        double z = 1e300;
        for (const meshes::Plate& plate : d.body.plates)
            for (const Vec3& c : plate.solid_corners_m()) z = std::min(z, (p.dipper_origin_m + p.dipper_rotation * c).z);
        return z;
    };
    double toe = 75.0;
    while (toe > 30.0 && lowest(toe) < 0.1) toe -= 0.5;
    return toe;
}

/// A key pose of a cycle: handle angle below horizontal, crowd extension, swing and door, and how much
/// of this pass's propel (0 to 1) the crawlers have done.
struct KeyPose { double t, angle, crowd, swing, door, propelled = 0.0; };

/// The key poses of `count` passes joined by smooth curves, sampled every 0.05 s at most (and at every key
/// pose exactly). A drive accelerates and brakes between key poses as a machine does instead of jumping
/// to a new speed: between linearly joined keys the dipper's sideways speed would jump by 3 m/s as the
/// swing starts, an impulse on its load of tens of tonnes. Each handle angle is turned into the rope length
/// that gives it after interpolation, so the rope follows the handle's smooth path. The dig ends at rest
/// (the key at kBuiltInDig_s of each pass): the dig itself is then the same whatever follows it.
MotionCurves repeated(const ShovelGeometry& g, const meshes::Dipper& d, const std::vector<KeyPose>& pass, double period_s,
                      int count, const std::string& name, double advance_per_pass_m = 0.0)
{
    std::vector<double> t, angle, crowd, swing, door, propel;
    std::vector<bool> rest;
    for (int k = 0; k < count; ++k)
        for (const KeyPose& key : pass) {
            t.push_back(period_s * k + key.t);
            angle.push_back(key.angle);
            crowd.push_back(key.crowd);
            swing.push_back(key.swing);
            door.push_back(key.door);
            propel.push_back(advance_per_pass_m * (k + key.propelled));
            rest.push_back(key.t == kBuiltInDig_s);
        }
    const std::vector<double> m_angle = monotone_slopes(t, angle, rest), m_crowd = monotone_slopes(t, crowd, rest),
                              m_swing = monotone_slopes(t, swing, rest), m_door = monotone_slopes(t, door, rest),
                              m_propel = monotone_slopes(t, propel, rest);
    std::vector<MotionSample> samples;
    const auto sample = [&](std::size_t k, double time) {
        const std::size_t b = std::min(k + 1, t.size() - 1);
        const auto at = [&](const std::vector<double>& y, const std::vector<double>& m) {
            return b == k ? y[k] : hermite(t[k], t[b], y[k], y[b], m[k], m[b], time);
        };
        const double a = at(angle, m_angle), c = at(crowd, m_crowd);
        samples.push_back({time, pose_shovel(g, d, a, c).rope_length_m, c, at(swing, m_swing), at(door, m_door), at(propel, m_propel)});
    };
    constexpr double kSpacing_s = 0.05;
    for (std::size_t k = 0; k < t.size(); ++k) {
        sample(k, t[k]);
        if (k + 1 == t.size()) break;
        const int parts = static_cast<int>(std::ceil((t[k + 1] - t[k]) / kSpacing_s - 1e-9));
        for (int j = 1; j < parts; ++j) sample(k, t[k] + (t[k + 1] - t[k]) * j / parts);
    }
    return MotionCurves::from_samples(std::move(samples), name);
}
}  // namespace

MotionCurves default_loading_cycle(const ShovelGeometry& g, const meshes::Dipper& d, double advance_per_pass_m)
{
    if (!(advance_per_pass_m >= 0.0 && advance_per_pass_m <= 10.0))
        throw InputError(concat("default_loading_cycle: advance_per_pass_m = ", advance_per_pass_m, "; expected 0 to 10 m"));
    const double toe = toe_handle_angle_deg(g, d);
    const std::vector<KeyPose> pass = {
        {0.0, toe, 8.5, 0.0, 0.0},      // dig start: dipper at the toe of the bank
        {5.0, 55.0, 8.0, 0.0, 0.0},
        {10.0, 30.0, 7.6, 0.0, 0.0},
        {15.0, 0.0, 7.5, 0.0, 0.0},     // dig end: handle level, dipper high and full
        {25.0, 20.0, 6.5, 90.0, 0.0},   // swung to the truck, lowered to the dump pose
        {26.0, 20.0, 6.5, 90.0, 60.0},  // door open
        {28.0, 20.0, 6.5, 90.0, 60.0},
        // swinging back high (the lowest point 8 m up), door shut; the crawlers propel from 28 s to 41 s
        {33.0, 10.0, 6.5, 45.0, 0.0, 5.0 / 13.0},
        {37.0, 10.0, 6.5, 0.0, 0.0, 9.0 / 13.0},
        {39.0, 10.0, 4.0, 0.0, 0.0, 11.0 / 13.0}, // crowd drawn in
        {42.0, 70.0, 5.0, 0.0, 0.0, 1.0},         // lowered, hanging in front of the bank
        {45.0, toe, 8.5, 0.0, 0.0, 1.0},          // crowded out into the toe
        {45.99, toe, 8.5, 0.0, 0.0, 1.0},
    };
    return repeated(g, d, pass, kDefaultCyclePass_s, 3,
                    advance_per_pass_m > 0.0 ? concat("default three-pass loading cycle, advancing ", advance_per_pass_m, " m per pass")
                                             : std::string("default three-pass loading cycle"),
                    advance_per_pass_m);
}

MotionCurves dig_and_return_cycle(const ShovelGeometry& g, const meshes::Dipper& d, int cycles)
{
    if (cycles < 1 || cycles > 1000) throw InputError(concat("dig_and_return_cycle: cycles = ", cycles, "; expected 1 to 1000"));
    const double toe = toe_handle_angle_deg(g, d);
    const std::vector<KeyPose> pass = {
        {0.0, toe, 8.5, 0.0, 0.0},      // the default cycle's dig
        {5.0, 55.0, 8.0, 0.0, 0.0},
        {10.0, 30.0, 7.6, 0.0, 0.0},
        {15.0, 0.0, 7.5, 0.0, 0.0},
        {19.0, 20.0, 3.0, 0.0, 0.0},    // crowd drawn in: the heel 8 m above the toe, the door facing down
        {20.0, 20.0, 3.0, 0.0, 60.0},   // door open: the load falls where the next dig begins
        {24.0, 20.0, 3.0, 0.0, 60.0},
        {25.0, 20.0, 3.0, 0.0, 0.0},    // door shut
        {29.0, toe, 8.5, 0.0, 0.0},     // back at the toe
        {29.99, toe, 8.5, 0.0, 0.0},
    };
    return repeated(g, d, pass, kDigAndReturnPass_s, cycles, concat("dig-and-return cycle of ", cycles, " fillings"));
}

struct ShovelState {
    ShovelGeometry geometry;
    meshes::Dipper dipper;
    MotionCurves motion;
    std::unique_ptr<btMultiBody> body;
    std::unique_ptr<btMultiBodyJointMotor> swing_motor, crowd_motor, door_motor;
    BodyId dipper_body = -1, door_body = -1;
    btVector3 sheave_local;      // link 0
    btVector3 bail_local[2];     // link 2
    btTransform dipper_in_link;  // dipper frame in link 2's frame
    btTransform door_in_link;    // door frame in link 3's frame
    double rope_mass_kg = 0.0;   // hoisted mass per rope, for the rope damping
    double previous_length[2] = {0.0, 0.0};
    bool started = false;
    double tension[2] = {0.0, 0.0};
    struct Sample { double t, crowd, hoist; };
    std::deque<Sample> window;
    ShovelReading reading;
    btVector3 base_origin;       // where the machine stands before it propels
    btVector3 forward;           // unit, its heading on the ground
    bool propels = false;        // the motion moves the machine (else its base never changes)
};

namespace {
/// Places the machine where the motion's propel puts it at time t, moving at the propel speed, and
/// updates the links' world transforms.
void place_base(ShovelState& s, double t, double dt)
{
    btMultiBody& mb = *s.body;
    // the propel speed over the step ahead (dt of the step to come or just done; before the first step, over
    // kBaseLookAhead_s: the speed is set again before every step, and nothing reads it before)
    constexpr double kBaseLookAhead_s = 1e-3;
    const double ahead = dt > 0.0 ? dt : kBaseLookAhead_s;
    const double p = s.motion.at(t).propel_m, p_next = s.motion.at(t + ahead).propel_m;
    mb.setBasePos(s.base_origin + s.forward * p);
    mb.setBaseVel(s.forward * ((p_next - p) / ahead));
    btAlignedObjectArray<btQuaternion> scratch_q;
    btAlignedObjectArray<btVector3> scratch_m;
    mb.forwardKinematics(scratch_q, scratch_m);
    mb.updateCollisionObjectWorldTransforms(scratch_q, scratch_m);
}
}  // namespace

void ShovelDeleter::operator()(ShovelState* s) const { delete s; }

namespace {
void read_pose(ShovelState& s);
}

RigidWorld::Impl::~Impl()
{
    if (shovel) {
        for (auto* m : {shovel->swing_motor.get(), shovel->crowd_motor.get(), shovel->door_motor.get()})
            if (m) world.removeMultiBodyConstraint(m);
        world.removeMultiBody(shovel->body.get());
    }
    // The broad phase's pairs go first, each in constant time: removing a body drops its pairs by a pass over
    // all of them, which for a pile of 20,000 rocks made the world's end quadratic (seconds).
    btOverlappingPairCache* cache = broadphase.getOverlappingPairCache();
    while (cache->getNumOverlappingPairs() > 0) {
        const btBroadphasePair& last = cache->getOverlappingPairArray()[cache->getNumOverlappingPairs() - 1];
        cache->removeOverlappingPair(last.m_pProxy0, last.m_pProxy1, &dispatcher);
    }
    for (auto& b : bodies) {
        if (b->body) world.removeRigidBody(b->body.get());
        else if (b->link_collider) world.removeCollisionObject(b->link_collider.get());
    }
}

RigidWorld::ShovelParts RigidWorld::add_rope_shovel(const meshes::Dipper& dipper, const ShovelGeometry& g, MotionCurves motion,
                                                    int dipper_material, const Vec3& position_m, double heading_deg)
{
    if (impl_->shovel) throw InputError("add_rope_shovel: the world has a rope shovel already; one per world");
    check_geometry(g);
    impl_->check_material(dipper_material, "rope shovel dipper");
    if (!is_finite(position_m) || !std::isfinite(heading_deg)) throw InputError("rope shovel: position or heading is not finite");
    std::unique_ptr<ShovelState, ShovelDeleter> s(new ShovelState());
    s->geometry = g;
    s->dipper = dipper;
    s->motion = std::move(motion);

    // ---- the zero pose: handle level (angle 0), crowd extension 0, swing 0, door shut; all link frames
    // have the machine's axes there
    const ShovelPose zero = pose_shovel(g, dipper, 0.0, 0.0);
    const Vec3 shaft = zero.shipper_shaft_m;
    const Mat3 r0 = zero.dipper_rotation;
    const Vec3 o0 = zero.dipper_origin_m;
    const auto [body_volume, body_centre] = steel(dipper.body.plates);
    const auto [door_volume, door_centre] = steel(dipper.door.plates);
    (void)body_volume;
    (void)door_volume;
    const Vec3 handle_centre = shaft - zero.handle_axis * (g.handle_length_m / 2.0);
    const Vec3 dipper_centre = o0 + r0 * body_centre;
    const Vec3 payload_centre = o0 + r0 * struck_centroid(dipper.parameters);
    const double m2 = g.handle_mass_kg + g.dipper_mass_kg + g.payload_kg;
    const Vec3 com2 = (handle_centre * g.handle_mass_kg + dipper_centre * g.dipper_mass_kg + payload_centre * g.payload_kg) * (1.0 / m2);
    const Vec3 hinge0 = o0 + r0 * dipper.door_hinge_m;
    const Vec3 com3 = hinge0 + r0 * door_centre;
    const auto& p = dipper.parameters;
    Vec3 inertia2 = shifted(box_inertia(g.handle_mass_kg, g.handle_length_m, g.handle_section_m, g.handle_section_m), g.handle_mass_kg, handle_centre - com2);
    const Vec3 dipper_box = box_inertia(g.dipper_mass_kg, p.bottom_length_m, p.width_m, p.height_m);
    const Vec3 payload_box = box_inertia(g.payload_kg, 0.75 * p.bottom_length_m, p.width_m, p.height_m);
    const Vec3 d2 = shifted(dipper_box, g.dipper_mass_kg, dipper_centre - com2), p2 = shifted(payload_box, g.payload_kg, payload_centre - com2);
    inertia2 = inertia2 + d2 + p2;
    const Vec3 inertia0 = box_inertia(g.upper_body_mass_kg, 12.0, 9.0, 8.0);
    const Vec3 inertia1 = box_inertia(g.saddle_mass_kg, 2.0, 2.0, 2.0);
    const Vec3 inertia3 = box_inertia(g.door_mass_kg, 0.3, p.width_m, p.height_m);

    s->body = std::make_unique<btMultiBody>(4, 1.0e5, btVector3(1e6, 1e6, 1e6), true, false);
    btMultiBody& mb = *s->body;
    const btQuaternion same(0, 0, 0, 1);
    mb.setupRevolute(0, g.upper_body_mass_kg, to_bt(inertia0), -1, same, btVector3(0, 0, 1), btVector3(0, 0, 0),
                     to_bt(g.upper_body_centre_m), true);
    mb.setupRevolute(1, g.saddle_mass_kg, to_bt(inertia1), 0, same, btVector3(0, 1, 0), to_bt(shaft - g.upper_body_centre_m),
                     btVector3(0, 0, 0), true);
    mb.setupPrismatic(2, m2, to_bt(inertia2), 1, same, btVector3(1, 0, 0), btVector3(0, 0, 0), to_bt(com2 - shaft), true);
    mb.setupRevolute(3, g.door_mass_kg, to_bt(inertia3), 2, same, btVector3(0, 1, 0), to_bt(hinge0 - com2), to_bt(com3 - hinge0), true);
    mb.setLinearDamping(0.0);
    mb.setAngularDamping(0.0);
    mb.setHasSelfCollision(false);
    mb.setCanSleep(false);
    mb.finalizeMultiDof();
    const btTransform machine(btQuaternion(btVector3(0, 0, 1), heading_deg * kDeg), to_bt(position_m));
    mb.setBaseWorldTransform(machine);
    s->base_origin = to_bt(position_m);
    s->forward = btVector3(std::cos(heading_deg * kDeg), std::sin(heading_deg * kDeg), 0.0);

    s->sheave_local = to_bt(zero.sheave_m - g.upper_body_centre_m);
    for (int k = 0; k < 2; ++k) s->bail_local[k] = to_bt(zero.bail_m[k] - com2);
    s->dipper_in_link = btTransform(to_bt(r0), to_bt(o0 - com2));
    s->door_in_link = btTransform(to_bt(r0), to_bt(hinge0 - com3));
    s->rope_mass_kg = (m2 + g.door_mass_kg) / 2.0;

    // ---- colliders: the dipper and handle on link 2, the door on link 3
    // (Bullet solves a multibody motor only in the island of a collider on its link or the base, so the
    // crawlers and the upper body get colliders too: boxes for the undercarriage and the house)
    const auto make_link_body = [&](int link, const std::string& name, const std::vector<meshes::Plate>& plates,
                                    const btTransform& part_in_link, bool with_handle, const Vec3& box_half = {},
                                    const Vec3& box_centre = {}) {
        auto b = std::make_unique<Impl::Body>();
        b->name = name;
        b->material = dipper_material;
        b->multibody = &mb;
        b->link = link;
        b->part_in_object = part_in_link;
        auto compound = std::make_unique<btCompoundShape>();
        add_plate_hulls(*compound, b->children, plates, part_in_link, impl_->settings.rock_margin_m, name);
        if (with_handle) {
            const double half = g.handle_section_m / 2.0;
            auto beam = std::make_unique<btBoxShape>(btVector3(g.handle_length_m / 2.0, half, half));
            compound->addChildShape(btTransform(btQuaternion(0, 0, 0, 1), to_bt(handle_centre - com2)), beam.get());
            b->children.push_back(std::move(beam));
        }
        if (box_half.x > 0.0) {
            auto box = std::make_unique<btBoxShape>(to_bt(box_half));
            compound->addChildShape(btTransform(btQuaternion(0, 0, 0, 1), to_bt(box_centre)), box.get());
            b->children.push_back(std::move(box));
        }
        b->shape = std::move(compound);
        b->link_collider = std::make_unique<btMultiBodyLinkCollider>(&mb, link);
        b->link_collider->setCollisionShape(b->shape.get());
        b->link_collider->setCollisionFlags(b->link_collider->getCollisionFlags() | btCollisionObject::CF_CUSTOM_MATERIAL_CALLBACK);
        b->link_collider->setUserPointer(&impl_->pairs);
        b->link_collider->setUserIndex(dipper_material);
        const BodyId id = static_cast<BodyId>(impl_->bodies.size());
        b->link_collider->setUserIndex2(id);
        b->link_collider->setActivationState(DISABLE_DEACTIVATION);
        if (link < 0) mb.setBaseCollider(b->link_collider.get());
        else mb.getLink(link).m_collider = b->link_collider.get();
        impl_->world.addCollisionObject(b->link_collider.get(), Impl::kMachineFilter, btBroadphaseProxy::AllFilter);
        impl_->bodies.push_back(std::move(b));
        impl_->contact_force.resize(impl_->bodies.size());
        return id;
    };
    make_link_body(-1, "crawlers", {}, btTransform::getIdentity(), false, {4.5, 4.0, 1.0}, {0.0, 0.0, 1.0});
    make_link_body(0, "upper body", {}, btTransform::getIdentity(), false, {5.0, 4.0, 2.5}, Vec3{0.0, 0.0, 4.5} - g.upper_body_centre_m);
    s->dipper_body = make_link_body(2, "dipper", dipper.body.plates, s->dipper_in_link, true);
    s->door_body = make_link_body(3, "door", dipper.door.plates, s->door_in_link, false);
    impl_->world.addMultiBody(&mb);

    // ---- drives
    // their largest impulses are force x step, set before each step (shovel_before_step)
    s->swing_motor = std::make_unique<btMultiBodyJointMotor>(&mb, 0, 0.0, 0.0);
    s->crowd_motor = std::make_unique<btMultiBodyJointMotor>(&mb, 2, 0.0, 0.0);
    s->door_motor = std::make_unique<btMultiBodyJointMotor>(&mb, 3, 0.0, 0.0);
    for (auto* m : {s->swing_motor.get(), s->crowd_motor.get(), s->door_motor.get()}) impl_->world.addMultiBodyConstraint(m);

    // ---- initial pose: the handle angle at which the ropes are just taut at the first hoist length
    const MotionSample m0 = s->motion.at(0.0);
    double lo = -60.0, hi = 89.0;  // the rope shortens as the handle rises
    const double length_lo = pose_shovel(g, dipper, lo, m0.crowd_extension_m).rope_length_m;
    const double length_hi = pose_shovel(g, dipper, hi, m0.crowd_extension_m).rope_length_m;
    if (m0.hoist_length_m > std::max(length_lo, length_hi)) {
        hi = lo = length_lo > length_hi ? -60.0 : 89.0;  // paid out beyond reach: the ropes start slack
    } else if (m0.hoist_length_m < std::min(length_lo, length_hi))
        throw InputError(concat(s->motion.source(), ": the first hoist length ", m0.hoist_length_m, " m cannot hold the dipper at crowd ",
                                m0.crowd_extension_m, " m (reachable: ", std::min(length_lo, length_hi), " to ",
                                std::max(length_lo, length_hi), " m)"));
    for (int it = 0; it < 100 && hi != lo; ++it) {
        const double mid = 0.5 * (lo + hi);
        const double length = pose_shovel(g, dipper, mid, m0.crowd_extension_m).rope_length_m;
        if ((length - m0.hoist_length_m) * (length_lo - m0.hoist_length_m) > 0.0) lo = mid;
        else hi = mid;
    }
    mb.setJointPos(0, m0.swing_deg * kDeg);
    mb.setJointPos(1, 0.5 * (lo + hi) * kDeg);
    mb.setJointPos(2, m0.crowd_extension_m);
    mb.setJointPos(3, m0.door_deg * kDeg);
    for (const MotionSample& m : s->motion.samples()) s->propels = s->propels || m.propel_m != 0.0;
    place_base(*s, impl_->time_s, impl_->step_s);
    for (auto& b : impl_->bodies)
        if (b->multibody) b->previous_pose = b->link_collider->getWorldTransform();

    const ShovelParts parts{s->dipper_body, s->door_body};
    impl_->shovel = std::move(s);
    read_pose(*impl_->shovel);
    impl_->shovel->reading.time_s = impl_->time_s;
    return parts;
}

void shovel_before_step(RigidWorld::Impl& w, double t_next)
{
    ShovelState& s = *w.shovel;
    btMultiBody& mb = *s.body;
    const double dt = w.step_s;
    if (s.propels) place_base(s, t_next - dt, dt);
    // drives: reach the curves' positions at the end of the step
    const MotionSample target = s.motion.at(t_next);
    s.swing_motor->setPositionTarget(target.swing_deg * kDeg, 1.0);
    s.swing_motor->setVelocityTarget(0.0, 1.0);
    s.swing_motor->setMaxAppliedImpulse(1e10 * dt);
    s.crowd_motor->setPositionTarget(target.crowd_extension_m, 1.0);
    s.crowd_motor->setVelocityTarget(0.0, 1.0);
    s.crowd_motor->setMaxAppliedImpulse(s.geometry.max_crowd_force_N * dt);
    s.door_motor->setPositionTarget(target.door_deg * kDeg, 1.0);
    s.door_motor->setVelocityTarget(0.0, 1.0);
    s.door_motor->setMaxAppliedImpulse(1e9 * dt);

    // ropes: tension only, T = k (d - L) + c d', k = EA / L, from the state at the start of the step
    const double paid_out = s.motion.at(t_next - dt).hoist_length_m;
    const double k = s.geometry.rope_axial_stiffness_N / paid_out;
    const double c = 2.0 * s.geometry.rope_damping_ratio * std::sqrt(k * s.rope_mass_kg);
    const btVector3 sheave = mb.localPosToWorld(0, s.sheave_local);
    const btVector3 com2 = mb.getLink(2).m_collider->getWorldTransform().getOrigin();
    const btVector3 com0 = mb.localPosToWorld(0, btVector3(0, 0, 0));
    for (int r = 0; r < 2; ++r) {
        const btVector3 bail = mb.localPosToWorld(2, s.bail_local[r]);
        const btVector3 span = sheave - bail;
        const double length = span.length();
        const double rate = s.started ? (length - s.previous_length[r]) / dt : 0.0;
        s.previous_length[r] = length;
        double tension = 0.0;
        if (length > paid_out) tension = std::max(0.0, k * (length - paid_out) + c * rate);
        s.tension[r] = tension;
        if (tension == 0.0) continue;
        const btVector3 f = span * (tension / length);  // pulls the bail towards the sheave
        mb.addLinkForce(2, f);
        mb.addLinkTorque(2, (bail - com2).cross(f));
        mb.addLinkForce(0, -f);
        mb.addLinkTorque(0, (sheave - com0).cross(-f));
    }
    s.started = true;
}

namespace {

/// The pose part of the reading: joints, rope lengths, heel, tooth tip and rake angle.
void read_pose(ShovelState& s)
{
    btMultiBody& mb = *s.body;
    ShovelReading& r = s.reading;
    r.swing_deg = mb.getJointPos(0) / kDeg;
    r.handle_angle_deg = mb.getJointPos(1) / kDeg;
    r.crowd_extension_m = mb.getJointPos(2);
    r.door_deg = mb.getJointPos(3) / kDeg;
    const btTransform link2 = mb.getLink(2).m_collider->getWorldTransform();
    const btTransform dipper = link2 * s.dipper_in_link;
    const btVector3 sheave = mb.localPosToWorld(0, s.sheave_local);
    for (int k = 0; k < 2; ++k) r.rope_length_m[k] = (sheave - link2 * s.bail_local[k]).length();
    r.heel_m = from_bt(dipper.getOrigin());
    r.tooth_tip_m = from_bt(dipper * to_bt(s.dipper.tooth_tip_m));
    const Vec3 to_saddle = from_bt(-link2.getBasis().getColumn(0));  // the handle axis points to the dipper
    const Vec3 heel_to_tip = normalized(r.tooth_tip_m - r.heel_m);
    r.rake_angle_deg = std::acos(std::clamp(std::abs(dot(heel_to_tip, to_saddle)), 0.0, 1.0)) / kDeg;
}

}  // namespace

void shovel_after_step(RigidWorld::Impl& w)
{
    ShovelState& s = *w.shovel;
    const double dt = w.step_s;
    ShovelReading& r = s.reading;
    r.time_s = w.time_s;
    r.crowd_force_N = s.crowd_motor->getAppliedImpulse(0) / dt;
    r.rope_tension_N[0] = s.tension[0];
    r.rope_tension_N[1] = s.tension[1];
    r.hoist_force_N = s.tension[0] + s.tension[1];
    r.dig_force_N = std::hypot(r.crowd_force_N, r.hoist_force_N);
    s.window.push_back({r.time_s, r.crowd_force_N, r.hoist_force_N});
    while (!s.window.empty() && s.window.front().t <= r.time_s - s.geometry.force_filter_window_s) s.window.pop_front();
    double crowd = 0.0, hoist = 0.0;
    for (const auto& x : s.window) {
        crowd += x.crowd;
        hoist += x.hoist;
    }
    const double n = static_cast<double>(std::max<std::size_t>(1, s.window.size()));
    r.crowd_force_filtered_N = crowd / n;
    r.hoist_force_filtered_N = hoist / n;
    r.dig_force_filtered_N = std::hypot(r.crowd_force_filtered_N, r.hoist_force_filtered_N);

    if (s.propels) place_base(s, w.time_s, dt);  // exactly where the propel curve has the machine now
    read_pose(s);
}

namespace {

/// The shovel's checkpoint fields, listed once for writing and reading (core/state_io.h): its joints, the
/// ropes, the force window and the last reading.
template <class IO, class State>
void shovel_state_fields(IO& io, State& s)
{
    io.tag("rope shovel");
    for (int j = 0; j < 4; ++j) {
        double position = s.body->getJointPos(j), velocity = s.body->getJointVel(j);
        io(position, velocity);
        if constexpr (IO::reading) {
            s.body->setJointPos(j, position);
            s.body->setJointVel(j, velocity);
        }
    }
    for (int r = 0; r < 2; ++r) io(s.previous_length[r], s.tension[r]);
    std::vector<ShovelState::Sample> window(s.window.begin(), s.window.end());
    io(s.started, window, s.reading);
    if constexpr (IO::reading) s.window.assign(window.begin(), window.end());
}

}  // namespace

void write_shovel_state(const ShovelState& s, StateWriter& out) { shovel_state_fields(out, s); }

void read_shovel_state(ShovelState& s, StateReader& in, double last_step_s)
{
    shovel_state_fields(in, s);
    btAlignedObjectArray<btQuaternion> scratch_q;
    btAlignedObjectArray<btVector3> scratch_m;
    s.body->forwardKinematics(scratch_q, scratch_m);
    s.body->updateCollisionObjectWorldTransforms(scratch_q, scratch_m);
    place_base(s, s.reading.time_s, last_step_s);
}

const ShovelReading& RigidWorld::shovel_reading() const
{
    if (!impl_->shovel) throw InputError("shovel_reading: the world has no rope shovel");
    return impl_->shovel->reading;
}

void RigidWorld::dipper_pose(Mat3& rotation, Vec3& origin_m) const
{
    if (!impl_->shovel) throw InputError("dipper_pose: the world has no rope shovel");
    const btTransform t = impl_->shovel->body->getLink(2).m_collider->getWorldTransform() * impl_->shovel->dipper_in_link;
    rotation = from_bt(t.getBasis());
    origin_m = from_bt(t.getOrigin());
}

void RigidWorld::door_pose(Mat3& rotation, Vec3& origin_m) const
{
    if (!impl_->shovel) throw InputError("door_pose: the world has no rope shovel");
    const btTransform t = impl_->shovel->body->getLink(3).m_collider->getWorldTransform() * impl_->shovel->door_in_link;
    rotation = from_bt(t.getBasis());
    origin_m = from_bt(t.getOrigin());
}

}  // namespace dipper::rigid
