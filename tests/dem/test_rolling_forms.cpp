// The two forms of rolling resistance (eq. 8): the spring on a pair's relative rolling, and the resistance of each
// sphere's own spin. On a fixed surface the two are one law; they part where two spheres spin together.
#include "dem/contact_law.h"
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

TEST_CASE("the torque against a sphere's own spin has the contacts' sum and never turns the spin round", "[dem][unit]")
{
    const Vec3 omega{0.0, 2.0, 0.0}, other{0.0, 0.0, 0.0};
    const double step_per_inertia = 1e-3;  // dt / I
    // resistance 100 N m over the step changes the spin by 0.1 rad/s, less than its 2 rad/s: all of it acts
    const Vec3 some = spin_resisting_torque(omega, other, 100.0, step_per_inertia);
    CHECK(some.x == 0.0);
    CHECK(some.y == Approx(-100.0).epsilon(1e-15));
    CHECK(some.z == 0.0);
    // resistance 1e4 N m would change it by 10 rad/s: only what stops the spin acts, and the step ends at rest
    const Vec3 other_torque{0.0, 500.0, 0.0};  // the spin the step would leave without it: 2.5 rad/s
    const Vec3 most = spin_resisting_torque(omega, other_torque, 1e4, step_per_inertia);
    CHECK(most.y == Approx(-2500.0).epsilon(1e-15));
    CHECK(omega.y + (other_torque.y + most.y) * step_per_inertia == Approx(0.0).margin(1e-15));
    // no spin, or no contact: nothing
    CHECK(norm(spin_resisting_torque({}, {}, 100.0, step_per_inertia)) == 0.0);
    CHECK(norm(spin_resisting_torque(omega, other, 0.0, step_per_inertia)) == 0.0);
}

namespace {

/// Sphere A resting on top of sphere B, B on the ground, gravity along -z; A and B spin together about y at
/// 2 rad/s, as two gear wheels would not: at their contact the surfaces slide past each other at 2 r omega. The
/// pair A-B has no sliding friction (so nothing but rolling resistance couples the spins) and mu_roll 0.1; B on
/// the ground has neither. Returns both spins after `seconds`.
std::pair<double, double> spins_after(RollingResistance form, double seconds)
{
    const double r = 0.1, g = 9.81, density = 3700.0;
    MaterialTable table;
    table.add({"p", density, 45e9, 0.3, false});
    table.add({"ground", 0.0, 0.0, 0.0, true});
    table.set_pair("p", "p", test::coefficients(0.0, 0.1, 1.0, 1.0, 0.05, 0.27));
    table.set_pair("p", "ground", test::coefficients(0.0, 0.0, 1.0, 1.0, 0.05, 0.27));
    table.set_rolling_resistance(form);
    WorldSettings s;
    s.gravity_m_per_s2 = {0.0, 0.0, -g};
    World w(table, s);
    w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "ground");
    // both at their static overlaps: B carries A's weight and its own on the ground, A its own on B
    const double m = sphere_mass_kg(r, density);
    const double k_wall = wall_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, 0.05);
    const double k_pair = pair_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, table.material(0).bulk_modulus_Pa(), r, 0.05);
    const double zb = r - 2.0 * m * g / k_wall, za = zb + 2.0 * r - m * g / k_pair;
    const Vec3 spin{0.0, 2.0, 0.0};
    w.add_particle({{0.0, 0.0, zb}, {}, spin, r, 0});
    w.add_particle({{0.0, 0.0, za}, {}, spin, r, 0});
    while (w.time_s() < seconds) w.step();
    const auto& p = w.particles();
    const std::size_t a = p.id[0] == 1 ? 0 : 1, b = 1 - a;
    return {p.angular_velocity_rad_per_s[a].y, p.angular_velocity_rad_per_s[b].y};
}

}  // namespace

TEST_CASE("two spheres spinning together: the relative spring lets them spin, their own spins are slowed at mu_roll r m g / I",
          "[dem][analytic]")
{
    const double r = 0.1, g = 9.81, mu_roll = 0.1;
    // own spin: each sphere's spin falls at mu_roll r Fn / I = mu_roll r m g / (0.4 m r^2) = 2.5 mu_roll g / r (Fn = A's
    // weight; B feels no rolling resistance on the frictionless ground), 24.5 rad/s^2: from 2 rad/s to rest in
    // 0.0815 s. At 0.04 s it is 2 - 0.981 = 1.019 rad/s. The static overlaps leave the contact force within 1e-6
    // of the weight; 0.2 % covers the step's rounding of the time (5e-5 s steps of a 2 rad/s spin).
    const double rate = 2.5 * mu_roll * g / r;
    const auto [a_half, b_half] = spins_after(RollingResistance::own_spin, 0.04);
    CHECK(a_half == Approx(2.0 - rate * 0.04).epsilon(2e-3));
    CHECK(b_half == Approx(2.0 - rate * 0.04).epsilon(2e-3));
    // after 0.2 s both are at rest, exactly: the resistance stops a spin and does not turn it round
    const auto [a_end, b_end] = spins_after(RollingResistance::own_spin, 0.2);
    CHECK(a_end == 0.0);
    CHECK(b_end == 0.0);
    // the relative spring sees no relative rolling: the spins stay as they were, to round-off
    const auto [a_spring, b_spring] = spins_after(RollingResistance::relative_spring, 0.2);
    CHECK(a_spring == Approx(2.0).epsilon(1e-9));
    CHECK(b_spring == Approx(2.0).epsilon(1e-9));
}
