// A sphere on an incline: at rest, rolling with rolling resistance, or sliding, as the closed forms say.
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

namespace {

struct InclineResult {
    double acceleration_m_per_s2;  ///< along the slope, fitted between two times after the start-up
    double slip_m_per_s;           ///< contact-point speed along the slope at the end
    double displacement_m;         ///< along the slope over the measured window
};

/// The incline is the floor z = 0 with gravity tilted by theta about y; the sphere starts resting at
/// its static overlap, so the normal force needs no settling.
InclineResult run_incline(double theta_rad, double friction, double rolling,
                          RollingResistance form = RollingResistance::relative_spring)
{
    const double r = 0.1, g = 9.81;
    const PairCoefficients p = test::coefficients(friction, rolling, 1.0, 1.0, 0.05, 0.27);
    MaterialTable table = test::two_material_table(p, 3700.0, 45e9, 0.3);
    table.set_rolling_resistance(form);
    WorldSettings s;
    s.gravity_m_per_s2 = {g * std::sin(theta_rad), 0.0, -g * std::cos(theta_rad)};
    World w(table, s);
    w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "incline");
    const double m = sphere_mass_kg(r, 3700.0);
    const double kn = wall_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, 0.05);
    w.add_particle({{0.0, 0.0, r - m * g * std::cos(theta_rad) / kn}, {}, {}, r, 0});

    const double t1 = 0.2, t2 = 0.6;
    double v1 = 0.0, x1 = 0.0;
    while (w.time_s() < t1) w.step();
    v1 = w.particles().velocity_m_per_s[0].x;
    x1 = w.particles().position_m[0].x;
    const double start = w.time_s();
    while (w.time_s() < t2) w.step();
    const auto& pp = w.particles();
    const double v2 = pp.velocity_m_per_s[0].x;
    // contact point velocity along x: v + (omega x (-r z)).x = v - omega_y r
    const double slip = v2 - pp.angular_velocity_rad_per_s[0].y * r;
    return {(v2 - v1) / (w.time_s() - start), slip, pp.position_m[0].x - x1};
}

}  // namespace

TEST_CASE("sphere on an incline rests while tan(theta) <= mu_roll", "[dem][analytic]")
{
    // tan(theta) = 0.2 < mu_roll = 0.3 (Table 2's ground value): the rolling spring holds the sphere.
    // After the start-up creep the sphere must not move: 1 um over 0.4 s is 2.5 um/s, against the
    // 0.5 m/s it would reach rolling freely.
    const InclineResult got = run_incline(std::atan(0.2), 0.9, 0.3);
    CHECK(std::abs(got.displacement_m) < 1e-6);
    CHECK(std::abs(got.acceleration_m_per_s2) < 1e-5);
}

TEST_CASE("sphere on an incline rolls with a = 5/7 g (sin - mu_roll cos)", "[dem][analytic]")
{
    // theta 20 deg, mu 0.5, mu_roll 0.05: tan(theta) = 0.36 lies in (mu_roll, 3.5 mu - 2.5 mu_roll = 1.625),
    // so the sphere rolls without slipping with the rolling torque at its limit. 0.5 % covers the
    // contact's elastic oscillation still present at t = 0.2 s (damped at 1x critical).
    const double theta = 20.0 * M_PI / 180.0;
    const InclineResult got = run_incline(theta, 0.5, 0.05);
    CHECK(got.acceleration_m_per_s2 == Approx(5.0 / 7.0 * 9.81 * (std::sin(theta) - 0.05 * std::cos(theta))).epsilon(5e-3));
    CHECK(std::abs(got.slip_m_per_s) < 1e-3);
}

TEST_CASE("sphere on an incline rolls with a = 5/7 g sin without rolling resistance", "[dem][analytic]")
{
    const double theta = 20.0 * M_PI / 180.0;
    const InclineResult got = run_incline(theta, 0.5, 0.0);
    CHECK(got.acceleration_m_per_s2 == Approx(5.0 / 7.0 * 9.81 * std::sin(theta)).epsilon(5e-3));
}

TEST_CASE("sphere on an incline slides with a = g (sin - mu cos) above tan(theta) = 3.5 mu - 2.5 mu_roll", "[dem][analytic]")
{
    // theta 30 deg, mu 0.1, mu_roll 0.05: tan 30 = 0.577 > 0.225. The centre's acceleration is set by
    // Coulomb friction alone; the slip grows.
    const double theta = 30.0 * M_PI / 180.0;
    const InclineResult got = run_incline(theta, 0.1, 0.05);
    CHECK(got.acceleration_m_per_s2 == Approx(9.81 * (std::sin(theta) - 0.1 * std::cos(theta))).epsilon(5e-3));
    CHECK(got.slip_m_per_s > 0.5);
}

TEST_CASE("resisting its own spin, a sphere on an incline rests while tan(theta) <= mu_roll and rolls as with the spring above",
          "[dem][analytic]")
{
    // On a fixed surface the sphere's own spin is its rolling on the surface, and the wall's lever R* is r: the
    // two forms give one law. The same bounds as the spring's cases above.
    const InclineResult rest = run_incline(std::atan(0.2), 0.9, 0.3, RollingResistance::own_spin);
    CHECK(std::abs(rest.displacement_m) < 1e-6);
    CHECK(std::abs(rest.acceleration_m_per_s2) < 1e-5);
    const double theta = 20.0 * M_PI / 180.0;
    const InclineResult rolls = run_incline(theta, 0.5, 0.05, RollingResistance::own_spin);
    CHECK(rolls.acceleration_m_per_s2 == Approx(5.0 / 7.0 * 9.81 * (std::sin(theta) - 0.05 * std::cos(theta))).epsilon(5e-3));
    CHECK(std::abs(rolls.slip_m_per_s) < 1e-3);
}
