// Walls that open: a wall removed at a chosen time (a gate, a plug) and a mesh whose motion starts and
// stops at chosen times. Checked against free fall and the motion's closed form.
#include "core/state_io.h"
#include "dem/world.h"
#include "helpers.h"
#include "meshes/triangle_mesh.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>

using namespace dipper;
using namespace dipper::dem;

namespace {

World gate_world()
{
    WorldSettings s;
    s.step_s = 2e-5;
    return World(test::two_material_table(test::coefficients(0.5, 0.0, 1.0, 1.0, 0.05, 0.27), 3700.0, 45e9, 0.3), s);
}

}  // namespace

TEST_CASE("a sphere held by a gate rests until the gate is removed, then falls freely", "[dem][walls][unit]")
{
    World w = gate_world();
    w.add_plane({0, 0, -10}, {0, 0, 1}, 1, "floor");
    const int gate = w.add_plane({0, 0, 1}, {0, 0, 1}, 1, "gate");
    const double r = 0.1;
    w.add_particle({{0, 0, 1 + r - 1e-6}, {}, {}, r, 0});
    while (w.time_s() < 0.2) w.step();  // settled: damping 1 (critical) on the gate
    const double z_rest = w.particles().position_m[0].z;
    CHECK(w.wall_force_N(gate).z == Approx(-w.particles().mass_kg[0] * 9.81).epsilon(1e-9));

    // held until t1: no move beyond round-off (it is at rest on the gate)
    const double t1 = 0.3;
    while (w.time_s() < t1 - 1e-12) {
        w.step();
        REQUIRE(std::abs(w.particles().position_m[0].z - z_rest) < 1e-12);
    }
    w.remove_wall(gate);
    CHECK(w.wall_removed(gate));
    const double t_removed = w.time_s();
    while (w.time_s() < t_removed + 0.2) w.step();
    // free fall from rest: z = z_rest - g tau^2 / 2. The step in which the gate goes starts with the half
    // kick of the gate's force, which held the weight, so the fall lags by at most g dt tau (dt = 2e-5 s,
    // tau = 0.2 s: 4e-5 m)
    const double tau = w.time_s() - t_removed;
    CHECK(w.particles().position_m[0].z == Approx(z_rest - 0.5 * 9.81 * tau * tau).margin(9.81 * 2e-5 * tau));
    CHECK(w.particles().velocity_m_per_s[0].z == Approx(-9.81 * tau).margin(9.81 * 2e-5));
    CHECK(w.wall_force_N(gate).z == 0.0);
    CHECK(w.wall_contact_count() == 0);
}

TEST_CASE("a plug removed from under a bed empties the box", "[dem][walls][unit]")
{
    // a 1 m x 1 m box of four planes; a mesh plate at z = 0 is its bottom, the floor 3 m lower
    World w = gate_world();
    w.add_plane({0, 0, -3}, {0, 0, 1}, 1, "floor");
    w.add_plane({0, 0, 0}, {1, 0, 0}, 1, "x0");
    w.add_plane({1, 0, 0}, {-1, 0, 0}, 1, "x1");
    w.add_plane({0, 0, 0}, {0, 1, 0}, 1, "y0");
    w.add_plane({0, 1, 0}, {0, -1, 0}, 1, "y1");
    const int plug = w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 4, 4), 1, "plug");
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 3; ++k) w.add_particle({{0.125 + 0.25 * i, 0.125 + 0.25 * j, 0.1 + 0.22 * k}, {}, {}, 0.1, 0});
    const auto in_box = [&] {
        std::size_t n = 0;
        for (const Vec3& x : w.particles().position_m) n += x.z > 0.0;
        return n;
    };
    while (w.time_s() < 0.3) w.step();
    CHECK(in_box() == 48);
    w.remove_wall(plug);
    while (w.time_s() < 1.2) w.step();  // 0.9 s: a sphere at rest falls 4 m, more than the 0.6 m bed
    CHECK(in_box() == 0);
    CHECK(w.wall_force_N(plug).z == 0.0);
}

TEST_CASE("a mesh's motion starts and ends at its times and holds its pose outside them", "[dem][walls][unit]")
{
    PrescribedMotion m;
    m.velocity_m_per_s = {1.0, 0.0, 0.0};
    m.angular_velocity_rad_per_s = {0.0, 0.0, 2.0};
    m.pivot_m = {0.5, 0.5, 0.0};
    m.start_s = 0.1;
    m.end_s = 0.3;
    Mat3 r;
    Vec3 t;
    // before the start: the t = 0 pose, at rest
    m.pose(0.05, r, t);
    CHECK(norm(t) == 0.0);
    CHECK(r.m[0][0] == 1.0);
    CHECK(norm(m.pivot_velocity_m_per_s(0.05)) == 0.0);
    CHECK(norm(m.angular_velocity_at(0.05)) == 0.0);
    // while it runs: t counts from the start (0.1 s of motion at 0.2 s)
    m.pose(0.2, r, t);
    CHECK(m.pivot_position_m(0.2).x == Approx(0.6).epsilon(1e-15));
    CHECK(r.m[0][0] == Approx(std::cos(0.2)).epsilon(1e-15));
    CHECK(m.pivot_velocity_m_per_s(0.2).x == 1.0);
    CHECK(m.angular_velocity_at(0.2).z == 2.0);
    // after the end: where it was brought, at rest
    m.pose(0.5, r, t);
    CHECK(m.pivot_position_m(0.5).x == Approx(0.7).epsilon(1e-15));
    CHECK(r.m[0][0] == Approx(std::cos(0.4)).epsilon(1e-15));
    CHECK(norm(m.pivot_velocity_m_per_s(0.5)) == 0.0);

    // in a world: a plate that slides 0.2 m between 0.1 s and 0.3 s
    World w = gate_world();
    PrescribedMotion slide;
    slide.velocity_m_per_s = {1.0, 0.0, 0.0};
    slide.start_s = 0.1;
    slide.end_s = 0.3;
    const int plate = w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 2, 2), 1, "plate", slide);
    w.add_particle({{5, 5, 5}, {}, {}, 0.1, 0});
    while (w.time_s() + 2e-5 < 0.1) w.step();  // the last step ends before the start
    CHECK(w.mesh_wall(plate).translation_m().x == 0.0);
    while (w.time_s() < 0.6) w.step();
    CHECK(w.mesh_wall(plate).translation_m().x == Approx(0.2).epsilon(1e-12));
    PrescribedMotion backwards = slide;
    backwards.end_s = 0.05;
    CHECK_THROWS_WITH(w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 2, 2), 1, "backwards", backwards),
                      Catch::Contains("runs from 0.1 s to 0.05 s"));
}

TEST_CASE("a removed wall stays removed through a checkpoint", "[dem][walls][unit]")
{
    const auto build = [] {
        World w = gate_world();
        w.add_plane({0, 0, 0}, {0, 0, 1}, 1, "floor");
        w.add_plane({0, 0, 1}, {0, 0, 1}, 1, "gate");
        w.add_particle({{0, 0, 1.2}, {}, {}, 0.1, 0});
        return w;
    };
    World a = build();
    while (a.time_s() < 0.05) a.step();
    a.remove_wall(1);
    a.step();
    StateWriter out;
    a.write_state(out);
    const std::string path = (std::filesystem::temp_directory_path() / "dipper_removed_wall.bin").string();
    out.save(path, "test-state 1");
    World b = build();
    StateReader in(path, "test-state 1");
    b.read_state(in);
    CHECK(b.wall_removed(1));
    CHECK_FALSE(b.wall_removed(0));
    for (int k = 0; k < 20000; ++k) a.step(), b.step();
    CHECK(test::state_hash(a) == test::state_hash(b));
    CHECK(a.particles().position_m[0].z < 0.9);  // through where the gate was
}
