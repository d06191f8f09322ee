// A settled bed: static loads, rest, determinism, and contact history across neighbour-list rebuilds.
#include "dem/insertion.h"
#include "dem/world.h"
#include "helpers.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

namespace {

/// Ore spheres (r 0.1 m; 3000 kg is about 200) dropped into a square box: ground floor, frictionless steel sides
/// (Table 2's "DE-remaining" mu 0), so the floor alone carries the weight.
World make_box_bed(int threads, double side_m = 1.0, double mass_kg = 3000.0)
{
    WorldSettings s;
    s.threads = threads;
    World w(MaterialTable::aitik_copper_ore(), s);
    const auto& m = w.materials();
    w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, m.index_of("ground"), "floor");
    w.add_plane({0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, m.index_of("steel"), "x0");
    w.add_plane({side_m, 0.0, 0.0}, {-1.0, 0.0, 0.0}, m.index_of("steel"), "x1");
    w.add_plane({0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, m.index_of("steel"), "y0");
    w.add_plane({0.0, side_m, 0.0}, {0.0, -1.0, 0.0}, m.index_of("steel"), "y1");
    fill_random(w, BoxRegion({0.0, 0.0, 0.0}, {side_m, side_m, 3.0}), {{{0.1, 1.0}}}, m.index_of("ore"), mass_kg, 11);
    return w;
}

}  // namespace

TEST_CASE("settled bed: floor force equals total weight and motion dies out", "[dem][analytic]")
{
    World w = make_box_bed(1, 0.7, 1200.0);
    REQUIRE(w.particles().size() > 70);
    const double weight = w.total_mass_kg() * 9.81;
    const double released_J = weight * 1.0;  // the bed's centre of mass falls about 1 m
    while (w.time_s() < 3.0) w.step();
    // Static equilibrium: the floor carries sum m g. 0.5 % is the bound; at rest the residual is
    // far smaller (the frictionless sides carry no vertical load at all).
    CHECK(-w.wall_force_N(0).z == Approx(weight).epsilon(5e-3));
    CHECK(std::abs(w.wall_force_N(1).z) < 1e-9 * weight);
    // Translational motion dies out: below 1e-6 of the energy released. (A sphere resting on one contact
    // may keep spinning about that contact's normal: twisting is not resisted, see docs/limits.md.)
    double translational_J = 0.0;
    for (std::size_t i = 0; i < w.particles().size(); ++i)
        translational_J += 0.5 * w.particles().mass_kg[i] * norm_squared(w.particles().velocity_m_per_s[i]);
    CHECK(translational_J < 1e-6 * released_J);
}

TEST_CASE("results are bitwise repeatable for a given thread count, in single steps or runs of steps", "[dem][unit]")
{
    // Each thread owns a fixed block of pairs and its own force arrays, added in thread order: for one
    // thread count the sums are always formed in the same order. Across thread counts they differ by
    // round-off only.
    // run_steps fuses a step's second half kick with the next step's first half kick and drift; it
    // performs the same operations in the same order, so it must give the same bits as single steps,
    // rebuilds within a call included.
    for (int threads : {1, 2}) {
        World a = make_box_bed(threads), b = make_box_bed(threads), c = make_box_bed(threads);
        for (int k = 0; k < 3000; ++k) {
            a.step();
            b.step();
        }
        c.run_steps(1000);
        c.run_steps(1);
        c.run_steps(1999);
        CAPTURE(threads);
        CHECK(a.rebuild_count() > 2);
        CHECK(c.step_count() == 3000);
        CHECK(c.rebuild_count() == a.rebuild_count());
        CHECK(test::state_hash(a) == test::state_hash(b));
        CHECK(test::state_hash(a) == test::state_hash(c));
    }
}

TEST_CASE("a wall's reaction is the sum of its contacts, on one thread and on two", "[dem][unit]")
{
    // Each thread sums its share of every wall's reaction in the wall phase and the shares are added in
    // thread order. Summed again here from the step's contact records (forces on the particles, negated),
    // the totals agree to round-off: 1e-9 of the wall's weight-scale force. A share lost or counted twice
    // would be off by a whole thread's part (about half the floor's load on two threads).
    for (int threads : {1, 2}) {
        World w = make_box_bed(threads, 0.7, 1200.0);
        w.prepare();
        w.run_steps(static_cast<std::uint64_t>(1.5 / w.step_s()));  // landed on the floor, against the four sides
        std::vector<Vec3> force(5, Vec3{});
        for (const ContactRecord& c : w.last_contact_records())
            force[static_cast<std::size_t>(c.surface_id)] -= c.normal_world * c.normal_force_N + c.tangential_force_N;
        const double weight = w.total_mass_kg() * 9.81;
        CAPTURE(threads);
        CHECK(-w.wall_force_N(0).z > 0.5 * weight);  // the floor carries the bed
        for (int k = 0; k < 5; ++k) {
            CAPTURE(k);
            CHECK(norm(w.wall_force_N(k) - force[static_cast<std::size_t>(k)]) < 1e-9 * weight);
        }
    }
}

TEST_CASE("contact history survives neighbour-list rebuilds", "[dem][unit]")
{
    // Settle, then run 200 steps twice: once as is, once rebuilding (and re-sorting) every step. With the
    // tangential and rolling springs carried over, the two differ by round-off only (summation order):
    // 1e-10 m. Lost springs would let the bed creep by Ft/Kt, about 1e-6 m.
    World a = make_box_bed(1);
    while (a.time_s() < 0.6) a.step();
    World b = a;
    const std::uint64_t rebuilds_before = b.rebuild_count();
    for (int k = 0; k < 200; ++k) {
        a.step();
        b.request_rebuild();
        b.step();
    }
    double worst = 0.0;
    for (std::uint32_t id = 0; id < a.particles().size(); ++id) {
        const std::size_t ia = test::index_of_id(a, id), ib = test::index_of_id(b, id);
        worst = std::max(worst, norm(a.particles().position_m[ia] - b.particles().position_m[ib]));
    }
    CHECK(b.rebuild_count() == rebuilds_before + 200);
    CHECK(worst < 1e-10);
    // and the springs are the same ones, by particle id
    const auto pa = a.pair_contacts(), pb = b.pair_contacts();
    REQUIRE(pa.size() == pb.size());
    REQUIRE(pa.size() > 100);
    double spring_difference = 0.0, spring_size = 0.0;
    for (std::size_t k = 0; k < pa.size(); ++k) {
        REQUIRE(pa[k].id_a == pb[k].id_a);
        REQUIRE(pa[k].id_b == pb[k].id_b);
        spring_difference = std::max(spring_difference, norm(pa[k].history.tangential_spring_m - pb[k].history.tangential_spring_m));
        spring_size = std::max(spring_size, norm(pa[k].history.tangential_spring_m));
    }
    CHECK(spring_size > 1e-8);
    CHECK(spring_difference < 1e-6 * spring_size);
}

TEST_CASE("a particle thrown far away does not break the neighbour grid", "[dem][unit]")
{
    // one sphere 1e9 m from the others: the grid coarsens instead of allocating (or overflowing) cells
    WorldSettings s;
    s.gravity_m_per_s2 = {};
    World w(MaterialTable::aitik_copper_ore(), s);
    w.add_particle({{0, 0, 0}, {}, {}, 0.1, 0});
    w.add_particle({{0.25, 0, 0}, {-1, 0, 0}, {}, 0.1, 0});
    w.add_particle({{1e9, 1e9, 1e9}, {}, {}, 0.1, 0});
    w.run_steps(2000);
    CHECK(w.rebuild_count() >= 1);
    CHECK(w.particles().velocity_m_per_s[test::index_of_id(w, 0)].x < -0.1);  // the pair still collided
}

TEST_CASE("every sphere-rock pair is computed at every step: two threads give one thread's bits", "[dem][unit]")
{
    // 64 spheres dropped from staggered heights onto one convex slab, too far apart to touch each other. Each
    // sphere's force is then the sum of its own pairs' pushes, added in the same order on any thread count, so
    // one thread and two give the same bits although two threads share the pairs' contacts out by their cost
    // (re-weighed at each rebuild) and each thread sums the slab's reaction over its own particles' pairs. A pair
    // that no thread computed would keep last step's contact and push: the spheres' state would part.
    auto run = [](int threads) {
        WorldSettings s;
        s.threads = threads;
        World w(MaterialTable::aitik_copper_ore(), s);
        const auto& m = w.materials();
        w.add_mesh(meshes::make_box_mesh({-1.0, -1.0, -1.0}, {3.4, 3.4, 0.0}), m.index_of("ground"), "slab");
        for (int i = 0; i < 8; ++i)
            for (int j = 0; j < 8; ++j)
                w.add_particle({{0.15 + 0.3 * i, 0.15 + 0.3 * j, 0.1 + 0.02 * ((3 * i + 5 * j) % 8)}, {}, {}, 0.1, m.index_of("ore")});
        w.prepare();
        std::size_t most = 0, fewest = 64;
        while (w.time_s() < 0.6) {
            w.step();
            most = std::max(most, w.wall_contact_count());
            if (w.time_s() > 0.05) fewest = std::min(fewest, w.wall_contact_count());
        }
        CAPTURE(threads);
        CHECK(w.rebuild_count() > 2);
        // the spheres land and bounce at different times: the pairs touching, and so the threads' shares, change
        CHECK(most == 64);
        CHECK(fewest < 60);
        CHECK(w.pair_contact_count() == 0);
        // the slab's reaction, summed by the threads over their own particles' pairs, is the sum of its contacts
        Vec3 force{};
        for (const ContactRecord& c : w.last_contact_records()) force -= c.normal_world * c.normal_force_N + c.tangential_force_N;
        CHECK(norm(w.wall_force_N(0) - force) < 1e-9 * w.total_mass_kg() * 9.81);
        CHECK(norm(force) > 0.0);
        return test::state_hash(w);
    };
    CHECK(run(1) == run(2));
}
