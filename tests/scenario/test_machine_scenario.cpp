// Scenarios with the shovel, rocks and wear: their keys and errors, rock fills and rock pairs, rocks that the
// rigid world cannot hold, a rock inside the dipper's steel, rocks carried by a moving wall, the dig cycles.
#include "core/errors.h"
#include "coupling/mixed_bed.h"
#include "meshes/machine_geometry.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/motion_curves.h"
#include "rigid/rope_shovel.h"
#include "scenario/run_limits.h"
#include "scenario/runner.h"
#include "scenario/simulation.h"
#include "scenario/scenario.h"
#include "scenario/helpers.h"
#include "scenario/sweep.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

using namespace dipper;
using namespace dipper::scenario;
namespace fs = std::filesystem;

namespace {

std::string base(const std::string& extra) { return test::machine_scenario(extra); }

std::string error_of(const std::string& text) { return test::scenario_error(text); }

}  // namespace

TEST_CASE("shovel, rock and wear keys: values, defaults and errors that name the key", "[scenario][shovel]")
{
    const Scenario s = parse_scenario(base("shovel: {rake_angle_deg: 59.8, wear_bars: diagonal, start_s: 1.5}\n"
                                           "wear:\n  - {part: dipper, constant: 2.0e-12}\ncoupling: {substeps: 3, runaway_guard: true}\n"),
                                      "case.yaml", ".");
    REQUIRE(s.shovel.has_value());
    CHECK(s.shovel->rake_angle_deg == 59.8);
    CHECK(s.shovel->wear_bars == "diagonal");
    CHECK(s.shovel->start_s == 1.5);
    CHECK(s.shovel->motion == "default_cycle");
    CHECK(s.shovel->bulk_density_kg_per_m3 == 1903.0);
    CHECK(s.coupling.substeps == 3);
    CHECK(s.coupling.runaway_guard);
    CHECK_FALSE(parse_scenario(base(""), "case.yaml", ".").coupling.runaway_guard);  // off unless asked for
    REQUIRE(s.wear.size() == 1);
    CHECK(s.wear[0].law == "force_work");
    CHECK(s.wear[0].smoothing_iterations == 2);
    CHECK(s.uses_coupling());
    CHECK_FALSE(parse_scenario(base(""), "case.yaml", ".").uses_coupling());

    std::string e = error_of(base("shovel: {rake_angel_deg: 60}\n"));
    CHECK_THAT(e, Catch::Contains("unknown key 'shovel.rake_angel_deg'") && Catch::Contains("rake_angle_deg"));
    e = error_of(base("shovel: {rake_angle_deg: 20}\n"));
    CHECK_THAT(e, Catch::Contains("shovel.rake_angle_deg") && Catch::Contains("20"));
    e = error_of(base("shovel: {wear_bars: zigzag}\n"));
    CHECK_THAT(e, Catch::Contains("shovel.wear_bars: got \"zigzag\"; expected baseline, transverse or diagonal"));
    e = error_of(base("shovel: {motion: curves.csv, dig_speed_factor: 1.2}\n"));
    CHECK_THAT(e, Catch::Contains("shovel.dig_speed_factor") && Catch::Contains("built-in cycles only"));
    CHECK(parse_scenario(base("shovel: {motion: dig_and_return, dig_speed_factor: 1.2}\n"), "case.yaml", ".").shovel->motion ==
          "dig_and_return");
    CHECK(parse_scenario(base("shovel: {advance_per_pass_m: 2.5}\n"), "case.yaml", ".").shovel->advance_per_pass_m == 2.5);
    e = error_of(base("shovel: {motion: dig_and_return, advance_per_pass_m: 2}\n"));
    CHECK_THAT(e, Catch::Contains("shovel.advance_per_pass_m: got 2; expected 0 unless shovel.motion is default_cycle"));
    e = error_of(base("shovel: {advance_per_pass_m: -1}\n"));
    CHECK_THAT(e, Catch::Contains("shovel.advance_per_pass_m") && Catch::Contains("-1"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: dipper, constant: 1.0e-12, sections: [{name: front, points_m: [[1, 0, 0]]}]}\n"));
    CHECK_THAT(e, Catch::Contains("wear[0].sections[0].points_m") && Catch::Contains("a list of at least 2 points"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: dipper, constant: 1.0e-12, sections: [{name: a b, points_m: [[1, 0, 0], [1, 1, 0]]}]}\n"));
    CHECK_THAT(e, Catch::Contains("wear[0].sections[0].name: got \"a b\"") && Catch::Contains("it names a file"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: dipper, constant: 1.0e-12, sections: [{name: a, points_m: [[1, 0, 0], [1, 0, 0]]}]}\n"));
    CHECK_THAT(e, Catch::Contains("wear[0].sections[0].points_m: got points 0 and 1 at the same place"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: boom, constant: 1.0e-12}\n"));
    CHECK_THAT(e, Catch::Contains("wear[0].part: got \"boom\"; expected one of the parts: dipper, door"));
    e = error_of(base("wear:\n  - {part: dipper, constant: 1.0e-12}\n"));
    CHECK_THAT(e, Catch::Contains("the scenario has no shovel and no mesh walls"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: dipper, law: hertz, constant: 1.0e-12}\n"));
    CHECK_THAT(e, Catch::Contains("wear[0].law") && Catch::Contains("unknown wear law 'hertz'"));
    e = error_of(base("shovel: {}\nwear:\n  - {part: dipper, constant: 1.0e-12}\n  - {part: dipper, constant: 1.0e-12}\n"));
    CHECK_THAT(e, Catch::Contains("wear[1].part") && Catch::Contains("each part once"));
    // generated parts instead of mesh files, turned and placed
    const Scenario g = parse_scenario(base("meshes:\n  - {name: truck, part: truck_body, material: truck, rotate_deg: [0, 0, 90], "
                                           "translate_m: [0, 20, 0], element_size_m: 0.3}\n"),
                                      "case.yaml", ".");
    REQUIRE(g.meshes.size() == 1);
    const auto world = build_world(g);
    const meshes::TriangleMesh& truck = world->mesh_wall(1).mesh();
    // turned 90 deg about z, the body's x becomes y and its y becomes -x; then moved 20 m along y
    meshes::TruckBodyParameters tp;
    tp.element_size_m = 0.3;
    const meshes::TriangleMesh own = meshes::make_truck_body(tp).surface;
    CHECK(truck.triangle_count() == own.triangle_count());
    CHECK(truck.bounds_min_m().y == Approx(20.0 + own.bounds_min_m().x).margin(1e-9));
    CHECK(truck.bounds_max_m().y == Approx(20.0 + own.bounds_max_m().x).margin(1e-9));
    CHECK(truck.bounds_min_m().x == Approx(-own.bounds_max_m().y).margin(1e-9));
    CHECK(truck.bounds_max_m().z == Approx(own.bounds_max_m().z).margin(1e-9));
    e = error_of(base("meshes:\n  - {name: t, part: truck_body, file: t.stl, material: truck}\n"));
    CHECK_THAT(e, Catch::Contains("meshes[0].part: got both file and part; expected a mesh file or a generated part"));
    e = error_of(base("meshes:\n  - {name: t, material: truck}\n"));
    CHECK_THAT(e, Catch::Contains("meshes[0].file: got neither file nor part"));
    e = error_of(base("meshes:\n  - {name: t, part: crusher, material: truck}\n"));
    CHECK_THAT(e, Catch::Contains("meshes[0].part: got \"crusher\"; expected truck_body, feeder_pan or feeder_bin"));
    e = error_of(base("coupling: {runaway_guard: yes please}\n"));
    CHECK_THAT(e, Catch::Contains("coupling.runaway_guard") && Catch::Contains("yes please") && Catch::Contains("true or false"));
    e = error_of(base("coupling: {substeps: 0}\n"));
    CHECK_THAT(e, Catch::Contains("coupling.substeps: got 0"));

    // mixed fills: one sphere class, fractions summing to 1 with the rocks
    const std::string mixed = "  - mass_kg: 5000\n    box: {min_m: [0, 0, 0], max_m: [3, 3, 3]}\n"
                              "    sizes: [{radius_m: 0.1, mass_fraction: 0.4}]\n"
                              "    rocks: [{size_m: 0.4, mass_fraction: 0.3}, {size_m: 0.6, mass_fraction: 0.3}]\n";
    const Scenario m = parse_scenario(base(mixed), "case.yaml", ".");
    REQUIRE(m.fills.size() == 2);
    CHECK(m.fills[1].rocks.size() == 2);
    CHECK(m.uses_coupling());
    e = error_of(base(std::regex_replace(mixed, std::regex("mass_fraction: 0.4"), "mass_fraction: 0.5")));
    CHECK_THAT(e, Catch::Contains("fills[1].rocks: got mass fractions summing to 1.1") && Catch::Contains("sum to 1"));
    e = error_of(base(std::regex_replace(mixed, std::regex("sizes: \\[\\{radius_m: 0.1, mass_fraction: 0.4\\}\\]"),
                                         "sizes: [{radius_m: 0.1, mass_fraction: 0.2}, {radius_m: 0.08, mass_fraction: 0.2}]")));
    CHECK_THAT(e, Catch::Contains("fills[1].sizes: got 2 sphere classes; expected one sphere class"));
}

TEST_CASE("a fill of rocks alone needs time.step_s, and then runs: the rocks fall and come to rest", "[scenario][shovel]")
{
    // the thesis calibrated its rocks apart from its spheres: a fill whose sphere class holds no mass
    const std::string text = R"(dipper_scenario: 1
name: rocks_alone
threads: 1
time: {duration_s: 3.5}
planes:
  - {name: ground, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
fills:
  - mass_kg: 3000
    box: {min_m: [0, 0, 0.2], max_m: [2, 2, 1.4]}
    sizes: [{radius_m: 0.1, mass_fraction: 0}]
    rocks: [{size_m: 0.4, mass_fraction: 1}]
output: {vtk_interval_s: 0, csv_interval_s: 0.5}
)";
    // no sphere to derive the default step from: said, with the key to set and not a run of zero steps
    CHECK_THAT(error_of(text), Catch::Contains("case.yaml:8:14: fills[0]") && Catch::Contains("rocks but no spheres") &&
                                   Catch::Contains("set time.step_s"));
    const std::string with_step = std::regex_replace(text, std::regex("duration_s: 3.5"), "duration_s: 3.5, step_s: 2.0e-4");
    const Scenario s = parse_scenario(with_step, "case.yaml", ".");
    const fs::path dir = fs::temp_directory_path() / "dipper_rocks_alone";
    fs::remove_all(dir);
    RunOptions o;
    o.progress = false;
    const RunResult r = run_scenario(s, dir.string(), o);
    REQUIRE(r.status == RunStatus::completed);
    CHECK(r.steps == 17500);  // 3.5 s of 2e-4 s steps
    const std::string summary = test::read_text_file((dir / "summary.json").string());
    CHECK_THAT(summary, Catch::Contains("\"particles\": 0") && Catch::Contains("\"step_s\": 0.0002"));
    // 3 t of 400 mm rocks (24 of them) dropped from up to 1.4 m: 6.9 kJ of motion at 0.25 s, at rest by 3 s
    const std::smatch m = [&] {
        std::smatch found;
        std::regex_search(summary, found, std::regex("\"rocks\": ([0-9]+),\n  \"rock_kinetic_energy_J\": ([0-9.e+-]+)"));
        return found;
    }();
    REQUIRE(m.size() == 3);
    CHECK(std::stoi(m[1].str()) == 24);  // 3000 kg / (3700 kg/m3 x pi/6 x 0.4^3 m3) = 24.2
    CHECK(std::stod(m[2].str()) < 5.0);  // under 0.1 % of the motion at 0.25 s (0.001 J at 3.5 s in a run of this scenario)
    fs::remove_all(dir);
}

TEST_CASE("materials.rock_pairs set the rocks' coefficients in Bullet over the preset's, and bad pairs are refused",
          "[scenario][shovel]")
{
    const std::string mixed = "  - mass_kg: 3000\n    box: {min_m: [0, 0, 0], max_m: [3, 3, 3]}\n"
                              "    sizes: [{radius_m: 0.1, mass_fraction: 0.5}]\n    rocks: [{size_m: 0.5, mass_fraction: 0.5}]\n";
    const std::string pairs = "materials:\n  rock_pairs:\n    - {materials: [rock, rock], friction: 1.1}\n"
                              "    - {materials: [ground, rock], friction: 0.3, restitution: 0.2}\n";
    const Scenario s = parse_scenario(base(mixed + pairs), "case.yaml", ".");
    REQUIRE(s.rock_pairs.size() == 2);
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    const rigid::RigidWorld& w = scene.rigid();
    const int rock = w.material_index("rock"), ground = w.material_index("ground"), bucket = w.material_index("bucket");
    CHECK(w.pair_friction(rock, rock) == 1.1);
    CHECK(w.pair_restitution(rock, rock) == 0.0);  // the key's default
    CHECK(w.pair_friction(rock, ground) == 0.3);
    CHECK(w.pair_restitution(ground, rock) == 0.2);
    CHECK(w.pair_friction(rock, bucket) == 0.53);  // not named: Table 2's value stays
    // every rigid material a pair may name is one the scene's rigid world has, and a pair of rocks with it is taken
    for (const std::string& name : rigid_material_names()) {
        CHECK_NOTHROW(w.material_index(name));
        const Scenario one = parse_scenario(base(mixed + "materials:\n  rock_pairs:\n    - {materials: [rock, " + name +
                                                 "], friction: 0.7}\n"),
                                            "case.yaml", ".");
        const auto with = build_co_simulation(one, build_world(one));
        CHECK(with->rigid().pair_friction(with->rigid().material_index("rock"), with->rigid().material_index(name)) == 0.7);
    }

    std::string e = error_of(base(mixed + std::regex_replace(pairs, std::regex("\\[ground, rock\\]"), "[ground, bucket]")));
    CHECK_THAT(e, Catch::Contains("materials.rock_pairs[1].materials: got [ground, bucket]; expected [rock, X]") &&
                      Catch::Contains("one of the rigid materials rock, ground, bucket, truck, steel"));
    e = error_of(base(mixed + std::regex_replace(pairs, std::regex("\\[rock, rock\\]"), "[rock, ore]")));
    CHECK_THAT(e, Catch::Contains("materials.rock_pairs[0].materials: got [rock, ore]"));
    e = error_of(base(mixed + std::regex_replace(pairs, std::regex("friction: 1.1"), "friction: -0.1")));
    CHECK_THAT(e, Catch::Contains("materials.rock_pairs[0].friction") && Catch::Contains("-0.1"));
    e = error_of(base(mixed + std::regex_replace(pairs, std::regex("restitution: 0.2"), "restitution: 1.5")));
    CHECK_THAT(e, Catch::Contains("materials.rock_pairs[1].restitution") && Catch::Contains("1.5"));
    e = error_of(base(mixed + "materials:\n  rock_pairs:\n    - {materials: [rock, rock]}\n"));
    CHECK_THAT(e, Catch::Contains("materials.rock_pairs[0].friction: got nothing"));
}

TEST_CASE("fills[].rock_points sets how many points each rock's hull is drawn from", "[scenario][shovel]")
{
    // A hull of n points has at most n vertices; at the default 20 points a rock keeps 18 on average
    // (docs/rigid.md), so among the 28 rocks of 300 mm (1.5 t) some have more than 10.
    const std::string mixed = "  - mass_kg: 3000\n    box: {min_m: [0, 0, 0], max_m: [3, 3, 3]}\n"
                              "    sizes: [{radius_m: 0.1, mass_fraction: 0.5}]\n    rocks: [{size_m: 0.3, mass_fraction: 0.5}]\n";
    const auto most_vertices = [&](const std::string& extra) {
        const Scenario s = parse_scenario(base(mixed + extra), "case.yaml", ".");
        const auto sim = build_co_simulation(s, build_world(s));
        coupling::CoSimulation& scene = *sim;
        fill_rocks(s, scene);
        REQUIRE(scene.coupled().rocks().size() > 10);
        std::size_t most = 0;
        for (const coupling::RockRecord& r : scene.coupled().rocks()) most = std::max(most, r.shape.vertices_m().size());
        return most;
    };
    CHECK(most_vertices("") > 10);
    CHECK(most_vertices("    rock_points: 8\n") <= 8);
    CHECK_THAT(error_of(base(mixed + "    rock_points: 7\n")),
               Catch::Contains("fills[1].rock_points: got 7; expected a number of points from 8 to 100"));
    CHECK_THAT(error_of(base(mixed + "    rock_points: 12.5\n")), Catch::Contains("fills[1].rock_points") && Catch::Contains("an integer"));
}

TEST_CASE("rocks and walls the rigid world cannot hold are refused with the wall named", "[scenario][shovel]")
{
    const std::string mixed = "  - mass_kg: 3000\n    box: {min_m: [0, 0, 0], max_m: [3, 3, 3]}\n"
                              "    sizes: [{radius_m: 0.1, mass_fraction: 0.5}]\n    rocks: [{size_m: 0.5, mass_fraction: 0.5}]\n";
    const std::string rubber = "materials:\n  add:\n    - {name: rubber, surface: true, density_kg_per_m3: 0, youngs_modulus_Pa: 1.0e7, "
                               "poisson_ratio: 0.45}\n  pairs:\n    - {materials: [ore, rubber], friction: 0.8}\n";
    Scenario t = parse_scenario(base(mixed + rubber), "case.yaml", ".");
    t.planes.push_back({"chute", "rubber", {0, 0, 0}, {1, 0, 0}});
    CHECK_THROWS_WITH(build_co_simulation(t, build_world(t)), Catch::Contains("rocks meet wall 'chute' of material 'rubber'") &&
                                               Catch::Contains("rock, ground, bucket, truck, steel"));
}


namespace {
/// A cube of edge `edge_m` about its centre, as a rock's hull.
rigid::ConvexPolyhedron cube_rock(double edge_m)
{
    std::vector<Vec3> corners;
    for (double x : {-0.5, 0.5})
        for (double y : {-0.5, 0.5})
            for (double z : {-0.5, 0.5}) corners.push_back(Vec3{x, y, z} * edge_m);
    return rigid::ConvexPolyhedron::hull_of(corners, "cube").in_principal_frame();
}
}  // namespace

TEST_CASE("a rock whose centre is inside the dipper's steel stops the run with a diagnosis", "[scenario][shovel]")
{
    const Scenario s = parse_scenario(base("shovel: {element_size_m: 0.3}\n"), "case.yaml", ".");
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    build_particles(s, *dem);
    scene.step();
    CHECK_NOTHROW(scene.check_tunnelling());  // no rocks: nothing to check

    // a 0.3 m cube with its centre 5 cm deep in the bottom plate (0.1 m thick, below the dipper's z = 0)
    const rigid::ConvexPolyhedron cube = cube_rock(0.3);
    Mat3 r;
    Vec3 o;
    scene.rigid().dipper_pose(r, o);
    const Vec3 centre = o + r * Vec3{2.0, 0.0, -0.05};
    scene.coupled().add_rock(cube, 3000.0, scene.rigid().material_index("rock"), dem->materials().index_of("rock"), centre);
    CHECK_THROWS_WITH(scene.check_tunnelling(), Catch::Contains("rock 0 (") && Catch::Contains("inside plate 0 of the dipper") &&
                                                    Catch::Contains("went through the steel") && Catch::Contains("Reduce WorldSettings::step_s") && Catch::Contains("CouplingSettings::substeps (now 5)"));
}

TEST_CASE("among many rocks on two threads, the first rock in order inside the steel is the one named", "[scenario][shovel]")
{
    // 600 rocks (more than the 256 from which the rocks are read on all threads): 597 on the ground far from the
    // machine, and rocks 150, 451 and 599 in the bottom plate. Each thread finds its own; the first of all is named.
    const Scenario s = parse_scenario(std::regex_replace(base("shovel: {element_size_m: 0.3}\n"), std::regex("threads: 1"), "threads: 2"),
                                      "case.yaml", ".");
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    REQUIRE(dem->threads() == 2);
    build_particles(s, *dem);
    scene.step();
    const rigid::ConvexPolyhedron cube = cube_rock(0.3);
    Mat3 r;
    Vec3 o;
    scene.rigid().dipper_pose(r, o);
    for (int k = 0; k < 600; ++k) {
        const bool inside = k == 150 || k == 451 || k == 599;
        const Vec3 centre = inside ? o + r * Vec3{2.0 - 0.001 * k, 0.0, -0.05} : Vec3{-40.0 + 0.5 * (k % 40), 30.0 + 0.5 * (k / 40), 0.2};
        scene.coupled().add_rock(cube, 3000.0, scene.rigid().material_index("rock"), dem->materials().index_of("rock"), centre);
    }
    CHECK_THROWS_WITH(scene.check_tunnelling(), Catch::Contains("rock 150 (") && Catch::Contains("inside plate 0 of the dipper"));
}


TEST_CASE("rocks ride on a moving mesh wall: a rising platform carries them up at its speed", "[scenario][rocks]")
{
    const std::string text = concat(R"(dipper_scenario: 1
threads: 1
seed: 4
time: {duration_s: 1.2}
planes:
  - {name: x0, point_m: [-1, 0, 0], normal: [1, 0, 0],  material: bucket}
  - {name: x1, point_m: [1, 0, 0],  normal: [-1, 0, 0], material: bucket}
  - {name: y0, point_m: [0, -1, 0], normal: [0, 1, 0],  material: bucket}
  - {name: y1, point_m: [0, 1, 0],  normal: [0, -1, 0], material: bucket}
meshes:
  - {name: lift, file: )", DIPPER_SOURCE_DIR, R"(/meshes/generated/ground.stl, material: ground, scale: 0.05,
     motion: {velocity_m_per_s: [0, 0, 0.5]}}
fills:
  - {mass_kg: 500, box: {min_m: [-0.95, -0.95, 0.05], max_m: [0.95, 0.95, 1.2]},
     sizes: [{radius_m: 0.08, mass_fraction: 0.5}], rocks: [{size_m: 0.3, mass_fraction: 0.5}]}
)");
    const Scenario s = parse_scenario(text, "lift.yaml", ".");
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    build_particles(s, *dem);
    fill_rocks(s, scene);
    REQUIRE(scene.coupled().rocks().size() >= 5);
    while (scene.coupled().time_s() < 1.2) scene.step();
    // after 1.2 s the platform's top is at 0.6 m and everything rests on it: every rock above it, and
    // the rocks moving up with it. Tolerance 0.1 m/s on the mean: the bed still settles on the platform
    // (measured below); a rock left behind by the platform would show about -10 m/s by now.
    const double top = 0.5 * scene.coupled().time_s();
    double vz = 0.0;
    for (const coupling::RockRecord& r : scene.coupled().rocks()) {
        const rigid::BodyState st = scene.rigid().state(r.body);
        CHECK(st.position_m.z > top);
        vz += st.velocity_m_per_s.z;
    }
    vz /= static_cast<double>(scene.coupled().rocks().size());
    UNSCOPED_INFO("mean rock vertical velocity " << vz << " m/s");
    CHECK(vz == Approx(0.5).margin(0.1));
}

TEST_CASE("the dig-and-return cycle digs like the default cycle, empties the dipper where the dig ends, and repeats",
          "[scenario][shovel]")
{
    const rigid::ShovelGeometry g;
    const meshes::Dipper dipper = meshes::make_dipper({});
    const rigid::MotionCurves loading = rigid::default_loading_cycle(g, dipper);
    const rigid::MotionCurves wear = rigid::dig_and_return_cycle(g, dipper, 4);
    CHECK(wear.duration_s() == Approx(3 * rigid::kDigAndReturnPass_s + 29.99).epsilon(1e-12));
    for (int k = 0; k < 4; ++k) {
        const double t0 = k * rigid::kDigAndReturnPass_s;
        // the dig: the same hoist and crowd as the default cycle's first dig, every 0.5 s
        for (double t = 0.0; t <= rigid::kBuiltInDig_s; t += 0.5) {
            const rigid::MotionSample a = loading.at(t), b = wear.at(t0 + t);
            CHECK(b.hoist_length_m == Approx(a.hoist_length_m).epsilon(1e-12));
            CHECK(b.crowd_extension_m == Approx(a.crowd_extension_m).epsilon(1e-12));
            CHECK(b.door_deg == 0.0);
        }
        // lowered in front of the bank, the door opens 60 deg without any swing, then shuts before the
        // dipper is back at the toe
        const rigid::ShovelPose dump = rigid::pose_shovel(g, dipper, 20.0, 3.0);
        CHECK(wear.at(t0 + 22.0).door_deg == Approx(60.0));
        CHECK(wear.at(t0 + 22.0).hoist_length_m == Approx(dump.rope_length_m).epsilon(1e-12));
        CHECK(wear.at(t0 + 22.0).crowd_extension_m == Approx(3.0).epsilon(1e-12));
        CHECK(wear.at(t0 + 19.0).door_deg == 0.0);
        CHECK(wear.at(t0 + 25.5).door_deg == 0.0);
        CHECK(wear.at(t0 + 29.5).hoist_length_m == Approx(loading.at(0.0).hoist_length_m).epsilon(1e-12));
        for (double t = 0.0; t < rigid::kDigAndReturnPass_s; t += 0.25) CHECK(wear.at(t0 + t).swing_deg == 0.0);
    }
    CHECK_THROWS_WITH(rigid::dig_and_return_cycle(g, dipper, 0), Catch::Contains("cycles = 0"));
    // a faster dig keeps the pass's other 15 s
    const rigid::MotionCurves fast = coupling::dig_speed_scaled(wear, 1.5, rigid::kDigAndReturnPass_s);
    CHECK(fast.duration_s() == Approx(3 * (15.0 + 10.0) + 29.99 - 15.0 + 10.0).epsilon(1e-12));
}

TEST_CASE("a faster dig shortens each pass's dig and keeps the poses and the rest of the cycle", "[scenario][shovel]")
{
    const rigid::ShovelGeometry g;
    const meshes::Dipper dipper = meshes::make_dipper({});
    const rigid::MotionCurves cycle = rigid::default_loading_cycle(g, dipper);
    const double factor = 1.3;
    const rigid::MotionCurves fast = coupling::dig_speed_scaled(cycle, factor);
    REQUIRE(fast.samples().size() == cycle.samples().size());
    const double pass = 31.0 + 15.0 / factor;
    CHECK(fast.duration_s() == Approx(2.0 * pass + 45.99 - 15.0 + 15.0 / factor).epsilon(1e-12));
    for (std::size_t k = 0; k < cycle.samples().size(); ++k) {
        const rigid::MotionSample& a = cycle.samples()[k];
        const rigid::MotionSample& b = fast.samples()[k];
        // the same poses, in the same order
        CHECK(b.hoist_length_m == a.hoist_length_m);
        CHECK(b.crowd_extension_m == a.crowd_extension_m);
        CHECK(b.swing_deg == a.swing_deg);
        CHECK(b.door_deg == a.door_deg);
        // at new times: inside a dig divided by the factor, after it shifted by what the dig saved
        const double n = std::floor(a.time_s / 46.0 + 1e-9), local = a.time_s - 46.0 * n;
        const double expected = n * pass + (local <= 15.0 ? local / factor : local - 15.0 + 15.0 / factor);
        CHECK(b.time_s == Approx(expected).margin(1e-12));
    }
    // the dig of the second pass runs from 46 s to 61 s in the default cycle, from 42.5 s to 54.1 s here
    const rigid::MotionSample mid_default = cycle.at(46.0 + 7.5), mid_fast = fast.at(pass + 7.5 / factor);
    CHECK(mid_fast.hoist_length_m == Approx(mid_default.hoist_length_m).epsilon(1e-12));
    CHECK(coupling::dig_speed_scaled(cycle, 1.0).samples().size() == cycle.samples().size());
}

TEST_CASE("a cycle that crosses the truck is refused by check and by the run, naming part, wall, time and depth, "
          "a material-only wall gives warnings",
          "[scenario][shovel][machine_path]")
{
    const std::string dir = std::string(DIPPER_SOURCE_DIR) + "/examples/scenarios";
    const std::string shipped = test::read_text_file(dir + "/loading_three_passes.yaml");
    const std::string placed = "translate_m: [-1.6, 19.25, 3.0]";
    REQUIRE(shipped.find(placed) != std::string::npos);
    // the shipped scenario passes, with a warning for each time the dipper reaches over the model's back end
    const std::vector<std::string> warnings = check_scenario(parse_scenario(shipped, "three.yaml", dir));
    REQUIRE(!warnings.empty());
    CHECK_THAT(warnings[0], Catch::Contains("into wall 'back'") && Catch::Contains("material_only"));

    // the truck's body raised 5 m: the dipper swings through its side on every pass
    std::string raised = shipped;
    raised.replace(raised.find(placed), placed.size(), "translate_m: [-1.6, 19.25, 8.0]");
    const Scenario s = parse_scenario(raised, "raised.yaml", dir);
    std::string e;
    try {
        check_scenario(s);
    } catch (const InputError& error) {
        e = error.what();
    }
    CHECK_THAT(e, Catch::Contains("raised.yaml: the shovel's cycle passes through walls that stand for steel"));
    // the dig ends at 15 s and the swing to the truck follows (the times against the multibody: test_machine_path)
    CHECK(std::regex_search(e, std::regex("dipper passes 0\\.[0-9]+ m into wall 'truck' from 2[0-9]\\.[0-9]+ s to [0-9.]+ s")));
    CHECK_THAT(e, Catch::Contains("material_only: true"));
    CHECK_THROWS_WITH(Simulation(s), Catch::Contains("passes through walls that stand for steel"));  // the run, before any particle

    // marked as holding material only, the same crossings are warnings
    std::string marked = raised;
    marked.replace(marked.find("material: truck,"), 16, "material: truck, material_only: true,");
    const std::vector<std::string> w = check_scenario(parse_scenario(marked, "marked.yaml", dir));
    CHECK(std::any_of(w.begin(), w.end(), [](const std::string& x) { return x.find("into wall 'truck'") != std::string::npos; }));
}
