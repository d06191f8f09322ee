// Wear laws against their formulas: Archard, Finnie's angle function, the thesis' force-work model and its
// impact-energy form; how each law reads a contact record.
#include "core/errors.h"
#include "wear/laws.h"

#include <catch2/catch.hpp>

#include <cmath>

using namespace dipper;
using namespace dipper::wear;

namespace {

constexpr double kDeg = M_PI / 180.0;

/// A contact record of a particle moving with velocity v over one step of dt on a surface with normal +z.
ContactRecord moving_contact(const Vec3& v, double dt, double fn, const Vec3& ft, double mass, bool first)
{
    ContactRecord c;
    c.normal_world = {0.0, 0.0, 1.0};
    c.normal_force_N = fn;
    c.tangential_force_N = ft;
    c.relative_displacement_m = v * dt;
    c.particle_mass_kg = mass;
    c.first_step = first;
    c.triangle_id = 0;
    return c;
}

}  // namespace

TEST_CASE("Finnie's angle function: zero at 0 and 90 deg, peak 0.3028 at 16.85 deg, continuous at 18.43 deg",
          "[wear][laws][unit]")
{
    // closed forms for K = 2: f = sin 2a - 3 sin^2 a (tan a <= 1/3), cos^2 a / 3 above
    CHECK(finnie_angle_function(0.0, 2.0) == 0.0);
    CHECK(std::abs(finnie_angle_function(90.0 * kDeg, 2.0)) < 1e-16);

    // the peak: d/da (sin 2a - 3 sin^2 a) = 2 cos 2a - 3 sin 2a = 0, so tan 2a = 2/3, a = 16.845 deg,
    // f = 0.30278. A 1e-4 deg scan finds it to the scan's resolution.
    double best_angle = 0.0, best_value = -1.0;
    for (int k = 0; k <= 900000; ++k) {
        const double a = k * 1e-4 * kDeg;
        const double f = finnie_angle_function(a, 2.0);
        if (f > best_value) { best_value = f; best_angle = a / kDeg; }
    }
    CHECK(best_angle == Approx(0.5 * std::atan(2.0 / 3.0) / kDeg).margin(1e-4));
    CHECK(best_angle == Approx(16.85).margin(0.005));
    CHECK(best_value == Approx(0.3028).margin(5e-5));
    CHECK(best_value == Approx((std::sqrt(13.0) - 3.0) / 2.0).epsilon(1e-9));  // exact maximum (sqrt 13 - 3)/2

    // the branch switch at tan a = K/6: both expressions give 0.3 there; the function is continuous
    const double a_switch = std::atan(1.0 / 3.0);
    CHECK(a_switch / kDeg == Approx(18.4349).margin(1e-4));
    const double below = finnie_angle_function(a_switch * (1.0 - 1e-12), 2.0);
    const double above = finnie_angle_function(a_switch * (1.0 + 1e-12), 2.0);
    CHECK(below == Approx(0.3).epsilon(1e-10));
    CHECK(above == Approx(0.3).epsilon(1e-10));

    // eq. 2.4 from eq. 2.3 with psi = 2, K = 2 and half the grains cutting: M v^2/(8p) f and M v^2/(24p) cos^2
    const double m = 3.0, v = 4.0, p = 1e9;
    CHECK(finnie_volume_m3(m, v, 10.0 * kDeg, p) ==
          Approx(m * v * v / (8.0 * p) * (std::sin(20.0 * kDeg) - 3.0 * std::pow(std::sin(10.0 * kDeg), 2))).epsilon(1e-14));
    CHECK(finnie_volume_m3(m, v, 40.0 * kDeg, p) ==
          Approx(m * v * v / (24.0 * p) * std::pow(std::cos(40.0 * kDeg), 2)).epsilon(1e-14));
}

TEST_CASE("Archard, force-work and impact-energy volumes are their formulas", "[wear][laws][unit]")
{
    CHECK(archard_volume_m3(2e-13, 1500.0, 0.3) == Approx(2e-13 * 1500.0 * 0.3).epsilon(1e-15));
    CHECK(force_work_volume_m3(1e-12, 300.0, 400.0, 0.02) == Approx(1e-12 * 500.0 * 0.02).epsilon(1e-15));
    CHECK(impact_energy_volume_m3(1e-11, 40.0, 3.0) == Approx(1e-11 * 40.0 * 9.0).epsilon(1e-15));
}

TEST_CASE("the thesis' model wears in sliding (0 deg) and in normal impact (90 deg), Finnie's in neither",
          "[wear][laws][unit]")
{
    const double dt = 1e-4, m = 10.0;
    // sliding at 2 m/s along the surface under 800 N with 200 N of friction
    const ContactRecord sliding = moving_contact({2.0, 0.0, 0.0}, dt, 800.0, {-200.0, 0.0, 0.0}, m, true);
    // normal impact at 3 m/s, no friction
    const ContactRecord impact = moving_contact({0.0, 0.0, -3.0}, dt, 5000.0, {}, m, true);

    const WearLaw thesis = WearLaw::from_name("force_work", 1e-12, "test");
    CHECK(thesis.volume_m3(sliding, dt) == Approx(1e-12 * std::hypot(800.0, 200.0) * 2.0 * dt).epsilon(1e-14));
    CHECK(thesis.volume_m3(impact, dt) == Approx(1e-12 * 5000.0 * 3.0 * dt).epsilon(1e-14));
    CHECK(thesis.volume_m3(sliding, dt) > 0.0);
    CHECK(thesis.volume_m3(impact, dt) > 0.0);

    const WearLaw finnie = WearLaw::from_name("finnie", 1e9, "test");
    CHECK(finnie.volume_m3(sliding, dt) == 0.0);
    CHECK(std::abs(finnie.volume_m3(impact, dt)) < 1e-30);
    // at 16.85 deg Finnie's law wears most: M v^2 / (8p) * 0.3028
    const double a = 0.5 * std::atan(2.0 / 3.0);
    const ContactRecord oblique = moving_contact({3.0 * std::cos(a), 0.0, -3.0 * std::sin(a)}, dt, 100.0, {}, m, true);
    CHECK(finnie.volume_m3(oblique, dt) == Approx(m * 9.0 / 8e9 * (std::sqrt(13.0) - 3.0) / 2.0).epsilon(1e-12));

    // Archard uses the sliding (tangential) distance only: nothing for a normal impact
    const WearLaw archard = WearLaw::from_name("archard", 1e-13, "test");
    CHECK(archard.volume_m3(sliding, dt) == Approx(1e-13 * 800.0 * 2.0 * dt).epsilon(1e-14));
    CHECK(archard.volume_m3(impact, dt) == 0.0);
}

TEST_CASE("impact laws count each contact once, on its first step", "[wear][laws][unit]")
{
    const double dt = 1e-4, m = 7.0;
    const WearLaw impact = WearLaw::from_name("impact_energy", 2e-12, "test");
    const ContactRecord first = moving_contact({1.0, 0.0, -2.0}, dt, 10.0, {}, m, true);
    ContactRecord later = first;
    later.first_step = false;
    CHECK(impact.volume_m3(first, dt) == Approx(2e-12 * m * 5.0).epsilon(1e-12));
    CHECK(impact.volume_m3(later, dt) == 0.0);
}

TEST_CASE("wear laws: unknown names and bad constants are errors that list what is valid", "[wear][laws][unit][bad_input]")
{
    CHECK_THROWS_WITH(WearLaw::from_name("archerd", 1e-12, "scenario.yaml: wear.bucket.law"),
                      Catch::Contains("unknown wear law 'archerd'") && Catch::Contains("archard, finnie, force_work, impact_energy") &&
                          Catch::Contains("scenario.yaml: wear.bucket.law"));
    CHECK_THROWS_AS(WearLaw::from_name("archard", -1.0, "test"), InputError);
    CHECK_THROWS_AS(WearLaw::from_name("force_work", std::nan(""), "test"), InputError);
    CHECK_THROWS_AS(WearLaw::from_name("finnie", 0.0, "test"), InputError);
    // scaling keeps the kind and scales the constant (finnie: the flow stress divides)
    CHECK(WearLaw::from_name("archard", 2.0, "t").scaled(3.0).constant == 6.0);
    CHECK(WearLaw::from_name("finnie", 6.0, "t").scaled(3.0).flow_stress_Pa == 2.0);
}
