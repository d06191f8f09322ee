// The contact law as a pure function: closed forms and shared properties.
#include "dem/contact_law.h"
#include "helpers.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

namespace {
ContactState head_on(double overlap_m, double approach_speed_m_per_s, double kn = 1e6, double mass = 2.0)
{
    ContactState c;
    c.overlap_m = overlap_m;
    c.normal = {0.0, 0.0, 1.0};
    c.relative_velocity_m_per_s = {0.0, 0.0, -approach_speed_m_per_s};
    c.effective_radius_m = 0.05;
    c.effective_mass_kg = mass;
    c.normal_stiffness_N_per_m = kn;
    return c;
}
}  // namespace

TEST_CASE("normal stiffness follows thesis eqs. 4 and 5", "[dem][analytic]")
{
    // Table 2 ore: E 45 GPa, nu 0.3 -> k = 45e9 / (3 * 0.4) = 37.5 GPa; r 0.1 m, C 0.05
    const Material ore{"ore", 3700.0, 45e9, 0.3, false};
    REQUIRE(ore.bulk_modulus_Pa() == Approx(37.5e9).epsilon(1e-15));
    // equal spheres: k r k r / (2 k r) C = k r C / 2
    CHECK(pair_normal_stiffness(37.5e9, 0.1, 37.5e9, 0.1, 0.05) == Approx(37.5e9 * 0.1 * 0.05 / 2.0).epsilon(1e-15));
    // unequal: 0.1 m and 0.3 m
    CHECK(pair_normal_stiffness(37.5e9, 0.1, 37.5e9, 0.3, 0.05) ==
          Approx(37.5e9 * 0.1 * 37.5e9 * 0.3 / (37.5e9 * 0.4) * 0.05).epsilon(1e-15));
    // wall = the limit r2 -> infinity
    CHECK(pair_normal_stiffness(37.5e9, 0.1, 37.5e9, 1e12, 0.05) ==
          Approx(wall_normal_stiffness(37.5e9, 0.1, 0.05)).epsilon(1e-12));
}

TEST_CASE("normal force is spring plus dashpot and never attractive", "[dem][analytic]")
{
    const PairCoefficients p = test::coefficients(0.5, 0.0, 0.3, 0.3);
    ContactHistory h;
    // approaching at 0.1 m/s with overlap 1e-4 m: Fn = K d + D 2 sqrt(m K) v
    const auto f = linear_spring_dashpot(head_on(1e-4, 0.1), p, h, 1e-5);
    CHECK(f.normal_force_N == Approx(1e6 * 1e-4 + 0.3 * 2.0 * std::sqrt(2.0 * 1e6) * 0.1).epsilon(1e-14));
    // separating fast: the dashpot would pull; the force is clamped to zero
    ContactHistory h2;
    const auto g = linear_spring_dashpot(head_on(1e-4, -10.0), p, h2, 1e-5);
    CHECK(g.normal_force_N == 0.0);
    CHECK(norm(g.tangential_force_N) == 0.0);
}

TEST_CASE("tangential spring accumulates, then Coulomb caps it", "[dem][analytic]")
{
    const PairCoefficients p = test::coefficients(0.5, 0.0, 0.0, 0.0, 1.0, 0.27);
    ContactState c = head_on(1e-4, 0.0);
    c.relative_velocity_m_per_s = {1e-3, 0.0, 0.0};  // sliding along x at 1 mm/s
    ContactHistory h;
    const double dt = 1e-4;
    // elastic: Ft = -Kt xi, xi = v dt per step
    auto f = linear_spring_dashpot(c, p, h, dt);
    CHECK(f.tangential_force_N.x == Approx(-0.27 * 1e6 * 1e-3 * dt).epsilon(1e-14));
    for (int k = 0; k < 10000; ++k) f = linear_spring_dashpot(c, p, h, dt);
    // after 1 mm of sliding the cap mu Fn = 0.5 * 100 N holds, and the spring stores no more than that
    CHECK(f.tangential_force_N.x == Approx(-0.5 * 100.0).epsilon(1e-14));
    CHECK(norm(h.tangential_spring_m) * 0.27 * 1e6 == Approx(50.0).epsilon(1e-14));
}

TEST_CASE("rolling torque is a spring capped at mu_roll R Fn (thesis eq. 8)", "[dem][analytic]")
{
    const PairCoefficients p = test::coefficients(0.5, 0.1, 0.0, 0.0);
    ContactState c = head_on(1e-4, 0.0);
    c.relative_angular_velocity_rad_per_s = {0.0, 2.0, 0.0};
    ContactHistory h;
    const double kr = rolling_stiffness(1e6, 0.1, 0.05);
    auto f = linear_spring_dashpot(c, p, h, 1e-5);
    CHECK(f.rolling_torque_N_m.y == Approx(-kr * 2.0 * 1e-5).epsilon(1e-14));
    for (int k = 0; k < 100000; ++k) f = linear_spring_dashpot(c, p, h, 1e-5);
    CHECK(f.rolling_torque_N_m.y == Approx(-0.1 * 0.05 * 100.0).epsilon(1e-14));
    // twisting about the normal is not resisted
    ContactState twist = c;
    twist.relative_angular_velocity_rad_per_s = {0.0, 0.0, 5.0};
    ContactHistory h2;
    CHECK(norm(linear_spring_dashpot(twist, p, h2, 1e-5).rolling_torque_N_m) == 0.0);
}

TEST_CASE("law properties: zero force without overlap motion, symmetry of a swapped pair", "[dem][unit]")
{
    const PairCoefficients p = test::coefficients(0.6, 0.05, 0.5, 0.5);
    ContactHistory h;
    const auto zero = linear_spring_dashpot(head_on(0.0, 0.0), p, h, 1e-5);
    CHECK(zero.normal_force_N == 0.0);
    CHECK(norm(zero.tangential_force_N) == 0.0);
    CHECK(norm(zero.rolling_torque_N_m) == 0.0);

    // the same contact seen from the other body: normal and relative motion reversed
    ContactState a = head_on(2e-4, 0.3);
    a.relative_velocity_m_per_s += Vec3{0.2, -0.1, 0.0};
    a.relative_angular_velocity_rad_per_s = {1.0, 2.0, 0.5};
    ContactState b = a;
    b.normal = -a.normal;
    b.relative_velocity_m_per_s = -a.relative_velocity_m_per_s;
    b.relative_angular_velocity_rad_per_s = -a.relative_angular_velocity_rad_per_s;
    ContactHistory ha, hb;
    for (int k = 0; k < 50; ++k) {
        const auto fa = linear_spring_dashpot(a, p, ha, 1e-5);
        const auto fb = linear_spring_dashpot(b, p, hb, 1e-5);
        CHECK(fa.normal_force_N == fb.normal_force_N);
        CHECK(fa.tangential_force_N == -fb.tangential_force_N);
        CHECK(fa.rolling_torque_N_m == -fb.rolling_torque_N_m);
    }
}

TEST_CASE("history springs are carried into the new tangent plane with their length", "[dem][unit]")
{
    // small turns use a series for the length correction, large ones the closed form: both must give a
    // vector in the plane with the old length (1e-14 relative), for turns from 1e-6 rad to 80 degrees
    const Vec3 spring{3e-4, -1e-4, 0.0};
    for (double angle : {1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.4}) {
        const Vec3 n = normalized(Vec3{std::sin(angle), 0.3 * std::sin(angle), std::cos(angle)});
        const Vec3 turned = rotate_into_tangent_plane(spring, n);
        CAPTURE(angle);
        CHECK(std::abs(dot(turned, n)) < 1e-14 * norm(spring));
        CHECK(norm(turned) == Approx(norm(spring)).epsilon(1e-14));
    }
    CHECK(norm(rotate_into_tangent_plane(Vec3{0, 0, 1e-4}, Vec3{0, 0, 1})) == 0.0);  // along the normal: nothing left
    CHECK(norm(rotate_into_tangent_plane(Vec3{}, Vec3{0, 0, 1})) == 0.0);
}
