// Frozen particles (World::set_frozen, what coupling::DynamicDomain decides): the pair pass leaves out the pairs of
// two frozen particles and takes them up again as soon as one is let go.
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

#include <memory>

using namespace dipper;
using namespace dipper::dem;

namespace {

/// Two spheres of 0.1 m overlapping by 5 mm, no gravity, the step fixed.
std::unique_ptr<World> pressed_pair()
{
    const MaterialTable table = test::two_material_table(test::coefficients(0.5, 0.0, 0.3, 0.3, 0.05, 0.27), 2500.0, 1e9, 0.25);
    WorldSettings s;
    s.gravity_m_per_s2 = {0.0, 0.0, 0.0};
    s.step_s = 1e-5;
    s.initial_overlap_tolerance = 0.1;
    auto w = std::make_unique<World>(table, s);
    w->add_particle({{0.0, 0.0, 0.0}, {}, {}, 0.1, 0});
    w->add_particle({{0.195, 0.0, 0.0}, {}, {}, 0.1, 0});
    return w;
}

}  // namespace

TEST_CASE("two frozen spheres are passed over, and the pair pushes again at the first step after one is let go", "[dem][frozen]")
{
    // Reference: only sphere 0 frozen from the start; its pair with sphere 1 touches from step 1 and pushes sphere 1
    // away with both half kicks of the step. The same pair with both frozen stays untouched (no contact, no motion).
    // Let sphere 1 go and its next step pushes it with the second half kick only (its force was cleared when it was
    // frozen, and the first half kick uses the force of the last step): half the reference's speed, to the change of
    // the force over the reference's first drift (about 1e-5 of it, since the drift of 1e-5 s moves it 4e-8 m of a
    // 5 mm overlap; 1e-3 allows for the damping's share). A pass whose list of pairs were not found again after the
    // flag changed would leave sphere 1 at rest. And how long the pair was frozen changes no bit.
    const std::unique_ptr<World> reference_world = pressed_pair(), frozen_world = pressed_pair(), briefly_world = pressed_pair();
    World& reference = *reference_world;
    World& w = *frozen_world;
    World& briefly = *briefly_world;
    reference.set_frozen(0, true);
    reference.step();
    const Vec3 pushed = reference.particles().velocity_m_per_s[1];
    REQUIRE(pushed.x > 0.0);
    REQUIRE(reference.pair_contact_count() == 1);

    for (World* x : {&w, &briefly}) {
        x->set_frozen(0, true);
        x->set_frozen(1, true);
    }
    for (int k = 0; k < 10; ++k) w.step();
    briefly.step();
    CHECK(w.pair_contact_count() == 0);  // never computed while both were frozen
    CHECK(w.particles().position_m[1].x == 0.195);
    CHECK(w.particles().velocity_m_per_s[1].x == 0.0);

    for (World* x : {&w, &briefly}) {
        x->set_frozen(1, false);
        x->step();
    }
    CHECK(w.pair_contact_count() == 1);
    CHECK(w.particles().velocity_m_per_s[1].x == Approx(0.5 * pushed.x).epsilon(1e-3));
    CHECK(w.particles().velocity_m_per_s[1].x == briefly.particles().velocity_m_per_s[1].x);
    CHECK(w.particles().position_m[1].x == briefly.particles().position_m[1].x);
    CHECK(w.particles().position_m[0].x == 0.0);  // still frozen

    // frozen again: the pair is passed over and sphere 1 stays where it was frozen, at rest
    w.set_frozen(1, true);
    const double at = w.particles().position_m[1].x;
    for (int k = 0; k < 5; ++k) w.step();
    CHECK(w.particles().position_m[1].x == at);
    CHECK(w.particles().velocity_m_per_s[1].x == 0.0);
}
