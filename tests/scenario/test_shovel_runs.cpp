// The shovel's runs against statics and their records: the material held in the dipper weighs on dipper and
// door with its weight; the mass in the dipper and the fill factor count exactly that material; the lip's force is
// told from the rest; piles loaded where the shovel stands; a pass is recorded when the door opens; sweeps and
// measured wear of shovel runs.
#include "core/errors.h"
#include "coupling/mixed_bed.h"
#include "meshes/machine_geometry.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/motion_curves.h"
#include "rigid/rope_shovel.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/simulation.h"
#include "scenario/helpers.h"
#include "scenario/sweep.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

using namespace dipper;
using namespace dipper::scenario;
namespace fs = std::filesystem;

namespace {

std::string base(const std::string& extra) { return test::machine_scenario(extra); }

/// A scenario whose shovel holds the dig-end pose (handle level, crowd 7.5 m), writing its motion file into
/// `dir`: the door opens from door_open_s to 30 deg in 0.3 s (never if door_open_s <= 0). 2.5 t of `material`
/// (a fill's sizes and rocks) fill a box 1.8 m across in the middle of the inside, in world coordinates (the
/// dipper is tilted, so the box is kept well inside its 4 x 4 x 3 m).
std::string held_in_dipper(const std::string& dir, double duration_s, double door_open_s, const std::string& material)
{
    const rigid::ShovelPose pose = rigid::pose_shovel(rigid::ShovelGeometry{}, meshes::make_dipper({}), 0.0, 7.5);
    std::vector<rigid::MotionSample> samples{{0.0, pose.rope_length_m, 7.5, 0.0, 0.0}};
    if (door_open_s > 0.0) {
        samples.push_back({door_open_s, pose.rope_length_m, 7.5, 0.0, 0.0});
        samples.push_back({door_open_s + 0.3, pose.rope_length_m, 7.5, 0.0, 30.0});
    } else {
        samples.push_back({duration_s, pose.rope_length_m, 7.5, 0.0, 0.0});
    }
    fs::create_directories(dir);
    rigid::MotionCurves::from_samples(samples, "held").write_csv(dir + "/held.csv");
    const Vec3 middle = pose.dipper_origin_m + pose.dipper_rotation * Vec3{2.0, 0.0, 1.5};
    const Vec3 lo = middle - Vec3{0.9, 0.9, 0.9}, hi = middle + Vec3{0.9, 0.9, 0.9};
    return concat(R"(dipper_scenario: 1
threads: 1
time: {duration_s: )", duration_s, R"(}
planes:
  - {name: ground, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
fills:
  - {mass_kg: 2500, box: {min_m: [)", lo.x, ", ", lo.y, ", ", lo.z, "], max_m: [", hi.x, ", ", hi.y, ", ", hi.z, "]},\n     ",
                  material, R"(}
shovel: {motion: held.csv, element_size_m: 0.3}
)");
}

}  // namespace

TEST_CASE("a saved pile loaded where the shovel stands leaves out the spheres the dipper and door would cut",
          "[scenario][shovel]")
{
    // a lattice of 150 mm spheres 0.5 m apart through the space the dipper takes at the start of the default
    // cycle (x 13-17.5 m, |y| < 2.1 m, z 0.1-3.8 m), as a pile built without the machine would hold
    const fs::path dir = fs::temp_directory_path() / "dipper_pile_at_shovel";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::size_t n = 0;
    std::ostringstream spheres;
    for (double x = 12.0; x < 18.6; x += 0.5)
        for (double y = -2.5; y < 2.6; y += 0.5)
            for (double z = 0.3; z < 4.4; z += 0.5, ++n) spheres << x << ' ' << y << ' ' << z << " 0 0 0 0 0 0 0.15 ore\n";
    {
        std::ofstream pile(dir / "pile.txt");
        pile << "dipper-state 1\nspheres " << n << "\n" << spheres.str() << "rocks 0\nend\n";
    }
    const Scenario s = parse_scenario(R"(dipper_scenario: 1
threads: 1
time: {duration_s: 0.002}
planes:
  - {name: ground, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
pile: pile.txt
shovel: {element_size_m: 0.3}
output: {vtk_interval_s: 0}
)", "pile_at_shovel.yaml", dir.string());

    // loaded whole, spheres sit deep in the steel: the first step stops on the overlap
    {
        const auto sim = build_co_simulation(s, build_world(s));
        coupling::CoSimulation& scene = *sim;
        const coupling::LoadedState all = coupling::load_state(scene.coupled(), s.pile);
        REQUIRE(all.spheres == n);
        CHECK_THROWS_WITH(scene.step(), Catch::Contains("overlaps wall"));
    }
    // loaded as a run loads it, those spheres stay out and the first step finds no contact at all (the
    // ground is 0.15 m below the lowest sphere)
    std::size_t left_out = 0;
    {
        const auto sim = build_co_simulation(s, build_world(s));
        coupling::CoSimulation& scene = *sim;
        dem::World* const dem = &scene.dem();
        const coupling::LoadedState kept =
            coupling::load_state(scene.coupled(), s.pile, [&scene](const Vec3& c, double r) { return scene.clear_of_machine(c, r); });
        left_out = kept.spheres_left_out;
        CHECK(kept.spheres + kept.spheres_left_out == n);
        CHECK(left_out > 20);       // the dipper's plates pass through the lattice
        CHECK(kept.spheres > n / 2);  // most of it is clear of the steel, inside the dipper or around it
        CHECK(dem->particles().size() == kept.spheres);
        scene.step();
        CHECK(dem->wall_contact_count() == 0);
    }
    // a run says what it left out
    RunOptions o;
    o.progress = false;
    REQUIRE(run_scenario(s, (dir / "out").string(), o).status == RunStatus::completed);
    CHECK_THAT(test::read_text_file((dir / "out" / "summary.json").string()),
               Catch::Contains(concat("\"pile\": {\"spheres\": ", n - left_out, ", \"rocks\": 0, \"spheres_left_out\": ", left_out,
                                      ", \"rocks_left_out\": 0, \"held\": 0}")));
    fs::remove_all(dir);
}

TEST_CASE("a mixed fill where the shovel stands keeps its spheres and rocks clear of the dipper and door", "[scenario][shovel]")
{
    // the box holds the space the dipper takes at the start of the default cycle (x 13-17.5 m, |y| < 2.1 m,
    // z 0.1-3.8 m), as a quick loading scenario's fill does
    const Scenario s = parse_scenario(R"(dipper_scenario: 1
threads: 1
time: {duration_s: 0.002}
planes:
  - {name: ground, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
fills:
  - mass_kg: 30000
    box: {min_m: [12, -2.5, 0], max_m: [18.5, 2.5, 4.4]}
    sizes: [{radius_m: 0.15, mass_fraction: 0.5}]
    rocks: [{size_m: 0.6, mass_fraction: 0.5}]
shovel: {element_size_m: 0.3}
output: {vtk_interval_s: 0}
)", "mixed_at_shovel.yaml", ".");
    auto bound = [](const coupling::RockRecord& r) {
        double radius = 0.0;
        for (const Vec3& v : r.shape.vertices_m()) radius = std::max(radius, norm(v));
        return radius;
    };
    // how many bodies of a fill the dipper's or door's surface passes within reach of
    auto count_in_steel = [&](const coupling::CoSimulation& scene, const dem::World& dem) {
        std::size_t n = 0;
        for (std::size_t i = 0; i < dem.particles().size(); ++i)
            n += !scene.clear_of_machine(dem.particles().position_m[i], dem.particles().radius_m[i]);
        for (const coupling::RockRecord& r : scene.coupled().rocks())
            n += !scene.clear_of_machine(scene.coupled().rigid().state(r.body).position_m, bound(r));
        return n;
    };
    // the same fill placed without regard to the machine: bodies sit in the steel
    {
        const auto sim = build_co_simulation(s, build_world(s));
        coupling::CoSimulation& scene = *sim;
        dem::World* const dem = &scene.dem();
        const FillSpec& f = s.fills[0];
        coupling::MixedDistribution d;
        d.spheres = {0.15, 0.5};
        d.rocks = {{0.6, 0.5}};
        const dem::MaterialIndex ore = dem->materials().index_of("ore");
        coupling::fill_mixed(scene.coupled(), f.min_m, f.max_m, d,
                             {ore, dem->materials().index_of("rock"), scene.coupled().rigid().material_index("rock"),
                              dem->materials().material(ore).density_kg_per_m3},
                             f.mass_kg, 1);
        CHECK(count_in_steel(scene, *dem) > 10);
    }
    // as a run fills it: none, the same mass, and the first step finds no body in the steel
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    fill_rocks(s, scene);
    CHECK(count_in_steel(scene, *dem) == 0);
    REQUIRE(scene.coupled().rocks().size() > 20);
    REQUIRE(dem->particles().size() > 200);
    double rock_mass = 0.0;
    for (const coupling::RockRecord& r : scene.coupled().rocks()) rock_mass += r.density_kg_per_m3 * r.shape.volume_m3();
    // the class counts come from the mass alone (round(f M / m)): the rocks' true volume differs from the
    // nominal sphere's by their shape, the spheres' total is exact to one sphere's mass
    CHECK(std::abs(dem->total_mass_kg() - 15000.0) < dem->particles().mass_kg[0]);
    CHECK(rock_mass > 0.5 * 15000.0);
    CHECK_NOTHROW(scene.step());
}

TEST_CASE("material held in the dipper: its weight on dipper and door, the mass and fill factor it shows, "
          "and the pass recorded when the door opens", "[scenario][shovel]")
{
    // the dig-end pose held for 2 s, then the door opens
    const meshes::Dipper dipper = meshes::make_dipper({});
    const std::string dir = (fs::temp_directory_path() / "dipper_held_material").string();
    const std::string text = held_in_dipper(dir, 2.4, 2.0, "sizes: [{radius_m: 0.15, mass_fraction: 1}]");
    const Scenario s = parse_scenario(text, "held.yaml", dir);
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    build_particles(s, *dem);
    REQUIRE(dem->particles().size() > 40);
    const double mass = dem->total_mass_kg();
    const int dipper_wall = scene.listed_walls()[1], door_wall = scene.listed_walls()[2];
    // the load on dipper and door, averaged over 0.5 s: the dipper hangs on its ropes and bobs on their
    // stretch at about 4 Hz, so the instantaneous load swings about the weight by some 10 %
    double load_sum = 0.0;
    Vec3 interface_sum;
    int load_samples = 0;
    while (scene.coupled().time_s() < 1.9) {
        scene.step();
        if (scene.coupled().time_s() < 1.4) continue;
        load_sum -= dem->wall_force_N(dipper_wall).z + dem->wall_force_N(door_wall).z;
        interface_sum += scene.interface_force_N();
        ++load_samples;
    }

    // every sphere is in the dipper: the probe counts all of them, and the fill factor is their mass over
    // the bulk density times the 42 m3 struck volume
    const coupling::BucketContents b = scene.bucket();
    CHECK(b.spheres == dem->particles().size());
    CHECK(b.mass_kg == Approx(mass).epsilon(1e-12));
    CHECK(b.fill_factor == Approx(mass / (1903.0 * dipper.struck_volume_m3)).epsilon(1e-12));

    // at rest the spheres press on dipper and door with their weight. Tolerance 3 %: the bed still creeps
    // on the tilted bottom (its kinetic energy is checked small as well) and the average spans two bobs
    double ke = 0.0;
    for (std::size_t i = 0; i < dem->particles().size(); ++i)
        ke += 0.5 * dem->particles().mass_kg[i] * norm_squared(dem->particles().velocity_m_per_s[i]);
    CHECK(ke < 0.01 * mass * 9.81 * 1.0);  // below 1 % of the bed's potential energy over 1 m
    const double down = load_sum / load_samples;
    CHECK(down == Approx(mass * 9.81).epsilon(0.03));
    // the interface force (resultant of the material's force on dipper and door) is that weight too, and
    // points down
    const Vec3 interface = interface_sum * (1.0 / load_samples);
    CHECK(norm(interface) == Approx(mass * 9.81).epsilon(0.03));
    CHECK(-interface.z == Approx(norm(interface)).epsilon(0.01));
    UNSCOPED_INFO("held material: " << mass << " kg, load on dipper and door " << down / 9.81 << " kg, kinetic energy " << ke << " J");
    CHECK(dem->wall_force_N(0).z == Approx(0.0).margin(1e-9));  // nothing rests on the ground

    // the door opens from t = 2 s: one pass, with the material that was in the dipper then
    CHECK(scene.passes().empty());
    while (scene.coupled().time_s() < 2.4) scene.step();
    REQUIRE(scene.passes().size() == 1);
    const coupling::PassRecord& p = scene.passes()[0];
    CHECK(p.dump_s > 2.0);
    CHECK(p.dump_s < 2.15);  // 5 deg of the 30 deg opening reached at 2.05 s, plus the door's lag
    CHECK(p.mass_kg == Approx(mass).epsilon(0.02));  // at 5 deg open, at most a few spheres have left
    CHECK(p.mean_dig_force_N == 0.0);                // the hoist never hauled in: no dig phase
    CHECK(scene.tonnage_t() == Approx(p.mass_kg / 1000.0));
    fs::remove_all(dir);
}

TEST_CASE("the interface force of spheres and rocks held in the dipper is their weight", "[scenario][shovel]")
{
    // the held pose of the test above, with 30 % of the mass in 400 mm rocks: the rocks press on the dipper
    // through Bullet's contacts, the spheres through the DEM walls; the resultant of both is the weight. At the
    // default coupling step (n = 5) and at one DEM step per rigid-body step
    const int substeps = GENERATE(1, 5);
    const std::string dir = (fs::temp_directory_path() / "dipper_held_rocks").string();
    const Scenario s = parse_scenario(
        held_in_dipper(dir, 3.0, 0.0, "sizes: [{radius_m: 0.15, mass_fraction: 0.7}], rocks: [{size_m: 0.4, mass_fraction: 0.3}]") +
            concat("coupling: {substeps: ", substeps, "}\n"),
        "held_rocks.yaml", dir);
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    build_particles(s, *dem);
    fill_rocks(s, scene);
    REQUIRE(!scene.coupled().rocks().empty());
    const double sphere_weight = dem->total_mass_kg() * 9.81;
    double rock_weight = 0.0;
    for (const coupling::RockRecord& r : scene.coupled().rocks()) rock_weight += scene.rigid().mass_kg(r.body) * 9.81;
    const double weight = sphere_weight + rock_weight;
    // averaged over 0.5 s after 1.4 s of settling, as above (the dipper bobs on its ropes): tolerance 3 %
    Vec3 sum;
    double spheres_only = 0.0, rocks_only = 0.0;
    int samples = 0;
    const int dipper_wall = scene.listed_walls()[1], door_wall = scene.listed_walls()[2];
    while (scene.coupled().time_s() < 1.9) {
        scene.step();
        if (scene.coupled().time_s() < 1.4) continue;
        sum += scene.interface_force_N();
        spheres_only += -(dem->wall_force_N(dipper_wall) + dem->wall_force_N(door_wall)).z;
        rocks_only += -(scene.rigid().contact_force_N(scene.dipper_body()) + scene.rigid().contact_force_N(scene.door_body())).z;
        ++samples;
    }
    spheres_only /= samples;
    rocks_only /= samples;
    UNSCOPED_INFO("n = " << substeps << ", held spheres and " << scene.coupled().rocks().size() << " rocks: " << weight / 9.81
                         << " kg, interface force " << norm(sum) / samples / 9.81 << " kg-force, of the spheres " << spheres_only / 9.81
                         << ", of the rocks on the steel " << rocks_only / 9.81);
    CHECK(norm(sum) / samples == Approx(weight).epsilon(0.03));
    CHECK(-sum.z == Approx(norm(sum)).epsilon(0.01));  // and it points down
    // How the rocks' weight divides between steel and spheres depends on where they came to rest; the bounds
    // do not: the spheres carry their own weight and at most all the rocks' as well, the rocks on the steel
    // at most their own weight (3 % as above). At least one rock rests on the steel, through Bullet's contacts:
    // more than 5 % of the rocks' weight (each of the six is about a sixth)
    CHECK(spheres_only > 0.97 * sphere_weight);
    CHECK(spheres_only < 1.03 * (sphere_weight + rock_weight));
    CHECK(rocks_only < 1.03 * rock_weight);
    CHECK(rocks_only > 0.05 * rock_weight);
    fs::remove_all(dir);
}

TEST_CASE("the force on the lip and its teeth is told from the rest of the dipper's, for a sphere and for a rock",
          "[scenario][shovel]")
{
    // The held pose with the fill moved far from the shovel, and one body pressed 1-2 mm into the dipper's
    // working face (z = 0 in its frame): in the middle of the lip (x 3.6-4.0 m) or of the bottom (x < 3.6 m).
    // After one coupling step that body's contact is all the interface force there is: all of it on the lip,
    // or none. The rock's contacts are Bullet's (their points located on the dipper's mesh), the sphere's the DEM's
    const std::string dir = (fs::temp_directory_path() / "dipper_lip_force").string();
    const std::string body = GENERATE(as<std::string>{}, "sphere", "rock");
    const double x = GENERATE(3.8, 2.0);
    std::string text = held_in_dipper(dir, 1.0, 0.0, "sizes: [{radius_m: 0.15, mass_fraction: 1}]");
    text = std::regex_replace(text, std::regex("box: \\{min_m: \\[[^]]*\\], max_m: \\[[^]]*\\]\\}"),
                              "box: {min_m: [-30, -1, 0], max_m: [-28, 1, 2]}");
    text = std::regex_replace(text, std::regex("mass_kg: 2500"), "mass_kg: 200");
    const Scenario s = parse_scenario(text, "lip.yaml", dir);
    const auto sim = build_co_simulation(s, build_world(s));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    build_particles(s, *dem);
    Mat3 r;
    Vec3 o;
    scene.rigid().dipper_pose(r, o);
    if (body == "sphere") {
        dem::ParticleSpawn p;
        p.radius_m = 0.15;
        p.position_m = o + r * Vec3{x, 0.0, p.radius_m - 0.002};
        p.material = dem->materials().index_of("ore");
        dem->add_particle(p);
    } else {
        std::vector<Vec3> corners;  // a 0.3 x 0.2 x 0.1 m block, turned with the dipper, its lowest face 1 mm in
        for (double a : {-0.15, 0.15})
            for (double b : {-0.1, 0.1})
                for (double c : {-0.05, 0.05}) corners.push_back({a, b, c});
        const rigid::ConvexPolyhedron block = rigid::ConvexPolyhedron::hull_of(corners, "block").in_principal_frame();
        double lowest = 0.0;
        for (const Vec3& v : block.vertices_m()) lowest = std::min(lowest, v.z);
        scene.coupled().add_rock(block, 2700.0, scene.rigid().material_index("rock"), dem->materials().index_of("rock"),
                                 o + r * Vec3{x, 0.0, -lowest - 0.001}, r);
    }
    scene.step();
    const Vec3 total = scene.interface_force_N(), lip = scene.lip_force_N();
    UNSCOPED_INFO(body << " at x = " << x << " m: interface force " << norm(total) << " N, on the lip " << norm(lip) << " N");
    REQUIRE(norm(total) > 1.0);  // it touches: more than a newton
    if (x > 3.6) CHECK(norm(lip - total) < 1e-9 * norm(total));  // the same sums, to round-off
    else CHECK(norm(lip) == 0.0);
    fs::remove_all(dir);
}


TEST_CASE("a sweep table of shovel runs has each pass's mass, fill factor and forces, the repose angle and the dipper's wear",
          "[scenario][shovel]")
{
    const fs::path dir = fs::temp_directory_path() / "dipper_shovel_sweep_table";
    fs::remove_all(dir);
    fs::create_directories(dir / "variant_000");
    fs::create_directories(dir / "variant_001");
    {
        std::ofstream scenario(dir / "base.yaml");
        scenario << base("shovel: {}\nwear:\n  - {part: dipper, constant: 1.0e-12}\n"
                         "probes:\n  repose: {min_m: [0, 0, 0], max_m: [1, 1, 1], along: x, bin_m: 0.1}\n");
        std::ofstream sweep(dir / "sweep.yaml");
        sweep << "dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: shovel.rake_angle_deg, values: [59.8, 63.8]}\n";
    }
    // the summaries two runs would leave: two passes in the first, one in the second
    const auto summary = [&](const fs::path& file, const std::string& passes, double wear) {
        std::ofstream out(file);
        out << "{\n  \"name\": \"x\",\n  \"status\": \"completed\",\n  \"time_s\": 60,\n  \"steps\": 10,\n  \"particles\": 5,\n"
            << "  \"mass_kg\": 1000,\n  \"kinetic_energy_J\": 1,\n  \"region_mass_kg\": {},\n  \"repose_angle_deg\": " << 30.0 + wear
            << ",\n  \"state_hash\": \"ab\",\n"
            << "  \"passes\": [" << passes << "\n  ],\n  \"tonnage_t\": 150,\n  \"wear\": {\"dipper\": {\"law\": \"force_work\", "
            << "\"constant\": 1e-12, \"volume_m3\": " << wear << ", \"max_depth_mm\": 0.1, \"volume_by_region_m3\": {\"bottom\": 0.25, "
            << "\"lip\": 0.125, \"sides\": 0, \"top\": 0, \"teeth\": 0, \"bars\": 0}}}\n}\n";
    };
    summary(dir / "variant_000" / "summary.json",
            "\n    {\"pass\": 1, \"mass_kg\": 80000, \"fill_factor\": 1.0, \"mean_dig_force_N\": 4200000, \"mean_interface_force_N\": 2100000, \"mean_interface_force_without_lip_N\": 1900000},"
            "\n    {\"pass\": 2, \"mass_kg\": 70000, \"fill_factor\": 0.875, \"mean_dig_force_N\": 3900000}",
            0.5);
    summary(dir / "variant_001" / "summary.json", "\n    {\"pass\": 1, \"mass_kg\": 85000, \"fill_factor\": 1.0625, \"mean_dig_force_N\": 4300000}",
            0.75);
    const Sweep sw = load_sweep((dir / "sweep.yaml").string());
    write_sweep_table(sw, dir.string());
    std::ifstream in(dir / "sweep.csv");
    std::string header, first, second;
    std::getline(in, header);
    std::getline(in, first);
    std::getline(in, second);
    CHECK_THAT(header, Catch::EndsWith("repose_angle_deg,pass1_mass_kg,pass1_fill_factor,pass1_mean_dig_force_N,pass1_mean_interface_force_N,"
                                       "pass1_mean_interface_force_without_lip_N,pass2_mass_kg,pass2_fill_factor,pass2_mean_dig_force_N,"
                                       "pass2_mean_interface_force_N,pass2_mean_interface_force_without_lip_N,"
                                       "tonnage_t,wear_dipper_m3,wear_dipper_bottom_m3,wear_dipper_lip_m3,wear_dipper_bars_m3"));
    // a field a summary lacks (an older run's) stays empty
    CHECK_THAT(first, Catch::StartsWith("0,\"59.8\",completed,") && Catch::EndsWith(",30.5,80000,1.0,4200000,2100000,1900000,70000,0.875,3900000,,,150,0.5,0.25,0.125,0"));
    CHECK_THAT(second, Catch::StartsWith("1,\"63.8\",completed,") && Catch::EndsWith(",30.75,85000,1.0625,4300000,,,,,,,,150,0.75,0.25,0.125,0"));
    fs::remove_all(dir);
}

TEST_CASE("measured wear: compared and calibrated at the end of a run, points off the part are refused before it",
          "[scenario][wear]")
{
    const std::string file = std::string(DIPPER_SOURCE_DIR) + "/tests/data/scenarios/wear_floor.yaml";
    const std::string dir = (fs::temp_directory_path() / "dipper_wear_floor").string();
    fs::remove_all(dir);
    RunOptions o;
    o.progress = false;
    const RunResult r = run_scenario(load_scenario(file), dir, o);
    REQUIRE(r.status == RunStatus::completed);
    const std::string s = test::read_text_file(dir + "/summary.json");
    const auto number = [&](const std::string& key) {
        std::smatch m;
        REQUIRE(std::regex_search(s, m, std::regex("\"" + key + "\": ([-0-9.eE+]+)")));
        return std::stod(m[1]);
    };
    CHECK(number("points") == 4);
    // the file's rates: 0.2, 0.3, 0.2, 0.4 mm over 0.3 t
    CHECK(number("mean_measured_mm_per_t") == Approx((0.2 + 0.3 + 0.2 + 0.4) / 4.0 / 0.3).epsilon(1e-9));
    const double simulated = number("mean_simulated_mm_per_t");
    CHECK(simulated > 0.0);
    // the calibration scales the constant so that the means agree
    CHECK(number("scale") == Approx(number("mean_measured_mm_per_t") / simulated).epsilon(1e-6));
    CHECK(number("calibrated_constant") == Approx(1.0e-12 * number("scale")).epsilon(1e-6));
    std::ifstream points(dir + "/wear_floor_points.csv");
    std::string line;
    int rows = 0;
    while (std::getline(points, line)) ++rows;
    CHECK(rows == 5);  // header and four points

    // the section y = -0.5 from x = -0.9 to 0.9: 19 samples 0.1 m apart, and the measured points a and b on it
    std::ifstream section(dir + "/wear_floor_section_south.csv");
    std::getline(section, line);
    CHECK(line == "kind,arc_length_m,x_m,y_m,z_m,simulated_mm_per_t,measured_mm_per_t,id");
    std::vector<std::vector<std::string>> simulated_rows, measured_rows;
    while (std::getline(section, line)) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) f.push_back(cell);
        (f[0] == "simulated" ? simulated_rows : measured_rows).push_back(f);
    }
    REQUIRE(simulated_rows.size() == 19);
    REQUIRE(measured_rows.size() == 2);
    CHECK(measured_rows[0][7] == "a");
    CHECK(std::stod(measured_rows[0][1]) == Approx(0.4).margin(1e-12));
    CHECK(measured_rows[1][7] == "b");
    CHECK(std::stod(measured_rows[1][1]) == Approx(1.4).margin(1e-12));
    CHECK(std::stod(measured_rows[1][6]) == Approx(0.3 / 0.3).epsilon(1e-9));
    // the profile at a point's arc length is the map's rate at that point
    CHECK(std::stod(simulated_rows[4][5]) == Approx(std::stod(measured_rows[0][5])).epsilon(1e-6));
    CHECK(std::stod(simulated_rows[14][5]) == Approx(std::stod(measured_rows[1][5])).epsilon(1e-6));
    CHECK(number("measured_points") == 2);
    CHECK(number("mean_measured_mm_per_t") == Approx((0.2 + 0.3 + 0.2 + 0.4) / 4.0 / 0.3).epsilon(1e-9));  // the file's first

    // a point 0.5 m above the floor belongs to no part: refused before anything runs
    const fs::path bad = fs::temp_directory_path() / "dipper_wear_floor_bad.csv";
    {
        std::ofstream out(bad);
        out << "id,x_m,y_m,z_m,depth_mm,tonnage_t\nhigh,0,0,0.5,0.1,1\n";
    }
    Scenario sc = load_scenario(file);
    sc.wear[0].measured_file = bad.string();
    CHECK_THROWS_WITH(run_scenario(sc, dir, o), Catch::Contains("measured point 'high'") && Catch::Contains("0.5 m from the surface of 'floor'"));
    // a section that leaves the part: refused before anything runs, with its key
    Scenario off = load_scenario(file);
    off.wear[0].sections[0].points_m[1] = {0.9, -0.5, 0.5};
    CHECK_THROWS_WITH(run_scenario(off, dir, o), Catch::Contains("wear[0].sections[0].name") && Catch::Contains("section 'south'") &&
                                                     Catch::Contains("from the surface of 'floor'"));
    fs::remove_all(dir);
    fs::remove(bad);
}


TEST_CASE("a pile saved cut at a height and loaded by another scenario holds what lay below the cut",
          "[scenario][rocks]")
{
    const fs::path dir = fs::temp_directory_path() / "dipper_saved_pile";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string walls = R"(planes:
  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
  - {name: x0, point_m: [-1, 0, 0], normal: [1, 0, 0],  material: steel}
  - {name: x1, point_m: [1, 0, 0],  normal: [-1, 0, 0], material: steel}
  - {name: y0, point_m: [0, -1, 0], normal: [0, 1, 0],  material: steel}
  - {name: y1, point_m: [0, 1, 0],  normal: [0, -1, 0], material: steel}
)";
    {
        std::ofstream out(dir / "build.yaml");
        out << "dipper_scenario: 1\nthreads: 1\nseed: 2\ntime: {duration_s: 0.6}\n" << walls
            << "fills:\n  - {mass_kg: 900, box: {min_m: [-0.95, -0.95, 0.02], max_m: [0.95, 0.95, 1.6]},\n"
               "     sizes: [{radius_m: 0.08, mass_fraction: 0.6}], rocks: [{size_m: 0.3, mass_fraction: 0.4}]}\n"
               "output: {vtk_interval_s: 0, pile_file: pile.txt, pile_cut_above_m: 0.3}\n";
        std::ofstream reuse(dir / "reuse.yaml");
        reuse << "dipper_scenario: 1\nthreads: 1\ntime: {duration_s: 0.01}\n" << walls
              << "pile: build_out/pile.txt\noutput: {vtk_interval_s: 0}\n";
    }
    RunOptions o;
    o.progress = false;
    const std::string built = (dir / "build_out").string();
    REQUIRE(run_scenario(load_scenario((dir / "build.yaml").string()), built, o).status == RunStatus::completed);
    // what the saved file holds, counted from its own lines: spheres and rocks below 0.3 m only
    std::ifstream pile(built + "/pile.txt");
    std::string word;
    std::size_t spheres = 0, rocks = 0;
    double z_max = -1.0;
    pile >> word >> word >> word >> spheres;  // magic, version, "spheres", count
    for (std::size_t k = 0; k < spheres; ++k) {
        double x, y, z;
        pile >> x >> y >> z;
        z_max = std::max(z_max, z);
        std::getline(pile, word);
    }
    pile >> word >> rocks;
    CHECK(word == "rocks");
    CHECK(spheres > 10);
    CHECK(rocks > 0);
    CHECK(z_max <= 0.3);
    UNSCOPED_INFO("saved pile: " << spheres << " spheres, " << rocks << " rocks");

    const Scenario reuse = load_scenario((dir / "reuse.yaml").string());
    const auto sim = build_co_simulation(reuse, build_world(reuse));
    coupling::CoSimulation& scene = *sim;
    dem::World* const dem = &scene.dem();
    coupling::load_state(scene.coupled(), reuse.pile);
    CHECK(dem->particles().size() == spheres);
    CHECK(scene.coupled().rocks().size() == rocks);
    for (const coupling::RockRecord& r : scene.coupled().rocks()) CHECK(scene.rigid().state(r.body).position_m.z <= 0.3);
    // and the run from it goes
    CHECK(run_scenario(reuse, (dir / "reuse_out").string(), o).status == RunStatus::completed);

    std::string e;
    try {
        parse_scenario(concat("dipper_scenario: 1\ntime: {duration_s: 1}\n", walls, "pile: nowhere.txt\n"), "case.yaml", dir.string());
    } catch (const InputError& error) {
        e = error.what();
    }
    CHECK_THAT(e, Catch::Contains("pile: got \"nowhere.txt\"; expected a saved pile file"));
    fs::remove_all(dir);
}

TEST_CASE("a pile cut to a region keeps what lies in it and holds the layer along the cut, through a resume",
          "[scenario][rocks][held]")
{
    // the thesis' simplified model: the pile cut to the region the dipper works in, a boundary layer held fixed
    const fs::path dir = fs::temp_directory_path() / "dipper_pile_region";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string walls = R"(planes:
  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
  - {name: x0, point_m: [-1, 0, 0], normal: [1, 0, 0],  material: steel}
  - {name: y0, point_m: [0, -1, 0], normal: [0, 1, 0],  material: steel}
  - {name: y1, point_m: [0, 1, 0],  normal: [0, -1, 0], material: steel}
)";
    {
        std::ofstream out(dir / "build.yaml");
        out << "dipper_scenario: 1\nthreads: 1\nseed: 3\ntime: {duration_s: 0.3}\n" << walls
            << "  - {name: x1, point_m: [1, 0, 0],  normal: [-1, 0, 0], material: steel}\n"
               "fills:\n  - {mass_kg: 700, box: {min_m: [-0.95, -0.95, 0.02], max_m: [0.95, 0.95, 1.2]},\n"
               "     sizes: [{radius_m: 0.08, mass_fraction: 0.6}], rocks: [{size_m: 0.3, mass_fraction: 0.4}]}\n"
               "output: {vtk_interval_s: 0, pile_file: pile.txt}\n";
    }
    RunOptions o;
    o.progress = false;
    REQUIRE(run_scenario(load_scenario((dir / "build.yaml").string()), (dir / "build_out").string(), o).status == RunStatus::completed);
    // the region cuts the pile at x = 0.1 only (its other faces lie beyond the pile), the +x wall taken away with it
    const std::string reuse = concat("dipper_scenario: 1\nthreads: 1\ntime: {duration_s: 0.2}\n", walls,
                                     "pile: build_out/pile.txt\ndynamic_domain: {}\n"
                                     "output: {vtk_interval_s: 0, checkpoint_interval_s: 0.05}\n");
    const std::string region = "pile_region: {min_m: [-2, -2, -1], max_m: [0.1, 2, 3], hold_m: 0.25}\n";
    Simulation whole(parse_scenario(reuse, "whole.yaml", dir.string()));
    Simulation cut(parse_scenario(reuse + region, "cut.yaml", dir.string()));
    // kept: the bodies whose centre lies at x <= 0.1; held: those of them within 0.25 m of the cut (x > -0.15)
    std::size_t spheres = 0, held_spheres = 0, rocks = 0, held_rocks = 0;
    for (const Vec3& x : whole.world().particles().position_m) {
        spheres += x.x <= 0.1 ? 1 : 0;
        held_spheres += x.x <= 0.1 && x.x > -0.15 ? 1 : 0;
    }
    for (const coupling::RockRecord& r : whole.co_simulation()->coupled().rocks()) {
        const double x = whole.co_simulation()->rigid().position_m(r.body).x;
        rocks += x <= 0.1 ? 1 : 0;
        held_rocks += x <= 0.1 && x > -0.15 ? 1 : 0;
    }
    UNSCOPED_INFO("whole pile " << whole.world().particles().size() << " spheres, " << whole.co_simulation()->coupled().rocks().size()
                                << " rocks; kept " << spheres << " and " << rocks << ", held " << held_spheres << " and " << held_rocks);
    REQUIRE(held_spheres > 5);
    REQUIRE(spheres > held_spheres + 5);
    REQUIRE(whole.world().particles().size() > spheres);
    const dem::ParticleStore& p = cut.world().particles();
    CHECK(p.size() == spheres);
    CHECK(cut.co_simulation()->coupled().rocks().size() == rocks);
    CHECK(cut.pile().spheres_left_out == whole.world().particles().size() - spheres);
    CHECK(cut.co_simulation()->dynamic_domain().held_bodies() == held_spheres + held_rocks);
    std::vector<std::pair<std::uint32_t, Vec3>> held;
    for (std::size_t i = 0; i < p.size(); ++i) {
        CHECK((p.frozen[i] == 1) == (p.position_m[i].x > -0.15));
        if (p.frozen[i]) held.emplace_back(p.id[i], p.position_m[i]);
    }
    // held for good: the layer has not moved by one bit when the material beside it has settled on
    cut.run_until(0.2);
    for (const auto& [id, x] : held) {
        const auto i = static_cast<std::size_t>(std::find(p.id.begin(), p.id.end(), id) - p.id.begin());
        REQUIRE(i < p.size());
        CHECK(p.frozen[i] == 1);
        CHECK(p.position_m[i] == x);
    }
    // a run stopped and resumed ends as the run in one go: the hold is in the checkpoint
    {
        std::ofstream(dir / "cut.yaml") << reuse << region;
    }
    const Scenario s = load_scenario((dir / "cut.yaml").string());
    REQUIRE(run_scenario(s, (dir / "one").string(), o).status == RunStatus::completed);
    RunOptions stop = o;
    stop.stop_after_s = 0.07;
    REQUIRE(run_scenario(s, (dir / "legs").string(), stop).status == RunStatus::interrupted);
    REQUIRE(resume_run((dir / "legs").string(), o).status == RunStatus::completed);
    auto hash = [](const fs::path& d) {
        std::ifstream in(d / "summary.json");
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        std::smatch m;
        REQUIRE(std::regex_search(text, m, std::regex("\"state_hash\": \"([0-9a-f]+)\"")));
        return m[1].str();
    };
    CHECK(hash(dir / "legs") == hash(dir / "one"));

    // what is refused, by key and value
    auto error = [&](const std::string& text) {
        try {
            Simulation(parse_scenario(text, "case.yaml", dir.string()));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    const std::string no_pile = std::regex_replace(reuse, std::regex("pile: build_out/pile.txt\n"), "fills: [{mass_kg: 10, box: {min_m: [-0.5, -0.5, 0], max_m: [0.5, 0.5, 0.5]}, sizes: [{radius_m: 0.08, mass_fraction: 1}]}]\n");
    CHECK_THAT(error(no_pile + region), Catch::Contains("pile_region: a region of a pile, but the scenario has no 'pile' to cut"));
    CHECK_THAT(error(reuse + "pile_region: {min_m: [-2, -2, -1], max_m: [0.1, 2, 3], hold_m: 1.1}\n"),
               Catch::Contains("pile_region.hold_m: got 1.1; expected less than half the region's narrowest side (2.1 m)"));
    CHECK_THAT(error(reuse + "pile_region: {min_m: [5, 5, 5], max_m: [8, 8, 8]}\n"), Catch::Contains("keeps none of the pile's bodies"));
    fs::remove_all(dir);
}
