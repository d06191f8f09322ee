// Piles of rocks in Bullet: a pile comes to rest, dipper's narrow phase and solver groups against Bullet's own,
// the same bits on any number of threads.
#include "coupling/mixed_bed.h"
#include "core/errors.h"
#include "meshes/machine_geometry.h"
#include "meshes/mesh_builder.h"
#include "meshes/triangle_mesh.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/rigid_world.h"
#include "rigid/rope_shovel.h"
#include "rigid/rock_generator.h"
#include "rigid/rock_helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

using namespace dipper;
using namespace dipper::rigid;
using namespace dipper::test;

namespace {

struct PileResult {
    double mass_kg, energy_J, deepest_m, reaction_over_weight;
};

/// `count` rocks of 300-400 mm dropped from a loose lattice of 10 x 10 per layer (0.5 m apart, layers
/// 0.55 m apart) onto the ground, Table 2 rock-rock friction 0.85, settled for `settle_s` at 1e-3 s; then
/// 100 steps measured.
PileResult settle_pile(int count, double settle_s)
{
    RigidWorld w = rock_world(kTable2RockFriction.rock);
    const BodyId ground = w.add_ground_plane(0.0, 1, "ground");
    PileResult r{0.0, 0.0, 0.0, 0.0};
    for (int k = 0; k < count; ++k) {
        const int i = k % 10, j = (k / 10) % 10, layer = k / 100;
        const ConvexPolyhedron rock = generate_rock({0.3 + 0.1 * (k % 2), 1.0, 1.8, 18}, 9000 + static_cast<std::uint64_t>(k));
        const BodyId id = w.add_rock(rock, 2700.0, 0, {0.5 * i, 0.5 * j, 0.3 + 0.55 * layer},
                                     rotation_about_axis({0.0, 0.0, 1.0}, 0.7 * k));
        r.mass_kg += w.mass_kg(id);
    }
    for (int k = 0; k < static_cast<int>(std::lround(settle_s / 1e-3)); ++k) w.step(1e-3);
    Vec3 sum;
    for (int k = 0; k < 100; ++k) {
        w.step(1e-3);
        sum += w.contact_force_N(ground);
        r.deepest_m = std::max(r.deepest_m, w.max_penetration_m());
    }
    r.energy_J = w.kinetic_energy_J();
    r.reaction_over_weight = -sum.z / 100.0 / (r.mass_kg * 9.81);
    return r;
}

}  // namespace

TEST_CASE("a pile of 100 rocks comes to rest on the ground", "[rigid][rocks][pile][unit]")
{
    // Bounds: kinetic energy below 1 mJ per kg of rock (a mean speed under 4.5 cm/s; Bullet's impulse
    // solver leaves a small jitter, notes/bullet-measurements.md), deepest overlap below 5 mm, and the ground
    // carrying the pile's weight within 1 % averaged over 100 steps. Measured: 0.042 J for 6.4 t, 0.013 mm,
    // reaction / weight 1.0001.
    const PileResult r = settle_pile(100, 3.0);
    CHECK(r.energy_J < 1e-3 * r.mass_kg);
    CHECK(r.deepest_m < 0.005);
    CHECK(r.reaction_over_weight == Approx(1.0).epsilon(0.01));
}

TEST_CASE("a pile of 500 rocks comes to rest on the ground", "[rigid][rocks][pile][slow]")
{
    // The same bounds for five layers of 100 (a few minutes: ctest -L slow).
    const PileResult r = settle_pile(500, 8.0);
    CHECK(r.energy_J < 1e-3 * r.mass_kg);
    CHECK(r.deepest_m < 0.005);
    CHECK(r.reaction_over_weight == Approx(1.0).epsilon(0.01));
    WARN("pile of 500: KE " << r.energy_J << " J for " << r.mass_kg << " kg, deepest " << r.deepest_m << " m, reaction/weight " << r.reaction_over_weight);
}

namespace {

/// Two spinning rocks thrown at each other without gravity, or one rock dropped spinning onto a steel plate
/// (a compound of plate hulls), stepped with dipper's hull-pair narrow phase or with Bullet's own.
struct Throw {
    std::vector<BodyState> states;
    Vec3 velocity_change;  ///< of the first rock over the run: shows that the bodies met
    std::size_t steps_with_contact = 0;
    std::vector<std::size_t> points_per_step;  ///< contact points in the manifolds after each step
};

Throw throw_rocks(std::uint64_t seed, bool onto_plate, bool bullet_pairs, int threads = 1)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    RigidSettings s;
    s.gravity_m_per_s2 = onto_plate ? Vec3{0.0, 0.0, -9.81} : Vec3{};
    s.bullet_convex_pairs = bullet_pairs;
    s.threads = threads;
    RigidWorld w = rock_world(s, "steel", 0.7, 0.3, 0.5, 0.3);
    auto spin = [&](double rate) { return Vec3{u(rng), u(rng), u(rng)} * rate; };
    std::vector<BodyId> rocks;
    const ConvexPolyhedron a = generate_rock({0.6, 1.8, 2.0, 20}, 100 + seed);
    rocks.push_back(w.add_rock(a, 2700.0, 0, {-0.8, 0.1 * u(rng), 0.1 * u(rng)}, rotation_about_axis(normalized(Vec3{u(rng), u(rng), 1.0}), 3.0 * u(rng)),
                               onto_plate ? Vec3{0.8, 0.3 * u(rng), 0.0} : Vec3{2.0, 0.2 * u(rng), 0.2 * u(rng)}, spin(15.0)));
    if (onto_plate) {
        const std::vector<meshes::Plate> plates{meshes::box_plate({-1.0, -1.0, -1.2}, {1.5, 1.0, -1.0}),
                                                meshes::box_plate({0.6, -1.0, -1.0}, {0.8, 1.0, -0.2})};
        w.add_plates(plates, 1, "plates", false);
    } else {
        const ConvexPolyhedron b = generate_rock({0.3, 1.5, 2.0, 20}, 200 + seed);
        rocks.push_back(w.add_rock(b, 2700.0, 0, {0.8, 0.1 * u(rng), 0.1 * u(rng)}, Mat3::identity(), {-2.0, 0.0, 0.0}, spin(30.0)));
    }
    const Vec3 v0 = w.state(rocks[0]).velocity_m_per_s;
    Throw t;
    for (int k = 0; k < 1500; ++k) {
        w.step(1e-3);
        t.steps_with_contact += w.contact_point_count() > 0 ? 1 : 0;
    }
    for (BodyId r : rocks) t.states.push_back(w.state(r));
    t.velocity_change = w.state(rocks[0]).velocity_m_per_s - v0 - s.gravity_m_per_s2 * 1.5;
    return t;
}

}  // namespace

TEST_CASE("hull pairs: dipper's narrow phase moves rocks exactly as Bullet's own does", "[rigid][rocks][unit]")
{
    // dipper's hull-pair algorithm finds contact points with the same GJK queries as Bullet's, but keeps no
    // manifold for a pair that is apart and does not search it again until the bodies' motion could have
    // closed its gap (a bound from translation along the separating direction and rotation times radius).
    // Had that bound ever let a pair skip a step on which Bullet finds a point, the two runs would part. With
    // one pair of bodies the solver sees the same points in the same order, so the runs must agree to
    // round-off: 1e-9 m and 1e-9 of the rotation. The rocks are elongated (1.8-2 and 1.5-2) and spin at up
    // to 15 and 30 rad/s, where the rotation part of the bound matters; each run must include contact.
    for (std::uint64_t seed = 1; seed <= 8; ++seed)
        for (bool plate : {false, true}) {
            CAPTURE(seed, plate);
            const Throw ours = throw_rocks(seed, plate, false);
            const Throw bullet = throw_rocks(seed, plate, true);
            CHECK(norm(ours.velocity_change) > 0.2);
            CHECK(ours.steps_with_contact > 5);
            CHECK(ours.steps_with_contact == bullet.steps_with_contact);
            for (std::size_t k = 0; k < ours.states.size(); ++k) {
                CHECK(norm(ours.states[k].position_m - bullet.states[k].position_m) < 1e-9);
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) CHECK(std::abs(ours.states[k].rotation.m[i][j] - bullet.states[k].rotation.m[i][j]) < 1e-9);
            }
        }
}

namespace {

/// 98 rocks of 300-850 mm dropped in two layers into a fixed open box (a triangle mesh) on the ground
/// plane, 500 steps of 1e-3 s: they fall, strike the floor, the walls and each other, and begin to settle,
/// so that hull pairs come into and out of contact (manifolds made and released) and rocks touch the mesh and
/// the plane. Returns every rock's state and the reactions of the box and the ground at the end.
struct Drop {
    std::vector<BodyState> states;
    Vec3 box_force, ground_force;
    std::size_t contact_points = 0, manifolds = 0;
};

Drop drop_into_box(int threads, bool bullet_pairs)
{
    RigidSettings s;
    s.threads = threads;
    s.bullet_convex_pairs = bullet_pairs;
    RigidWorld w = rock_world(s, "ground", kTable2RockFriction.rock, 0.1, 0.8, 0.1);
    const BodyId ground = w.add_ground_plane(0.0, 1, "ground");
    const BodyId box = w.add_static_mesh(meshes::make_open_box_mesh(3.0, 3.0, 2.0, 1.0), 1, "box");
    const std::vector<coupling::RockClass> table1 = coupling::MixedDistribution::thesis_table1().rocks;
    std::vector<BodyId> rocks;
    for (int k = 0; k < 98; ++k) {
        const int i = k % 7, j = (k / 7) % 7, layer = k / 49;
        const ConvexPolyhedron r = generate_rock({table1[k % 4].size_m, 1.0, 1.8, 16}, 500 + static_cast<std::uint64_t>(k));
        rocks.push_back(w.add_rock(r, 2700.0, 0, {0.25 + 0.42 * i, 0.25 + 0.42 * j, 0.5 + 0.9 * layer},
                                   rotation_about_axis(normalized(Vec3{1.0, 0.3 * (k % 3), 0.5}), 0.9 * k)));
    }
    for (int k = 0; k < 500; ++k) w.step(1e-3);
    Drop d;
    for (BodyId r : rocks) d.states.push_back(w.state(r));
    d.box_force = w.contact_force_N(box);
    d.ground_force = w.contact_force_N(ground);
    d.contact_points = w.contact_point_count();
    d.manifolds = w.pair_counts().touching_manifolds;
    return d;
}

bool same_bits(const Vec3& a, const Vec3& b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

}  // namespace

TEST_CASE("the narrow phase on 2 and 3 threads moves rocks to the same bits as on one", "[rigid][rocks][threads][unit]")
{
    // RigidSettings::threads spreads the pairs' contact search over threads, while manifolds are made and
    // released on one thread in the pairs' order (rigid/detail/dispatcher.h), so Bullet's solver sees the
    // same contact rows in the same order. The solver itself then runs the groups of rocks that touch through
    // contact points on the threads, each group's rows in the dispatcher's order (rigid/detail/dynamics_world.h), and
    // the per-body loops run there too. Any difference in a single contact point or row would change the rocks'
    // motion after 500 steps of a falling pile, so the test asks for equality of every bit: positions,
    // rotations, velocities, and the reactions of the box and the ground. Both hull-pair algorithms: Bullet's
    // keeps an empty manifold for every pair of overlapping boxes, which a group must not take up.
    for (bool bullet_pairs : {false, true}) {
        CAPTURE(bullet_pairs);
        const Drop one = drop_into_box(1, bullet_pairs);
        // the pile must touch the mesh, the plane and itself for the check to mean anything
        CHECK(norm(one.box_force) > 1e3);
        CHECK(norm(one.ground_force) > 1e4);
        CHECK(one.manifolds > 100);
        for (int threads : bullet_pairs ? std::vector<int>{2} : std::vector<int>{2, 3}) {
            CAPTURE(threads);
            const Drop many = drop_into_box(threads, bullet_pairs);
            CHECK(many.contact_points == one.contact_points);
            CHECK(same_bits(many.box_force, one.box_force));
            CHECK(same_bits(many.ground_force, one.ground_force));
            bool all_same = true;
            for (std::size_t k = 0; k < one.states.size(); ++k) {
                const BodyState& a = one.states[k];
                const BodyState& b = many.states[k];
                all_same = all_same && same_bits(a.position_m, b.position_m) && same_bits(a.velocity_m_per_s, b.velocity_m_per_s) &&
                           same_bits(a.angular_velocity_rad_per_s, b.angular_velocity_rad_per_s);
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) all_same = all_same && a.rotation.m[i][j] == b.rotation.m[i][j];
            }
            CHECK(all_same);
        }
    }
    // On two threads a hull pair found apart is passed over while the growth of its bodies' odometers stays
    // below what is left of its gap (dispatcher.cpp). The spinning, elongated throws of the test above are where
    // the rotation part of that bound matters: the same bits as on one thread.
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
        CAPTURE(seed);
        const Throw one = throw_rocks(seed, false, false, 1);
        const Throw two = throw_rocks(seed, false, false, 2);
        CHECK(one.steps_with_contact > 5);
        CHECK(two.steps_with_contact == one.steps_with_contact);
        for (std::size_t k = 0; k < one.states.size(); ++k) {
            CHECK(same_bits(two.states[k].position_m, one.states[k].position_m));
            CHECK(same_bits(two.states[k].angular_velocity_rad_per_s, one.states[k].angular_velocity_rad_per_s));
        }
    }
}

TEST_CASE("the solver's groups move rocks exactly as Bullet's islands do where both order the rows alike", "[rigid][rocks][unit]")
{
    // Where no body may sleep and there is no joint or multibody, the solver builds no islands: it solves the
    // groups of bodies that touch through contact points (rigid/detail/dynamics_world.h), each group's rows in
    // the dispatcher's order of manifolds. Bullet's islands order a group's manifolds their own way, so the two
    // agree bit for bit where each group holds one manifold: here twelve rocks far apart, each dropped spinning
    // and sliding onto the ground, bouncing and tumbling there. A rope shovel 100 m away (a multibody) sends the
    // second world to Bullet's islands without touching the rocks. A group that lost a body (whose gravity
    // reaches its velocity through the solver), lost a row or solved one twice would part the runs.
    struct Run {
        std::vector<BodyState> states;
        Vec3 ground_force;
        std::size_t steps_with_contact = 0;
    };
    auto drop = [](bool islands) {
        RigidSettings s;
        RigidWorld w = rock_world(s, "ground", 0.6, 0.3, 0.6, 0.3);
        const BodyId ground = w.add_ground_plane(0.0, 1, "ground");
        if (islands) {
            const meshes::Dipper dipper = meshes::make_dipper({});
            const ShovelGeometry g;
            const double hoist = pose_shovel(g, dipper, 30.0, 8.0).rope_length_m;
            w.add_rope_shovel(dipper, g, MotionCurves::from_samples({{0.0, hoist, 8.0, 0.0, 0.0}, {10.0, hoist, 8.0, 0.0, 0.0}}, "hold"), 1,
                              {100.0, 100.0, 0.0});
        }
        const std::vector<coupling::RockClass> table1 = coupling::MixedDistribution::thesis_table1().rocks;
        std::vector<BodyId> rocks;
        for (int k = 0; k < 12; ++k)
            rocks.push_back(w.add_rock(generate_rock({table1[k % 4].size_m, 1.0, 1.8, 16}, 700 + static_cast<std::uint64_t>(k)), 2700.0, 0,
                                       {2.5 * (k % 4), 2.5 * (k / 4), 0.6 + 0.05 * k},
                                       rotation_about_axis(normalized(Vec3{1.0, 0.4 * (k % 3), 0.7}), 0.8 * k),
                                       {0.5 * ((k % 3) - 1.0), 0.3, 0.0}, Vec3{2.0, -1.0 + 0.3 * k, 0.5}));
        Run r;
        for (int k = 0; k < 1000; ++k) {
            w.step(1e-3);
            r.steps_with_contact += w.contact_point_count() > 0 ? 1 : 0;
        }
        for (BodyId b : rocks) r.states.push_back(w.state(b));
        r.ground_force = w.contact_force_N(ground);
        return r;
    };
    const Run groups = drop(false), islands = drop(true);
    CHECK(groups.steps_with_contact > 500);  // the rocks land within 0.4 s and stay on the ground
    CHECK(norm(groups.ground_force) > 1e3);
    for (std::size_t k = 0; k < groups.states.size(); ++k) {
        CAPTURE(k);
        const BodyState& a = groups.states[k];
        const BodyState& b = islands.states[k];
        for (std::size_t q = 0; q < k; ++q) CHECK(norm(a.position_m - groups.states[q].position_m) > 1.5);  // one manifold per group
        CHECK(same_bits(a.position_m, b.position_m));
        CHECK(same_bits(a.velocity_m_per_s, b.velocity_m_per_s));
        CHECK(same_bits(a.angular_velocity_rad_per_s, b.angular_velocity_rad_per_s));
    }
}

TEST_CASE("rocks on moving kinematic plates end with the same bits on 1, 2 and 3 threads", "[rigid][rocks][threads][unit]")
{
    // A kinematic part is not moved by its contact rows, but the solver writes its velocity back, so every group
    // that touches it joins its group (rigid/detail/dynamics_world.cpp). Four plates rise and tilt under four
    // heaps of rocks that also touch the ground and each other. The rocks' states and the plates' reactions must
    // agree to the bit, and each plate must carry its heap (a plate's manifolds left out of the groups fail that).
    struct Run {
        std::vector<BodyState> states;
        std::vector<Vec3> plate_forces;
    };
    auto run = [](int threads) {
        RigidSettings s;
        s.threads = threads;
        RigidWorld w = rock_world(s, "ground", 0.7, 0.2, 0.7, 0.2);
        w.add_ground_plane(0.0, 1, "ground");
        std::vector<BodyId> plates;
        for (int p = 0; p < 4; ++p)
            plates.push_back(w.add_kinematic_mesh(meshes::make_plate_mesh(1.6, 1.6, 2, 2), 1, concat("plate ", p), Mat3::identity(),
                                                  {1.8 * p, 0.0, 0.05}));
        const double sizes[3] = {0.3, 0.4, 0.6};
        std::vector<BodyId> rocks;
        for (int k = 0; k < 36; ++k) {
            const int p = k % 4, layer = k / 12, slot = (k / 4) % 3;
            rocks.push_back(w.add_rock(generate_rock({sizes[(k / 4) % 3], 1.0, 1.6, 16}, 900 + static_cast<std::uint64_t>(k)), 2700.0, 0,
                                       {1.8 * p + 0.3 + 0.5 * slot, 0.8 + 0.15 * (slot - 1), 0.5 + 0.7 * layer},
                                       rotation_about_axis(normalized(Vec3{0.3, 1.0, 0.2 * (k % 5)}), 0.6 * k)));
        }
        for (int k = 0; k < 800; ++k) {
            const double t = (k + 1) * 1e-3;
            for (int p = 0; p < 4; ++p)
                w.set_kinematic_pose(plates[static_cast<std::size_t>(p)], rotation_about_axis({0.0, 1.0, 0.0}, (p % 2 ? 0.3 : -0.3) * t),
                                     {1.8 * p, 0.0, 0.05 + 0.2 * t});
            w.step(1e-3);
        }
        Run r;
        for (BodyId b : rocks) r.states.push_back(w.state(b));
        for (BodyId b : plates) r.plate_forces.push_back(w.contact_force_N(b));
        return r;
    };
    const Run one = run(1);
    for (const Vec3& f : one.plate_forces) CHECK(norm(f) > 100.0);  // every plate carries rocks
    for (int threads : {2, 3}) {
        CAPTURE(threads);
        const Run many = run(threads);
        for (std::size_t p = 0; p < one.plate_forces.size(); ++p) CHECK(same_bits(one.plate_forces[p], many.plate_forces[p]));
        bool all_same = true;
        for (std::size_t k = 0; k < one.states.size(); ++k)
            all_same = all_same && same_bits(one.states[k].position_m, many.states[k].position_m) &&
                       same_bits(one.states[k].velocity_m_per_s, many.states[k].velocity_m_per_s) &&
                       same_bits(one.states[k].angular_velocity_rad_per_s, many.states[k].angular_velocity_rad_per_s);
        CHECK(all_same);
    }
}

namespace {

/// An elongated rock thrown at a fixed surface under gravity: an open box (a static triangle mesh) or the ground
/// plane. Spinning, it flies at the box's wall at x = 4 (or falls onto the plane); without spin it drops from
/// rest straight onto the box's floor (or the plane), where the odometer's growth equals its approach.
/// Its state after the run, and on how many steps the surface carried a force.
Throw throw_at_surface(std::uint64_t seed, bool mesh, bool spin, int threads)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    RigidSettings s;
    s.threads = threads;
    RigidWorld w = rock_world(s, "ground", 0.7, 0.3, 0.6, 0.4);
    const BodyId surface = mesh ? w.add_static_mesh(meshes::make_open_box_mesh(4.0, 4.0, 3.0, 1.0), 1, "box")
                                : w.add_ground_plane(0.0, 1, "ground");
    const ConvexPolyhedron shape = generate_rock({0.6, 1.8, 2.0, 20}, 300 + seed);
    // turned at random, but square to the box when it drops onto the box's floor: then the box Bullet puts around
    // the rock is as low as the rock itself, and the mesh's gap is as tight as the plane's
    Mat3 rotation = rotation_about_axis(normalized(Vec3{u(rng), u(rng), 1.0}), 3.0 * u(rng));
    if (mesh && !spin) rotation = Mat3::identity();
    Vec3 start = mesh ? Vec3{2.0, 2.0 + 0.3 * u(rng), 1.5} : Vec3{0.0, 0.0, 1.5};
    Vec3 velocity{}, angular_velocity{};
    if (spin) {
        velocity = mesh ? Vec3{3.0, 0.5 * u(rng), 1.0} : Vec3{0.5 * u(rng), 0.5 * u(rng), -1.0};
        angular_velocity = Vec3{u(rng), u(rng), u(rng)} * 20.0;
    } else {
        // released at rest with its lowest point 3-13 cm up: it meets the surface at under 1.6 m/s, 1.6 mm a step
        double lowest = 0.0;
        for (const Vec3& v : shape.vertices_m()) lowest = std::min(lowest, (rotation * v).z);
        start.z = -lowest + 0.08 + 0.05 * u(rng);
    }
    const BodyId rock = w.add_rock(shape, 2700.0, 0, start, rotation, velocity, angular_velocity);
    Throw t;
    const Vec3 v0 = w.state(rock).velocity_m_per_s;
    for (int k = 0; k < 1200; ++k) {
        w.step(1e-3);
        t.steps_with_contact += norm(w.contact_force_N(surface)) > 0.0 ? 1 : 0;
        t.points_per_step.push_back(w.contact_point_count());
    }
    t.states.push_back(w.state(rock));
    t.velocity_change = w.state(rock).velocity_m_per_s - v0 - s.gravity_m_per_s2 * 1.2;
    return t;
}

}  // namespace

TEST_CASE("a rock passed over while apart from a fixed mesh or plane meets it on the same step as on one thread", "[rigid][rocks][threads][unit]")
{
    // On two threads a rock whose manifold with a fixed plane or triangle mesh is empty is passed over while its
    // odometer grows less than its gap to the surface (the plane: its lowest point; the mesh: the nearest
    // triangle's box), dispatcher.cpp. One thread runs Bullet's own dispatch, which processes every pair every
    // step. Had the bound let the rock skip a step on which Bullet adds a point, the runs would part: the test
    // asks for the same bits of position, rotation and velocity after 1.2 s, and for the same number of steps
    // with contact, and for the same number of manifold points at every step: a point Bullet adds at the contact
    // breaking distance presses only later, so a late one would not move the rock at once. A rock dropped from
    // rest without spin closes the gap as fast as its odometer grows, 1.6 mm a step at most, so a gap measured
    // 1 mm too large is caught (checked for both surfaces); elongated rocks (1.8-2) spinning at up to 20 rad/s
    // make the rotation part of the bound count.
    for (bool mesh : {true, false})
        for (bool spin : {false, true})
            for (std::uint64_t seed = 1; seed <= 4; ++seed) {
                CAPTURE(mesh, spin, seed);
                const Throw one = throw_at_surface(seed, mesh, spin, 1);
                const Throw two = throw_at_surface(seed, mesh, spin, 2);
                CHECK(norm(one.velocity_change) > 0.5);  // the surface stopped or turned the rock
                CHECK(one.steps_with_contact > 5);
                CHECK(two.steps_with_contact == one.steps_with_contact);
                CHECK(two.points_per_step == one.points_per_step);  // every point, even those not yet pressing
                const BodyState& a = one.states[0];
                const BodyState& b = two.states[0];
                CHECK(same_bits(a.position_m, b.position_m));
                CHECK(same_bits(a.velocity_m_per_s, b.velocity_m_per_s));
                CHECK(same_bits(a.angular_velocity_rad_per_s, b.angular_velocity_rad_per_s));
                bool rotation_same = true;
                for (int i = 0; i < 3; ++i)
                    for (int j = 0; j < 3; ++j) rotation_same = rotation_same && a.rotation.m[i][j] == b.rotation.m[i][j];
                CHECK(rotation_same);
            }
}
