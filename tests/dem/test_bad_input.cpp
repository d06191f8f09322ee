// Bad input is refused with a message that names the value and where it came from.
#include "core/errors.h"
#include "dem/world.h"
#include "helpers.h"
#include "meshes/mesh_io.h"
#include "meshes/triangle_mesh.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

using namespace dipper;
using namespace dipper::dem;
using Catch::Contains;

TEST_CASE("bad particles are refused by name", "[dem][input][unit]")
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    REQUIRE_THROWS_WITH(w.add_particle({{}, {}, {}, 0.0, 0}, "spawn 3"), Contains("radius_m") && Contains("spawn 3"));
    REQUIRE_THROWS_WITH(w.add_particle({{}, {}, {}, -0.02, 0}, "spawn 4"), Contains("-0.02"));
    REQUIRE_THROWS_WITH(w.add_particle({{0, std::nan(""), 0}, {}, {}, 0.1, 0}), Contains("position_m"));
    REQUIRE_THROWS_WITH(w.add_particle({{}, {}, {}, 0.1, 99}), Contains("material index 99"));
    REQUIRE_THROWS_WITH(w.add_particle({{}, {}, {}, 0.1, w.materials().index_of("ground")}), Contains("surface material"));
    // finite but absurd speeds (a corrupt pile file): at 1e300 m/s the kinetic energy was inf in every output
    REQUIRE_THROWS_WITH(w.add_particle({{}, {1e300, 0, 0}, {}, 0.1, 0}, "sphere 7"),
                        Contains("velocity_m_per_s (1e+300, 0, 0)") && Contains("at most 10000 m/s") && Contains("sphere 7"));
    REQUIRE_THROWS_WITH(w.add_particle({{}, {}, {0, 0, 2e5}, 0.1, 0}), Contains("rim speed of at most 10000 m/s"));
    REQUIRE_NOTHROW(w.add_particle({{}, {1e4, 0, 0}, {0, 0, 1e5}, 0.1, 0}));  // both exactly at the bound
    CHECK(w.particles().size() == 1);
}

TEST_CASE("bad materials and coefficients are refused by name", "[dem][input][unit]")
{
    MaterialTable t;
    REQUIRE_THROWS_WITH(t.add({"rock", 0.0, 45e9, 0.3, false}), Contains("density_kg_per_m3") && Contains("rock"));
    REQUIRE_THROWS_WITH(t.add({"rock", 3700.0, -1.0, 0.3, false}), Contains("youngs_modulus_Pa") && Contains("-1"));
    REQUIRE_THROWS_WITH(t.add({"rock", 3700.0, 45e9, 0.5, false}), Contains("poisson_ratio"));
    t.add({"rock", 3700.0, 45e9, 0.3, false});
    t.add({"plate", 0, 0, 0, true});
    REQUIRE_THROWS_WITH(t.add({"rock", 3700.0, 45e9, 0.3, false}), Contains("defined twice"));
    PairCoefficients c;
    c.friction = -0.1;
    REQUIRE_THROWS_WITH(t.set_pair("rock", "plate", c, "scenario.yaml line 12"),
                        Contains("friction") && Contains("-0.1") && Contains("line 12") && Contains("rock"));
    c = {};
    c.normal_damping_ratio = 1.2;
    REQUIRE_THROWS_WITH(t.set_pair("rock", "rock", c), Contains("normal_damping_ratio") && Contains("1.2"));
    c = {};
    c.tangential_damping_ratio = -0.1;
    REQUIRE_THROWS_WITH(t.set_pair("rock", "rock", c), Contains("tangential_damping_ratio"));
    REQUIRE_THROWS_WITH(t.index_of("granite"), Contains("granite") && Contains("known: rock, plate"));
}

TEST_CASE("a missing pair, a too-large step and initial overlaps are refused at the start", "[dem][input][unit]")
{
    MaterialTable t;
    t.add({"rock", 3700.0, 45e9, 0.3, false});
    t.add({"plate", 0, 0, 0, true});
    t.set_pair("rock", "rock", {});
    {
        World w(t, WorldSettings{});
        w.add_plane({}, {0, 0, 1}, 1, "floor");
        w.add_particle({{0, 0, 1}, {}, {}, 0.1, 0});
        REQUIRE_THROWS_WITH(w.step(), Contains("'rock'-'plate'"));
    }
    {
        WorldSettings s;
        s.step_s = 1e-3;
        World w(t, s);
        w.add_particle({{0, 0, 1}, {}, {}, 0.1, 0});
        const double limit = w.stable_step_limit_s();
        REQUIRE_THROWS_WITH(w.step(), Contains("step_s = 0.001") && Contains("stable limit") && Contains(concat(limit)));
    }
    {
        World w(t, WorldSettings{});
        w.add_particle({{0, 0, 1}, {}, {}, 0.1, 0});
        w.add_particle({{0, 0, 1.15}, {}, {}, 0.1, 0});
        REQUIRE_THROWS_WITH(w.step(), Contains("initial particles 0 and 1 overlap") && Contains("0.5 of the smaller radius"));
    }
    REQUIRE_THROWS_WITH(World(t, [] { WorldSettings s; s.threads = -2; return s; }()), Contains("threads"));
}

TEST_CASE("a diverging run stops with particle, time and a suggested step", "[dem][input][unit]")
{
    // Two spheres fired into each other at 300 m/s: the overlap passes half a radius within a step or two.
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    w.add_particle({{0, 0, 0}, {300, 0, 0}, {}, 0.1, 0});
    w.add_particle({{0.201, 0, 0}, {-300, 0, 0}, {}, 0.1, 0});
    REQUIRE_THROWS_AS(w.run_steps(100), SimulationError);
    World v(MaterialTable::aitik_copper_ore(), WorldSettings{});
    v.add_particle({{0, 0, 0}, {300, 0, 0}, {}, 0.1, 0});
    v.add_particle({{0.201, 0, 0}, {-300, 0, 0}, {}, 0.1, 0});
    REQUIRE_THROWS_WITH(v.run_steps(100), Contains("particles 0 and 1") && Contains("overlap") && Contains("reduce WorldSettings::step_s"));
}

TEST_CASE("a sphere overrun by a fast body names the body's mass and speed", "[dem][input][unit]")
{
    // A 50 kg plate under a resting sphere (0.01 m gap) is put 0.07 m higher at 500 m/s, as a runaway coupled body
    // would be: the overlap is 0.6 of the radius, past the 0.5 limit, in the first step.
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    w.add_particle({{1, 1, 0.11}, {}, {}, 0.1, 0});
    const int plate = w.add_mesh(meshes::make_plate_mesh(2, 2, 2, 2), w.materials().index_of("bucket"), "plate");
    w.prepare();
    w.set_wall_mass_kg(plate, 50.0);
    w.set_mesh_pose(plate, Mat3::identity(), {0, 0, 0.07}, {1, 1, 0.07}, {0, 0, 500}, {});
    REQUIRE_THROWS_WITH(w.step(), Contains("overlaps wall 'plate'") && Contains("the body behind the wall (50 kg) moves at 500 m/s") &&
                                      Contains("CouplingSettings::substeps") && Contains("CouplingSettings::runaway_guard"));
    // an immovable wall (no mass) keeps the message about the step only
    World v(MaterialTable::aitik_copper_ore(), WorldSettings{});
    v.add_particle({{1, 1, 0.11}, {}, {}, 0.1, 0});
    const int fixed = v.add_mesh(meshes::make_plate_mesh(2, 2, 2, 2), v.materials().index_of("bucket"), "fixed");
    v.prepare();
    v.set_mesh_pose(fixed, Mat3::identity(), {0, 0, 0.07}, {1, 1, 0.07}, {0, 0, 500}, {});
    try {
        v.step();
        FAIL("the overlap was not caught");
    } catch (const SimulationError& e) {
        CHECK_THAT(e.what(), Contains("or slow the wall") && !Contains("body behind"));
    }
}

TEST_CASE("missing, corrupt and degenerate mesh files are refused by name", "[meshes][input][unit]")
{
    REQUIRE_THROWS_WITH(meshes::load_triangle_mesh("/nonexistent/bucket.stl"), Contains("/nonexistent/bucket.stl") && Contains("does not exist"));
    const std::string corrupt = (std::filesystem::temp_directory_path() / "dipper_corrupt_mesh_test.obj").string();
    {
        std::ofstream f(corrupt);
        f << "v 0 0 0\nv 1 0 0\nf 1 2 7\n";  // face refers to a missing vertex
    }
    REQUIRE_THROWS_WITH(meshes::load_triangle_mesh(corrupt), Contains(corrupt));
    const std::string degenerate = (std::filesystem::temp_directory_path() / "dipper_degenerate_mesh_test.obj").string();
    {
        std::ofstream f(degenerate);
        f << "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 4\nf 1 2 3\n";  // the second triangle is a line
    }
    REQUIRE_THROWS_WITH(meshes::load_triangle_mesh(degenerate), Contains(degenerate) && Contains("triangle 1") && Contains("degenerate"));
}

TEST_CASE("walls need plain, unique names and a valid material", "[dem][input][unit]")
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    w.add_plane({}, {0, 0, 1}, 2, "floor");
    REQUIRE_THROWS_WITH(w.add_plane({}, {0, 0, 1}, 2, "floor"), Contains("'floor' is used twice"));
    REQUIRE_THROWS_WITH(w.add_plane({}, {0, 0, 1}, 2, "back wall"), Contains("'back wall'") && Contains("letters, digits"));
    REQUIRE_THROWS_WITH(w.add_plane({}, {0, 0, 0}, 2, "zero"), Contains("normal non-zero"));
    REQUIRE_THROWS_WITH(w.add_plane({}, {0, 0, 1}, 77, "bad_material"), Contains("material index 77"));
    PrescribedMotion runaway;
    runaway.velocity_m_per_s = {std::nan(""), 0, 0};
    REQUIRE_THROWS_WITH(w.add_mesh(meshes::make_plate_mesh(1, 1, 1, 1), 2, "plate", runaway), Contains("'plate'") && Contains("finite"));
}
