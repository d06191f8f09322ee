// Normal and oblique impacts against the exact solution of the implemented law.
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

namespace {

struct Measured {
    double restitution = 0.0, duration_s = 0.0, peak_overlap_m = 0.0, peak_force_N = 0.0;
};

/// Drops one sphere (no gravity) on a plane at v0, or two spheres head on at +-v0/2 each, and measures
/// restitution (separation speed / approach speed) and contact duration (first to last touching step,
/// half a step added at each end to centre the estimate).
Measured run_impact(bool sphere_pair, double damping, double steps_per_contact)
{
    const double r = 0.05, v0 = 1.0;
    const PairCoefficients p = test::coefficients(0.0, 0.0, damping, 0.0);
    const MaterialTable table = test::two_material_table(p, 2500.0, 1e9, 0.25);
    const double k = table.material(0).bulk_modulus_Pa();
    const double m = sphere_mass_kg(r, 2500.0);
    const double kn = sphere_pair ? pair_normal_stiffness(k, r, k, r, 1.0) : wall_normal_stiffness(k, r, 1.0);
    const double m_eff = sphere_pair ? 0.5 * m : m;
    const double omega0 = std::sqrt(kn / m_eff);

    WorldSettings s;
    s.gravity_m_per_s2 = {};
    s.step_s = M_PI / omega0 / steps_per_contact;
    World w(table, s);
    if (sphere_pair) {
        w.add_particle({{0.0, 0.0, -r - 1e-4}, {0.0, 0.0, 0.5 * v0}, {}, r, 0});
        w.add_particle({{0.0, 0.0, r + 1e-4}, {0.0, 0.0, -0.5 * v0}, {}, r, 0});
    } else {
        w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
        w.add_particle({{0.0, 0.0, r + 1e-4}, {0.0, 0.0, -v0}, {}, r, 0});
    }
    Measured out;
    int first = -1, last = -1;
    for (int step = 0; step < 20 * static_cast<int>(steps_per_contact); ++step) {
        w.step();
        const std::size_t contacts = sphere_pair ? w.pair_contact_count() : w.wall_contact_count();
        if (contacts > 0) {
            if (first < 0) first = step;
            last = step;
            const auto& x = w.particles().position_m;
            const double overlap = sphere_pair ? 2.0 * r - norm(x[0] - x[1]) : r - x[0].z;
            out.peak_overlap_m = std::max(out.peak_overlap_m, overlap);
            const double force = sphere_pair ? norm(w.particles().force_N[0]) : -w.wall_force_N(0).z;
            out.peak_force_N = std::max(out.peak_force_N, force);
        } else if (first >= 0) {
            break;
        }
    }
    const auto& v = w.particles().velocity_m_per_s;
    const std::size_t lower = test::index_of_id(w, 0), upper = sphere_pair ? test::index_of_id(w, 1) : lower;
    out.restitution = sphere_pair ? (v[upper].z - v[lower].z) / v0 : v[lower].z / v0;
    out.duration_s = (last - first + 1) * s.step_s;
    return out;
}

}  // namespace

TEST_CASE("normal impacts: restitution and duration match the exact clamped solution", "[dem][analytic]")
{
    // 1000 steps per contact: the contact start and end are resolved to 1/1000 of its duration and the
    // mid-step damping velocity is O(dt) off, so 0.5 % on e and t_c leaves room for both and no more:
    // the unclamped law differs by 2 % (D = 0.3) to 600 % (D = 0.9).
    const double r = 0.05, k = 1e9 / (3.0 * (1.0 - 0.5));
    const double m = sphere_mass_kg(r, 2500.0);
    for (bool pair : {false, true}) {
        const double kn = pair ? pair_normal_stiffness(k, r, k, r, 1.0) : wall_normal_stiffness(k, r, 1.0);
        const double omega0 = std::sqrt(kn / (pair ? 0.5 * m : m));
        for (double damping : {0.0, 0.3, 0.6, 0.9}) {
            CAPTURE(pair, damping);
            const test::ClampedImpact exact = test::clamped_impact(damping, omega0);
            const Measured got = run_impact(pair, damping, 1000.0);
            CHECK(got.restitution == Approx(exact.restitution).epsilon(5e-3));
            CHECK(got.duration_s == Approx(exact.duration_s).epsilon(5e-3));
            // the clamp's consequence: restitution above the unclamped exp(-pi D / sqrt(1 - D^2))
            const double unclamped = std::exp(-M_PI * damping / std::sqrt(1.0 - damping * damping));
            if (damping > 0.0) CHECK(got.restitution > unclamped * 1.01);
        }
    }
}

TEST_CASE("undamped impact: peak overlap v0/omega0 and peak force v0 sqrt(K m*)", "[dem][analytic]")
{
    // sampled at 1000 steps per contact the peak is missed by at most 1 - cos(pi/1000): 5e-6; 1e-4 allows
    // for the velocity Verlet phase error
    const double r = 0.05, k = 1e9 / (3.0 * (1.0 - 0.5)), m = sphere_mass_kg(r, 2500.0);
    const double kn = wall_normal_stiffness(k, r, 1.0);
    const Measured got = run_impact(false, 0.0, 1000.0);
    CHECK(got.peak_overlap_m == Approx(1.0 / std::sqrt(kn / m)).epsilon(1e-4));
    CHECK(got.peak_force_N == Approx(std::sqrt(kn * m)).epsilon(1e-4));
    CHECK(got.restitution == Approx(1.0).epsilon(1e-4));
    CHECK(got.duration_s == Approx(M_PI / std::sqrt(kn / m)).epsilon(2e-3));
}

TEST_CASE("oblique impacts of Chung & Ooi (2011) test 4 in the gross-sliding range", "[dem][analytic]")
{
    // alumina sphere R 2.5 mm, 4000 kg/m3, E 380 GPa, nu 0.23, 3.9 m/s, mu 0.092 against a rigid plane.
    // While the contact slides throughout, the impulse ratio is mu: v_t'/v_t = 1 - mu (1 + e) / tan(theta)
    // and omega' = 2.5 mu (1 + e) v cos(theta) / R (theta from the normal, e the normal restitution).
    // While sliding, every step's tangential impulse is exactly mu times the normal one, so the tangential
    // restitution matches to round-off (1e-9). The spin differs by the lever arm: the force acts on the
    // wall surface at r - delta, and delta / r <= 1.1e-3 at 3.9 m/s; 2e-3 covers it. (The issue asks for
    // 2 % on both.)
    const double r = 2.5e-3, v = 3.9, mu = 0.092;
    MaterialTable t;
    t.add({"alumina", 4000.0, 380e9, 0.23, false});
    t.add({"plane", 0.0, 0.0, 0.0, true});
    t.set_pair("alumina", "plane", {1.0, 0.27, mu, 0.0, 0.05, 0.05});
    t.set_pair("alumina", "alumina", {1.0, 0.27, mu, 0.0, 0.05, 0.05});
    const double kn = wall_normal_stiffness(t.material(0).bulk_modulus_Pa(), r, 1.0);
    const double omega0 = std::sqrt(kn / sphere_mass_kg(r, 4000.0));

    for (int angle_deg = 5; angle_deg <= 85; angle_deg += 5) {
        const double theta = angle_deg * M_PI / 180.0;
        WorldSettings s;
        s.gravity_m_per_s2 = {};
        s.step_s = M_PI / omega0 / 500.0;
        World w(t, s);
        w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "plane");
        w.add_particle({{0.0, 0.0, r + 1e-7}, {v * std::sin(theta), 0.0, -v * std::cos(theta)}, {}, r, 0});
        const double energy_before = w.kinetic_energy_J();
        bool touched = false;
        for (int step = 0; step < 100000; ++step) {
            w.step();
            if (w.wall_contact_count() > 0) touched = true;
            else if (touched) break;
        }
        const Vec3 vout = w.particles().velocity_m_per_s[0];
        const Vec3 spin = w.particles().angular_velocity_rad_per_s[0];
        const double e = vout.z / (v * std::cos(theta));
        CAPTURE(angle_deg, e, vout.x, spin.y);
        // energy never increases, at any angle
        CHECK(w.kinetic_energy_J() <= energy_before * (1.0 + 1e-12));
        if (angle_deg >= 35) {
            const double tangential_restitution = vout.x / (v * std::sin(theta));
            CHECK(tangential_restitution == Approx(1.0 - mu * (1.0 + e) / std::tan(theta)).epsilon(1e-9));
            // positive spin about +y is forward rolling for motion along +x on a floor below
            CHECK(spin.y == Approx(2.5 * mu * (1.0 + e) * v * std::cos(theta) / r).epsilon(2e-3));
        }
    }
}

TEST_CASE("equal and opposite spins meeting head on: no tangential force, spins unchanged", "[dem][analytic]")
{
    // Opposite spins about z on spheres approaching along x: the contact surfaces move together
    // (omega1 x r1 = omega2 x r2 at the contact), so the tangential slip and force are exactly zero.
    // Rolling resistance is off: such a contact rolls, and a rolling torque would (rightly) act.
    const PairCoefficients p = test::coefficients(0.5, 0.0, 0.3, 0.3);
    WorldSettings s;
    s.gravity_m_per_s2 = {};
    s.step_s = 1e-6;
    World w(test::two_material_table(p), s);
    const double r = 0.05;
    w.add_particle({{-r - 1e-4, 0.0, 0.0}, {0.5, 0.0, 0.0}, {0.0, 0.0, 20.0}, r, 0});
    w.add_particle({{r + 1e-4, 0.0, 0.0}, {-0.5, 0.0, 0.0}, {0.0, 0.0, -20.0}, r, 0});
    bool touched = false;
    for (int step = 0; step < 200000; ++step) {
        w.step();
        if (w.pair_contact_count() > 0) touched = true;
        else if (touched) break;
    }
    REQUIRE(touched);
    const auto& pp = w.particles();
    for (std::uint32_t id = 0; id < 2; ++id) {
        const std::size_t i = test::index_of_id(w, id);
        CHECK(pp.angular_velocity_rad_per_s[i].z == Approx(id == 0 ? 20.0 : -20.0).epsilon(1e-12));
        CHECK(pp.velocity_m_per_s[i].y == 0.0);
        CHECK(pp.velocity_m_per_s[i].z == 0.0);
    }
    CHECK(pp.velocity_m_per_s[test::index_of_id(w, 0)].x < 0.0);  // they did bounce
}

TEST_CASE("a sphere against a huge, heavy sphere behaves as against a wall", "[dem][analytic]")
{
    // One law serves both: with r2 = 1e4 m and m2 -> 1e15 kg, Kn, m* and R* differ from the wall values
    // by r1 / r2 = 1e-5 at most, so an oblique, spinning impact must end the same within 1e-4.
    const double r = 0.05, big = 1e4;
    const PairCoefficients p = test::coefficients(0.4, 0.1, 0.5, 0.5);
    MaterialTable table = test::two_material_table(p, 2500.0, 1e9, 0.25);
    table.add({"anvil", 2500.0, 1e9, 0.25, false});
    table.set_pair("p", "anvil", p);
    table.set_pair("anvil", "anvil", p);
    WorldSettings s;
    s.gravity_m_per_s2 = {};
    World on_wall(table, s), on_sphere(table, s);
    const ParticleSpawn ball{{0.0, 0.0, r + 1e-4}, {0.7, 0.2, -1.0}, {3.0, -2.0, 1.0}, r, 0};
    on_wall.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "wall");
    on_wall.add_particle(ball);
    on_sphere.add_particle(ball);
    on_sphere.add_particle({{0.0, 0.0, -big}, {}, {}, big, 2});
    for (int k = 0; k < 4000; ++k) {
        on_wall.step();
        on_sphere.step();
    }
    const std::size_t a = test::index_of_id(on_wall, 0), b = test::index_of_id(on_sphere, 0);
    const Vec3 va = on_wall.particles().velocity_m_per_s[a], vb = on_sphere.particles().velocity_m_per_s[b];
    const Vec3 wa = on_wall.particles().angular_velocity_rad_per_s[a], wb = on_sphere.particles().angular_velocity_rad_per_s[b];
    REQUIRE(va.z > 0.1);  // it bounced
    CHECK(norm(va - vb) < 1e-4 * norm(va));
    CHECK(norm(wa - wb) < 1e-4 * norm(wa));
}
