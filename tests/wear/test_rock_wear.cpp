// Wear from rock contacts (Bullet): a load of rocks sliding back and forth on the floor of a moving bucket.
// The bucket's total wear must not depend on the step or on the solver's iterations, and must match the
// sliding work that the rocks' own motion implies.
#include "meshes/mesh_builder.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"
#include "wear/wear_surface.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace dipper;
using namespace dipper::rigid;

namespace {

struct RockWearRun {
    double wear_m3 = 0.0;
    double expected_m3 = 0.0;  ///< phi sqrt(1 + mu^2) m g |v_rel| dt summed over the rocks' own motion
    double seconds = 0.0;
};

/// Nine rocks (generated, 300-400 mm, or flat slabs; Table 2 rock-bucket friction 0.53) on the 4 x 4 m floor of an open bucket that
/// swings 0.3 m back and forth at 1 Hz (peak acceleration 11.8 m/s^2 > mu g): the rocks slide on the floor
/// every half cycle and never reach the walls. Bullet sees the bucket as five 50 mm plates; the wear mesh is
/// the bucket's 75 mm surface mesh.
RockWearRun slide_rocks(double step_s, int iterations, bool slabs)
{
    const double mu = kTable2RockFriction.bucket, phi = 1e-12, size = 4.0, height = 0.8, thick = 0.05;
    RigidSettings settings;
    settings.solver_iterations = iterations;
    RigidWorld w(settings);
    w.add_material("rock");
    w.add_material("bucket");
    w.set_pair("rock", "rock", kTable2RockFriction.rock, 0.0);
    w.set_pair("rock", "bucket", mu, 0.0);
    const meshes::TriangleMesh surface = meshes::make_open_box_mesh(size, size, height, 0.075);
    const std::vector<meshes::Plate> plates{
        meshes::box_plate({-thick, -thick, -thick}, {size + thick, size + thick, 0.0}),
        meshes::box_plate({-thick, -thick, 0.0}, {size + thick, 0.0, height}),
        meshes::box_plate({-thick, size, 0.0}, {size + thick, size + thick, height}),
        meshes::box_plate({-thick, 0.0, 0.0}, {0.0, size, height}),
        meshes::box_plate({size, 0.0, 0.0}, {size + thick, size, height})};
    const BodyId bucket = w.add_plates(plates, w.material_index("bucket"), "bucket", true);
    std::vector<BodyId> rocks;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double a = 0.15 + 0.02 * ((i + j) % 3);  // slabs: half sizes a x 0.9 a x 0.5 a, cannot roll
            const ConvexPolyhedron r =
                slabs ? ConvexPolyhedron::from_mesh(meshes::make_box_mesh({-a, -0.9 * a, -0.5 * a}, {a, 0.9 * a, 0.5 * a}))
                      : generate_rock({0.3 + 0.05 * ((i + j) % 3), 1.0, 1.6, 20}, 40 + 3 * i + j);
            rocks.push_back(w.add_rock(r, 2700.0, 0, {1.2 + 0.8 * i, 1.2 + 0.8 * j, 0.3}));
        }

    wear::WearSurface wear("bucket", surface, wear::WearLaw::from_name("force_work", phi, "test"), 0);
    RockWearRun run;
    const double settle = 0.5, duration = 2.5;
    const auto steps = static_cast<long>(std::lround(duration / step_s));
    for (long k = 1; k <= steps; ++k) {
        const double t = k * step_s;
        const double x = t < settle ? 0.0 : 0.3 * std::sin(2.0 * M_PI * (t - settle));
        const double v = t < settle ? 0.0 : 0.3 * 2.0 * M_PI * std::cos(2.0 * M_PI * (t - settle));
        w.set_kinematic_pose(bucket, Mat3::identity(), {x, 0.0, 0.0});
        w.step(step_s);
        if (t <= settle) continue;
        wear.accumulate(w.surface_contacts(bucket, 0, &surface), step_s);
        for (const BodyId r : rocks) {
            const BodyState s = w.state(r);
            const double slip = std::hypot(s.velocity_m_per_s.x - v, s.velocity_m_per_s.y);
            run.expected_m3 += phi * std::sqrt(1.0 + mu * mu) * w.mass_kg(r) * 9.81 * slip * step_s;
        }
    }
    run.wear_m3 = wear.total_volume_m3();
    return run;
}

}  // namespace

TEST_CASE("wear from rock contacts converges with the step and the solver iterations", "[wear][rigid][rocks][unit]")
{
    // The force for wear is Bullet's contact impulse per step with position correction kept out of it
    // (split impulse at every depth: RigidSettings::split_impulse_threshold_m = 0), and the slip is the
    // relative velocity of the contact points after the step. Tolerance 10 % (the issue's) between
    // dt = 1e-3 and 1e-4 s and between 10 and 50 iterations. Measured: within 4 %. (With Bullet's default
    // split-impulse threshold of 40 mm the same load wore 19 % more at dt = 1e-3: position corrections
    // counted as loads.)
    const RockWearRun coarse = slide_rocks(1e-3, 10, false);
    const RockWearRun coarse_50 = slide_rocks(1e-3, 50, false);
    const RockWearRun fine = slide_rocks(1e-4, 10, false);
    const RockWearRun fine_50 = slide_rocks(1e-4, 50, false);
    CHECK(coarse.wear_m3 > 0.0);
    CHECK(fine.wear_m3 == Approx(coarse.wear_m3).epsilon(0.10));
    CHECK(coarse_50.wear_m3 == Approx(coarse.wear_m3).epsilon(0.10));
    CHECK(fine_50.wear_m3 == Approx(fine.wear_m3).epsilon(0.10));
    CHECK(fine_50.wear_m3 == Approx(coarse.wear_m3).epsilon(0.10));
}

TEST_CASE("wear from sliding slabs equals the sliding work phi sqrt(1 + mu^2) m g |v_rel| dt", "[wear][rigid][rocks][unit]")
{
    // Flat slabs cannot roll: each slides flat, so its contact force is m g sqrt(1 + mu^2) while it slips and
    // its contact points move with its centre. Tolerance 5 %; measured +2.9 % (1e-3 s) and +2.1 % (1e-4 s):
    // the slabs also turn a little about the vertical, so their corners slip more than their centres.
    for (const double dt : {1e-3, 1e-4}) {
        CAPTURE(dt);
        const RockWearRun run = slide_rocks(dt, 10, true);
        CHECK(run.wear_m3 == Approx(run.expected_m3).epsilon(0.05));
    }
}

TEST_CASE("a rock landing flat is one impact, with its approach speed", "[wear][rigid][rocks][unit]")
{
    // A 0.4 m cube dropped 0.3 m onto a plate lands on a whole face: Bullet adds the face's contact points
    // over several steps, but that is one impact. The impact-energy law then wears K m v^2 with v the
    // landing speed sqrt(2 g h); the record's speed is the rock's at the start of the landing step, short
    // of it by at most g dt (0.4 % at 1e-3 s): tolerance 1 %.
    const double K = 1e-12, h = 0.3;
    constexpr double step_s = 1e-3;
    RigidWorld w;
    w.add_material("rock");
    w.add_material("steel");
    w.set_pair("rock", "steel", 0.5, 0.0);
    const meshes::TriangleMesh surface = meshes::make_plate_mesh(4.0, 4.0, 16, 16);
    const BodyId floor = w.add_plates({meshes::box_plate({0.0, 0.0, -0.1}, {4.0, 4.0, 0.0})}, 1, "floor", false);
    const ConvexPolyhedron cube = ConvexPolyhedron::from_mesh(meshes::make_box_mesh({-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2}));
    const BodyId rock = w.add_rock(cube, 2700.0, 0, {2.0, 2.0, 0.2 + h});
    wear::WearSurface wear("floor", surface, wear::WearLaw::from_name("impact_energy", K, "test"), 0);
    int impacts = 0;
    for (int k = 0; k < 1500; ++k) {
        w.step(step_s);
        const std::vector<ContactRecord> records = w.surface_contacts(floor, 0, &surface);
        for (const ContactRecord& c : records) impacts += c.first_step;
        wear.accumulate(records, step_s);
    }
    CHECK(impacts == 1);
    const double v = std::sqrt(2.0 * 9.81 * h);
    CHECK(wear.total_volume_m3() == Approx(K * w.mass_kg(rock) * v * v).epsilon(0.02));
}

TEST_CASE("a rock landing across two plates of one part is one impact", "[wear][rigid][rocks][unit]")
{
    // The floor is two plates that meet under the rock's centre: Bullet keeps a manifold per plate, and the
    // rock lands on both in the same step. An impact is the start of contact between a rock and a part, so
    // it is counted once. Kicked upwards at 1 m/s after it has come to rest, it lifts off about 5 cm and lands
    // again: a second impact, two in all (a count keyed by manifold would give one per plate and landing).
    constexpr double step_s = 1e-3;
    RigidWorld w;
    w.add_material("rock");
    w.add_material("steel");
    w.set_pair("rock", "steel", 0.5, 0.0);
    const BodyId floor = w.add_plates({meshes::box_plate({0.0, 0.0, -0.1}, {2.0, 4.0, 0.0}), meshes::box_plate({2.0, 0.0, -0.1}, {4.0, 4.0, 0.0})},
                                      1, "floor", false);
    const ConvexPolyhedron cube = ConvexPolyhedron::from_mesh(meshes::make_box_mesh({-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2}));
    const BodyId rock = w.add_rock(cube, 2700.0, 0, {2.0, 2.0, 0.5});
    int impacts = 0, steps_on_both = 0;
    for (int k = 0; k < 1500; ++k) {
        if (k == 900) w.apply_force(rock, {0.0, 0.0, w.mass_kg(rock) * (9.81 + 1.0 / step_s)}, w.state(rock).position_m);
        w.step(step_s);
        int on_plate[2] = {0, 0};
        for (const ContactRecord& c : w.surface_contacts(floor, 0)) {
            impacts += c.first_step;
            on_plate[c.point_world.x < 2.0 ? 0 : 1] = 1;
        }
        steps_on_both += on_plate[0] && on_plate[1];
    }
    CHECK(steps_on_both > 100);  // it did rest across the joint
    CHECK(impacts == 2);
}
