// Energy, momentum and integration order.
#include "dem/insertion.h"
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

#include <random>

using namespace dipper;
using namespace dipper::dem;

TEST_CASE("zero damping: a bouncing sphere keeps its energy over 1e5 steps", "[dem][analytic]")
{
    // Energy = kinetic + gravitational + spring (K d^2 / 2). Velocity Verlet is symplectic while the
    // contact set is fixed; each contact switch falls at a random phase within a step and adds an error of
    // order (omega dt)^2 of the contact energy that does not build up in one direction (measured: a random
    // walk, worst 5.5e-3 of the drop energy at the default step, about 1e-3 at a third of it over the same
    // simulated time). The bounds, 1e-2 and 2e-3, fail for any systematic gain or loss: a first-order
    // integrator loses the whole energy here.
    const double r = 0.1;
    const PairCoefficients p = test::coefficients(0.0, 0.0, 0.0, 0.0, 0.05, 0.27);
    const MaterialTable table = test::two_material_table(p, 3700.0, 45e9, 0.3);
    const double kn = wall_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, 0.05);
    for (int refine : {1, 3}) {
        const double step_factor = kDefaultStepFactor / refine;
        WorldSettings s;
        s.step_s = step_factor * std::sqrt(sphere_mass_kg(r, 3700.0) / kn);
        World w(table, s);
        w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
        w.add_particle({{0.0, 0.0, r + 0.05}, {}, {}, r, 0});
        auto energy = [&] {
            const double overlap = std::max(0.0, r - w.particles().position_m[0].z);
            return w.kinetic_energy_J() + w.gravitational_potential_energy_J() + 0.5 * kn * overlap * overlap;
        };
        const double e0 = energy();
        const double scale = w.particles().mass_kg[0] * 9.81 * 0.05;  // energy of the drop
        double worst = 0.0;
        int bounces = 0;
        bool touching = false;
        for (int step = 0; step < 100000 * refine; ++step) {
            w.step();
            worst = std::max(worst, std::abs(energy() - e0));
            const bool now = w.wall_contact_count() > 0;
            if (now && !touching) ++bounces;
            touching = now;
        }
        CAPTURE(step_factor, bounces);
        CHECK(bounces > 15);
        CHECK(worst / scale < (refine == 1 ? 1e-2 : 2e-3));
    }
}

TEST_CASE("colliding cloud without gravity conserves momentum to round-off", "[dem][analytic]")
{
    // Pair forces are stored once and added to both particles with opposite signs, so linear momentum
    // changes only by round-off: 1e-13 of sum |m v|. The rolling torques are equal and opposite and the
    // tangential forces act at one contact point, so angular momentum about the origin is conserved up to
    // the O(dt^2) mismatch between x(t+dt) x v(t+dt) and the torque integral: 1e-8 of sum |L_i|.
    WorldSettings s;
    s.gravity_m_per_s2 = {};
    World w(MaterialTable::aitik_copper_ore(), s);
    const MaterialIndex ore = w.materials().index_of("ore");
    fill_random(w, BoxRegion({0.0, 0.0, 0.0}, {1.5, 1.5, 1.5}), {{{0.1, 0.5}, {0.07, 0.5}}}, ore, 1500.0, 7);
    std::mt19937_64 random(3);
    std::normal_distribution<double> speed(0.0, 1.0);
    auto& p = w.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3 centre{0.75, 0.75, 0.75};
        p.velocity_m_per_s[i] = (centre - p.position_m[i]) * 2.0 + Vec3{speed(random), speed(random), speed(random)};
        p.angular_velocity_rad_per_s[i] = {speed(random) * 5.0, speed(random) * 5.0, speed(random) * 5.0};
    }
    const Vec3 p0 = w.linear_momentum_kg_m_per_s();
    const Vec3 l0 = w.angular_momentum_kg_m2_per_s();
    double momentum_scale = 0.0, angular_scale = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        momentum_scale += p.mass_kg[i] * norm(p.velocity_m_per_s[i]);
        angular_scale += norm(cross(p.position_m[i], p.velocity_m_per_s[i] * p.mass_kg[i]));
    }
    std::size_t contact_steps = 0;
    for (int step = 0; step < 4000; ++step) {
        w.step();
        contact_steps += w.pair_contact_count();
    }
    CHECK(contact_steps > 2000);
    CHECK(norm(w.linear_momentum_kg_m_per_s() - p0) < 1e-13 * momentum_scale);
    CHECK(norm(w.angular_momentum_kg_m2_per_s() - l0) < 1e-8 * angular_scale);
}

TEST_CASE("free fall is exact with velocity Verlet at any step", "[dem][analytic]")
{
    // Constant acceleration is integrated exactly by velocity Verlet: x = x0 + v0 t + g t^2 / 2 to round-off.
    for (double dt : {1e-3, 1e-4, 1e-5}) {
        WorldSettings s;
        s.step_s = dt;
        s.gravity_m_per_s2 = {0.0, 0.0, -9.81};
        MaterialTable t = test::two_material_table(test::coefficients(0.5, 0.0, 0.5, 0.5), 2500.0, 1e5, 0.25);
        World w(t, s);
        w.add_particle({{0.0, 0.0, 10.0}, {1.0, 0.0, 2.0}, {}, 0.1, 0});
        const int steps = static_cast<int>(std::lround(0.5 / dt));
        w.run_steps(static_cast<std::uint64_t>(steps));
        const double time = steps * dt;
        const Vec3 x = w.particles().position_m[0];
        CHECK(x.z == Approx(10.0 + 2.0 * time - 0.5 * 9.81 * time * time).epsilon(1e-12));
        CHECK(x.x == Approx(time).epsilon(1e-12));
    }
}

TEST_CASE("integration error falls as dt^2", "[dem][analytic]")
{
    // A sphere resting on an undamped spring floor, lifted 40 % of its static overlap and released, stays in
    // contact and oscillates as z = z_eq + A cos(omega0 t). The solution is smooth, so the position error
    // at a fixed time must fall by 4 when the step halves (velocity Verlet is second order): ratios in
    // [3.5, 4.5]. (Contact switches are not smooth; their error shows in the energy test above.)
    const double r = 0.1, g = 9.81;
    const PairCoefficients p = test::coefficients(0.0, 0.0, 0.0, 0.0, 0.05, 0.27);
    const MaterialTable table = test::two_material_table(p, 3700.0, 45e9, 0.3);
    const double kn = wall_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, 0.05);
    const double m = sphere_mass_kg(r, 3700.0);
    const double omega0 = std::sqrt(kn / m);
    const double static_overlap = m * g / kn, lift = 0.4 * static_overlap;
    const double t_end = 7.3 * 2.0 * M_PI / omega0;
    const double exact_z = r - static_overlap + lift * std::cos(omega0 * t_end);
    std::vector<double> errors;
    for (int n : {400, 800, 1600, 3200}) {
        WorldSettings s;
        s.step_s = t_end / n;
        World w(table, s);
        w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
        w.add_particle({{0.0, 0.0, r - static_overlap + lift}, {}, {}, r, 0});
        w.run_steps(static_cast<std::uint64_t>(n));
        REQUIRE(w.wall_contact_count() == 1);
        errors.push_back(std::abs(w.particles().position_m[0].z - exact_z));
    }
    for (std::size_t k = 1; k < errors.size(); ++k) {
        CAPTURE(k, errors[k - 1], errors[k]);
        CHECK(errors[k - 1] / errors[k] > 3.5);
        CHECK(errors[k - 1] / errors[k] < 4.5);
    }
}
