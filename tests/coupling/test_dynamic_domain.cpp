// The dynamic domain (coupling/dynamic_domain.h): bodies at rest away from moving things are frozen, and let go
// before anything moving reaches them.
#include "core/errors.h"
#include "coupled_scene.h"
#include "coupling/dynamic_domain.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace dipper;
using namespace dipper::test;

namespace {

/// A square bed of 200 mm spheres, two layers on the ground (x, y in [0, 0.2 n)), with a rock on it if asked; `carry`
/// as dem::WorldSettings::carry_wall_candidates.
std::unique_ptr<CoupledScene> bed(int n, bool rock, bool carry = true)
{
    dem::WorldSettings ds;
    ds.carry_wall_candidates = carry;
    rigid::RigidSettings rs;
    rs.gravity_m_per_s2 = ds.gravity_m_per_s2;
    auto s = std::make_unique<CoupledScene>(dem::MaterialTable::aitik_copper_ore(), ds, rs, 5);
    const auto ground = s->dem.materials().index_of("ground");
    s->dem.add_plane({0, 0, 0}, {0, 0, 1}, ground, "ground");
    s->rigid.add_ground_plane(0.0, s->rigid.material_index("ground"), "ground");
    for (int layer = 0; layer < 2; ++layer)  // the second in the hollows of the first
        for (int i = 0; i < n - layer; ++i)
            for (int j = 0; j < n - layer; ++j)
                add_sphere(s->dem, {0.1 + 0.2 * i + 0.1 * layer, 0.1 + 0.2 * j + 0.1 * layer, 0.1 + 0.1415 * layer});
    if (rock)
        s->world.add_rock(cube(0.3), 2700.0, s->rigid.material_index("rock"), s->dem.materials().index_of("rock"),
                          {0.2 * n - 0.4, 0.2 * n - 0.4, 0.5});
    return s;
}

/// Coupling steps, each followed by the domain's update, for `seconds` of simulated time.
void run_for(CoupledScene& s, coupling::DynamicDomain& d, double seconds)
{
    const double end = s.world.time_s() + seconds;
    while (s.world.time_s() < end) {
        s.world.step();
        d.update(s.world, s.world.coupling_step_s());
    }
}

}  // namespace

TEST_CASE("a bed at rest freezes whole, stays where it is, and still weighs on the ground", "[coupling][dynamic_domain]")
{
    auto s = bed(8, true);
    coupling::DynamicDomain d({true, 0.5, 0.01, 0.2});
    // the bed and the rock settle (the rock lands at about 0.3 s) and rest for 0.2 s
    run_for(*s, d, 1.5);
    const dem::ParticleStore& p = s->dem.particles();
    REQUIRE(d.frozen_spheres() == p.size());
    REQUIRE(d.frozen_rocks() == 1);
    CHECK(s->dem.frozen_count() == p.size());
    CHECK(s->rigid.frozen(s->world.rocks()[0].body));
    const std::vector<Vec3> x = p.position_m;
    const Vec3 rock_x = s->rigid.state(s->world.rocks()[0].body).position_m;
    const Vec3 ground_before = s->dem.wall_force_N(0);
    run_for(*s, d, 0.1);
    // frozen: not one bit moves, and the ground's reaction from the spheres' contacts (still found at every step)
    // is the same bits
    CHECK(p.position_m == x);
    CHECK(s->rigid.state(s->world.rocks()[0].body).position_m == rock_x);
    CHECK(s->rigid.state(s->world.rocks()[0].body).velocity_m_per_s == Vec3{});
    CHECK(s->dem.wall_force_N(0) == ground_before);
    // what the ground carries is the spheres' weight and the rock's, which the spheres pass on: within 1 % of the sum.
    // A bed frozen while its contacts still ring keeps their forces of that instant: a contact of stiffness k
    // between masses m that rings at speed v is off by about v sqrt(k m). At rest at 0.05 m/s over 0.1 s (within 5 mm
    // of one point), this bed's sum was off by 4.0 % (714 N of 17,896 N); at 0.02 m/s over 0.1 s by 6e-5, at 0.01 m/s
    // over 0.2 s (the default) by 2e-8.
    double weight = 0.0;
    for (double m : p.mass_kg) weight += 9.81 * m;
    const double rock_weight = 9.81 * s->rigid.mass_kg(s->world.rocks()[0].body);
    INFO("rock at " << rock_x.x << " " << rock_x.y << " " << rock_x.z << ", Bullet ground " << s->rigid.contact_force_N(0).z);
    CHECK(std::abs(ground_before.z + weight + rock_weight) < 0.01 * (weight + rock_weight));
    CHECK(s->dem.kinetic_energy_J() == 0.0);
    CHECK(s->rigid.kinetic_energy_J() == 0.0);
}

TEST_CASE("a sphere thrown at a frozen bed lets go what it comes near, and only that", "[coupling][dynamic_domain]")
{
    auto s = bed(20, false);  // 4 m square
    const double margin = 0.5;
    coupling::DynamicDomain d({true, margin, 0.05, 0.1});
    run_for(*s, d, 0.5);
    REQUIRE(d.frozen_spheres() == s->dem.particles().size());
    // a sphere thrown down at one corner, from 2 m up at 3 m/s
    add_sphere(s->dem, {0.3, 0.3, 2.0}, {0.0, 0.0, -3.0});
    std::size_t woken = 0, far_woken = 0;
    const double end = s->world.time_s() + 0.8;  // it lands after 0.5 s
    for (int k = 0; s->world.time_s() < end; ++k) {
        s->world.step();
        d.update(s->world, s->world.coupling_step_s());
        if (k % 10 != 0) continue;  // the checks below at every tenth coupling step
        const dem::ParticleStore& p = s->dem.particles();
        // Whatever moves is never closer than the margin less the two radii to a frozen sphere: the grid's cells are
        // margin wide and a frozen sphere has none of its 27 cells holding anything that moved. Moving: faster than
        // ten times the rest speed of late (over the last 10-20 ms).
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (!d.sphere_moving(p.id[i])) continue;
            REQUIRE_FALSE(p.frozen[i]);
            for (std::size_t j = 0; j < p.size(); ++j)
                if (p.frozen[j]) REQUIRE(norm(p.position_m[i] - p.position_m[j]) >= margin - 0.2);
        }
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.frozen[i]) continue;
            ++woken;
            if (p.position_m[i].x > 2.5 && p.position_m[i].y > 2.5) ++far_woken;
        }
    }
    CHECK(woken > 0);       // the impact woke its neighbours
    CHECK(far_woken == 0);  // the far corner, 3 m away, never felt it
    // and once all is still again, it freezes again
    run_for(*s, d, 1.0);
    CHECK(d.frozen_spheres() == s->dem.particles().size());
}

TEST_CASE("at rest is going nowhere: a slow drift freezes, a creep neither freezes nor keeps others from freezing",
          "[coupling][dynamic_domain]")
{
    // Spheres in free space (no gravity, no contacts) at constant velocities; rest speed 0.01 m/s over 0.2 s, so at
    // rest within 2 mm of one point for 0.2 s, moving above 0.1 m/s over the last 10-20 ms; margin 0.5 m.
    auto s = make_scene(5, {0.0, 0.0, 0.0});
    const std::uint32_t drift = add_sphere(s->dem, {0.0, 0.0, 0.0}, {0.005, 0.0, 0.0});  // 1 mm in 0.2 s: at rest
    const std::uint32_t creep = add_sphere(s->dem, {3.0, 0.0, 0.0}, {0.03, 0.0, 0.0});   // 6 mm in 0.2 s: never at
                                                                                          // rest, never moving
    const std::uint32_t by_creep = add_sphere(s->dem, {3.0, 0.3, 0.0});                   // at rest 0.3 m from it
    const std::uint32_t fast = add_sphere(s->dem, {-3.3, 0.4, 0.0}, {0.0, 1.0, 0.0});    // 1 m/s, 0.3 m past:
    const std::uint32_t by_fast = add_sphere(s->dem, {-3.0, 0.6, 0.0});                   // at rest beside its path
    const dem::ParticleStore& p = s->dem.particles();
    auto at = [&](std::uint32_t id) {  // the store's order changes at rebuilds; ids stay
        return static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), id) - p.id.begin());
    };
    coupling::DynamicDomain d({true, 0.5, 0.01, 0.2});
    run_for(*s, d, 0.3);  // longer than the 0.2 s to come to rest, less than the creeper takes to move 0.2 m
    CHECK(p.frozen[at(drift)]);  // the drift went nowhere: frozen, held where it was
    CHECK(p.velocity_m_per_s[at(drift)] == Vec3{});
    CHECK_FALSE(p.frozen[at(creep)]);
    CHECK_FALSE(d.sphere_moving(creep));
    CHECK(p.frozen[at(by_creep)]);  // the creeper beside it kept nothing from freezing
    CHECK(d.sphere_moving(fast));
    CHECK_FALSE(p.frozen[at(by_fast)]);  // the moving sphere, within 0.36 m of it throughout, keeps it going
    // the creeper goes on at its speed (not a frozen body's zero)
    CHECK(p.velocity_m_per_s[at(creep)].x == Approx(0.03).epsilon(1e-12));
    run_for(*s, d, 1.0);  // the moving sphere is 1.1 m beyond the other: two cells of the margin
    CHECK(p.frozen[at(by_fast)]);
    CHECK_FALSE(p.frozen[at(creep)]);
}

TEST_CASE("a body set going near its resting point does not freeze with the push in it", "[coupling][dynamic_domain]")
{
    // A sphere in free space sits still for 0.17 s, then is pushed at 0.05 m/s: it stays within the 2 mm reach of
    // its resting point until 0.21 s, so its time there passes the 0.2 s rest time while it moves five times faster
    // than the rest speed at every coupling step. It must not freeze then (frozen, it would lose the push for good);
    // it creeps, and is not moving either (below 0.1 m/s).
    auto s = make_scene(5, {0.0, 0.0, 0.0});
    const std::uint32_t id = add_sphere(s->dem, {0.0, 0.0, 0.0});
    dem::ParticleStore& p = s->dem.particles();
    auto at = [&](std::uint32_t k) { return static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), k) - p.id.begin()); };
    coupling::DynamicDomain d({true, 0.5, 0.01, 0.2});
    run_for(*s, d, 0.17);
    REQUIRE_FALSE(p.frozen[at(id)]);
    p.velocity_m_per_s[at(id)] = {0.05, 0.0, 0.0};
    run_for(*s, d, 0.035);  // to about 0.205 s: past the rest time, 1.75 mm from the resting point
    REQUIRE(std::abs(p.position_m[at(id)].x) < 0.002);
    CHECK_FALSE(p.frozen[at(id)]);
    CHECK_FALSE(d.sphere_moving(id));
    CHECK(p.velocity_m_per_s[at(id)].x == Approx(0.05).epsilon(1e-12));
}

TEST_CASE("a body that rings in place is not moving: what lies beside it freezes", "[coupling][dynamic_domain]")
{
    // A rattler in a rock cage, or a rock under Bullet's sawtooth, goes fast and nowhere. Here a sphere in free space
    // is set each coupling step to a velocity of 0.3 m/s amplitude at 200 Hz (0.24 mm amplitude of its place) on a
    // creep of 0.02 m/s, so that it never comes to rest: over a coupling step it often goes faster than the 0.1 m/s
    // of moving, over the 10-20 ms window at most 0.02 + 2 x 0.24 mm / 10 ms = 0.068 m/s. A sphere 0.3 m from it, at
    // rest, must freeze and stay frozen; with the speed taken over one coupling step it was let go whenever the
    // ringing one was fast.
    auto s = make_scene(5, {0.0, 0.0, 0.0});
    const std::uint32_t ringing = add_sphere(s->dem, {0.0, 0.0, 0.0});
    const std::uint32_t beside = add_sphere(s->dem, {0.0, 0.3, 0.0});
    dem::ParticleStore& p = s->dem.particles();
    auto at = [&](std::uint32_t k) { return static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), k) - p.id.begin()); };
    coupling::DynamicDomain d({true, 0.5, 0.01, 0.2});
    const double amplitude = 0.3, omega = 2.0 * M_PI * 200.0;
    int updates = 0, frozen_beside = 0, fast_steps = 0;
    while (s->world.time_s() < 0.5) {
        const double v = 0.02 + amplitude * std::cos(omega * (s->world.time_s() + 0.5 * s->world.coupling_step_s()));
        p.velocity_m_per_s[at(ringing)] = {v, 0.0, 0.0};
        fast_steps += std::abs(v) > 0.1 ? 1 : 0;
        s->world.step();
        d.update(s->world, s->world.coupling_step_s());
        if (s->world.time_s() > 0.3) {  // past the rest time and a window
            ++updates;
            frozen_beside += p.frozen[at(beside)] ? 1 : 0;
            CHECK_FALSE(d.sphere_moving(ringing));
        }
    }
    REQUIRE(fast_steps > 1000);  // the ringing sphere was faster than moving over a coupling step most of the time
    CHECK(p.position_m[at(ringing)].x == Approx(0.01).margin(5e-4));  // and went no farther than its creep
    CHECK(frozen_beside == updates);
    CHECK_FALSE(p.frozen[at(ringing)]);  // the creep keeps it from freezing itself
}

TEST_CASE("a frozen bed's walls carried over at a rebuild give the bits of a search", "[coupling][dynamic_domain]")
{
    // The same bed twice, one searching every sphere's walls at every rebuild: frozen with its rock, then hit at one
    // corner by a sphere thrown from 2 m, whose fall and landing rebuild the lists every few steps
    auto a = bed(12, true, true), b = bed(12, true, false);
    coupling::DynamicDomain da({true, 0.5, 0.05, 0.1}), db({true, 0.5, 0.05, 0.1});
    run_for(*a, da, 0.5);
    run_for(*b, db, 0.5);
    REQUIRE(da.frozen_spheres() == a->dem.particles().size());
    REQUIRE(da.frozen_rocks() == 1);
    add_sphere(a->dem, {0.3, 0.3, 2.0}, {0.0, 0.0, -3.0});
    add_sphere(b->dem, {0.3, 0.3, 2.0}, {0.0, 0.0, -3.0});
    std::size_t carried = 0, searched_carried = 0;
    const std::uint64_t rebuilds = a->dem.rebuild_count();
    const double end = a->world.time_s() + 0.8;  // it lands after 0.5 s and wakes the corner
    while (a->world.time_s() < end) {
        for (CoupledScene* s : {a.get(), b.get()}) s->world.step();
        da.update(a->world, a->world.coupling_step_s());
        db.update(b->world, b->world.coupling_step_s());
        carried = std::max(carried, a->dem.carried_wall_candidates());
        searched_carried = std::max(searched_carried, b->dem.carried_wall_candidates());
    }
    INFO("rebuilds " << a->dem.rebuild_count() - rebuilds << ", at most " << carried << " spheres carried");
    CHECK(a->dem.rebuild_count() - rebuilds > 10);
    CHECK(carried > a->dem.particles().size() / 2);  // most of the bed stays frozen
    CHECK(searched_carried == 0);
    CHECK(a->dem.particles().position_m == b->dem.particles().position_m);
    CHECK(a->dem.particles().velocity_m_per_s == b->dem.particles().velocity_m_per_s);
    CHECK(a->dem.wall_force_N(0) == b->dem.wall_force_N(0));
    CHECK(a->rigid.state(a->world.rocks()[0].body).position_m == b->rigid.state(b->world.rocks()[0].body).position_m);
    CHECK(da.frozen_spheres() == db.frozen_spheres());
}

TEST_CASE("a frozen rock is let go when a sphere comes near, and is pushed", "[coupling][dynamic_domain]")
{
    auto s = make_scene(5, {0.0, 0.0, 0.0});
    s->world.add_rock(cube(0.4), 2700.0, s->rigid.material_index("rock"), s->dem.materials().index_of("rock"), {0, 0, 0});
    const std::uint32_t far = add_sphere(s->dem, {-5.0, 0.0, 0.0});  // at rest, far away
    coupling::DynamicDomain d({true, 0.5, 0.05, 0.05});
    run_for(*s, d, 0.1);
    const rigid::BodyId rock = s->world.rocks()[0].body;
    REQUIRE(s->rigid.frozen(rock));
    REQUIRE(s->dem.wall_frozen(s->world.body(s->world.index_of(rock)).wall));
    REQUIRE(s->dem.frozen_count() == 1);
    // a sphere at 2 m/s towards the rock
    add_sphere(s->dem, {-2.0, 0.0, 0.0}, {2.0, 0.0, 0.0});
    run_for(*s, d, 1.0);  // 1 s: it reaches the rock after about 0.8 s
    CHECK_FALSE(s->rigid.frozen(rock));
    CHECK(s->rigid.state(rock).velocity_m_per_s.x > 0.01);
    // the sphere at rest 5 m away never moved (the one thrown rests after the blow, at 0.047 m/s under the rest speed, and may freeze too)
    const dem::ParticleStore& p = s->dem.particles();
    CHECK(p.frozen[static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), far) - p.id.begin())]);
    CHECK(p.position_m[static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), far) - p.id.begin())] == Vec3{-5.0, 0.0, 0.0});
}

TEST_CASE("a dynamic domain that freezes nothing changes no bit of a run", "[coupling][dynamic_domain]")
{
    auto a = bed(6, true), b = bed(6, true);
    coupling::DynamicDomain off({false, 0.5, 0.05, 0.1}), late({true, 0.5, 0.05, 1e6});
    run_for(*a, off, 0.3);
    run_for(*b, late, 0.3);
    CHECK(a->dem.particles().position_m == b->dem.particles().position_m);
    CHECK(a->dem.particles().velocity_m_per_s == b->dem.particles().velocity_m_per_s);
    CHECK(a->rigid.state(a->world.rocks()[0].body).position_m == b->rigid.state(b->world.rocks()[0].body).position_m);
}

TEST_CASE("the dynamic domain's settings are checked", "[coupling][dynamic_domain][input]")
{
    CHECK_THROWS_WITH(coupling::DynamicDomain({true, 0.0, 0.05, 0.1}), Catch::Contains("margin_m"));
    CHECK_THROWS_WITH(coupling::DynamicDomain({true, 1.0, -1.0, 0.1}), Catch::Contains("rest_speed_m_per_s"));
    CHECK_THROWS_WITH(coupling::DynamicDomain({true, 1.0, 0.05, NAN}), Catch::Contains("rest_time_s"));
    CHECK_THROWS_WITH(coupling::DynamicDomain({true, 1.0, 0.05, 0.0}), Catch::Contains("rest_time_s"));
}

TEST_CASE("a held sphere and a held rock stay where they are when struck, enabled or not, and through a checkpoint",
          "[coupling][dynamic_domain][held]")
{
    for (const bool enabled : {false, true}) {
        INFO("domain enabled " << enabled);
        auto s = make_scene(5, {0.0, 0.0, 0.0});
        s->world.add_rock(cube(0.4), 2700.0, s->rigid.material_index("rock"), s->dem.materials().index_of("rock"), {0, 0, 0});
        const std::uint32_t held = add_sphere(s->dem, {-1.0, 0.0, 0.0});           // held, in the path of the next
        const std::uint32_t at_it = add_sphere(s->dem, {-2.0, 0.0, 0.0}, {2.0, 0.0, 0.0});  // thrown at it
        const std::uint32_t at_rock = add_sphere(s->dem, {1.0, 0.0, 0.0}, {-2.0, 0.0, 0.0});  // thrown at the rock
        coupling::DynamicDomain d({enabled, 0.5, 0.05, 0.05});
        d.hold(s->world, {0}, {0});
        const rigid::BodyId rock = s->world.rocks()[0].body;
        REQUIRE(d.held_bodies() == 2);
        REQUIRE(s->dem.particles().frozen[0] == 1);
        REQUIRE(s->rigid.frozen(rock));
        const Vec3 rock_x = s->rigid.state(rock).position_m;
        run_for(*s, d, 1.0);  // both blows land after about 0.4 s
        const dem::ParticleStore& p = s->dem.particles();
        // dense indices change at the neighbour rebuilds (the spheres are sorted in space): found by id
        auto at = [&p](std::uint32_t id) { return static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), id) - p.id.begin()); };
        // held: not one bit moved, and the blows came back from them as from fixed bodies
        CHECK(p.position_m[at(held)] == Vec3{-1.0, 0.0, 0.0});
        CHECK(p.frozen[at(held)] == 1);
        CHECK(s->rigid.frozen(rock));
        CHECK(s->rigid.state(rock).position_m == rock_x);
        CHECK(p.velocity_m_per_s[at(at_it)].x < -0.1);
        CHECK(p.velocity_m_per_s[at(at_rock)].x > 0.1);

        // the hold is part of the domain's checkpoint: a domain read back holds them still
        const std::string path = "dipper_held_checkpoint.bin";
        {
            StateWriter out;
            d.write_state(out);
            out.save(path, "dipper-test held 1");
        }
        coupling::DynamicDomain back({enabled, 0.5, 0.05, 0.05});
        StateReader in(path, "dipper-test held 1");
        back.read_state(in);
        in.finish();
        std::remove(path.c_str());
        CHECK(back.held_bodies() == 2);
        // the two thrown spheres still move near them, yet the held stay frozen (the domain, enabled, would let go an
        // ordinary frozen body within its margin of them)
        run_for(*s, back, 0.2);
        CHECK(p.frozen[at(held)] == 1);
        CHECK(s->rigid.frozen(rock));
        CHECK(p.position_m[at(held)] == Vec3{-1.0, 0.0, 0.0});
    }
}

TEST_CASE("hold refuses an index past the bodies there are", "[coupling][dynamic_domain][held][input]")
{
    auto s = make_scene(5, {0.0, 0.0, 0.0});
    add_sphere(s->dem, {0.0, 0.0, 0.0});
    coupling::DynamicDomain d({false, 0.5, 0.05, 0.05});
    CHECK_THROWS_WITH(d.hold(s->world, {1}, {}), Catch::Contains("sphere index 1 of 1"));
    CHECK_THROWS_WITH(d.hold(s->world, {}, {0}), Catch::Contains("rock index 0 of 0"));
}
