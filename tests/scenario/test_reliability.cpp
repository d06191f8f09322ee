// Inputs that `dipper check` once accepted and `dipper run` then crashed or hung on, and states dipper
// wrote that it would not read back: each is refused by its key, file and line before the first step, or
// now runs. Each case is the reproducer it was found with.
#include "core/errors.h"
#include "meshes/mesh_file_check.h"
#include "meshes/mesh_io.h"
#include "scenario/helpers.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/sweep.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>

using namespace dipper;
using namespace dipper::scenario;
using Catch::Contains;
namespace fs = std::filesystem;

namespace {

/// examples/scenarios/settle_box.yaml, the scenario the pour defects were found with, shortened.
std::string settle_box(double duration_s = 0.02)
{
    std::string text = test::read_text_file(DIPPER_SOURCE_DIR "/examples/scenarios/settle_box.yaml");
    REQUIRE(!text.empty());
    return std::regex_replace(text, std::regex("duration_s: 3.0"), concat("duration_s: ", duration_s));
}

/// The InputError of `check` (parsing and check_scenario) on the text, or "" if it passed.
std::string check_error(const std::string& text)
{
    try {
        check_scenario(parse_scenario(text, "case.yaml", DIPPER_SOURCE_DIR "/examples/scenarios"));
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

std::string write_file(const std::string& name, const std::string& text)
{
    const std::string path = (fs::temp_directory_path() / name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string mesh_error(const std::string& path)
{
    try {
        meshes::load_triangle_mesh(path);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

/// A closed unit box as an ASCII STL with its 12 facets.
std::string ascii_stl_box()
{
    const double v[8][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {0, 1, 1}, {1, 0, 0}, {1, 0, 1}, {1, 1, 0}, {1, 1, 1}};
    const int f[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                          {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
    std::string s = "solid box\n";
    for (const auto& t : f) {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for (int c : t) s += concat("      vertex ", v[c][0], " ", v[c][1], " ", v[c][2], "\n");
        s += "    endloop\n  endfacet\n";
    }
    return s + "endsolid box\n";
}

const std::string kPlyHeader = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                               "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

}  // namespace

TEST_CASE("a pour box too narrow for its spheres is refused by check, not a segfault of run", "[scenario][input][unit]")
{
    // 0.15-0.21 m wide for spheres of radius 0.1 m: nothing was placed at t = 0, the step was 0 and the run
    // read particle 0 of none (exit 139)
    const auto narrow = [&](double width) {
        return std::regex_replace(settle_box(), std::regex("max_m: \\[2.5, 2.5, 4.0\\]"), concat("max_m: [", width, ", ", width, ", 4.0]"));
    };
    CHECK_THAT(test::scenario_error(narrow(0.15)), Contains("pours[0].box: got a box 0.15 m wide in x") &&
                                                       Contains("wider than the largest sphere's diameter, 0.2 m"));
    CHECK_THAT(test::scenario_error(narrow(0.2)), Contains("pours[0].box"));
    // 0.21 m: a centre may fit, but 200 random tries in the box find none at t = 0; check places the pour
    // with the run's seed and refuses it, and so does the run
    const std::string e = check_error(narrow(0.21));
    CHECK_THAT(e, Contains("case.yaml:18:14: pours[0].mass_kg: no sphere found room in the pour's box at t = 0") &&
                      Contains("time.step_s"));
    const fs::path dir = fs::temp_directory_path() / "dipper_narrow_pour";
    fs::remove_all(dir);
    RunOptions quiet;
    quiet.progress = false;
    CHECK_THROWS_WITH(run_scenario(parse_scenario(narrow(0.21), "case.yaml", "."), dir.string(), quiet), Contains("no sphere found room"));
    // with the step given the run does not need a sphere at t = 0, and the pour places as room is found
    CHECK(check_error(std::regex_replace(narrow(0.21), std::regex("duration_s: 0.02"), "duration_s: 0.02\n  step_s: 4e-5")).empty());
    CHECK(check_error(narrow(0.22)).empty());
}

TEST_CASE("output intervals shorter than the step are refused by check and run (1e-17 s hung the run)", "[scenario][input][unit]")
{
    for (const char* key : {"csv_interval_s: 0.01", "vtk_interval_s: 0.1", "checkpoint_interval_s: 1.0"}) {
        const std::string name = std::string(key).substr(0, std::string(key).find(':'));
        const std::string text = std::regex_replace(settle_box(), std::regex(key), name + ": 1e-17");
        REQUIRE(text != settle_box());
        CHECK_THAT(check_error(text), Contains(concat("output.", name, ": got 1e-17; expected at least the time step, 4.31")));
    }
    // and a step count past 10^9 is refused by check as by run (C_norm 1e30: a step of about 1e-20 s)
    CHECK_THAT(check_error(std::regex_replace(settle_box(), std::regex("  preset: aitik_copper_ore\n"),
                                              "  preset: aitik_copper_ore\n  pairs:\n    - {materials: [ore, ground], normal_stiffness_scale: 1e30}\n")),
               Contains("case.yaml: time.duration_s = 0.02 s is") && Contains("a run takes at most 1000000000 steps"));
    // the step itself is what the run takes: 0.15 sqrt(m/k) of the 0.1 m ore sphere against its stiffest pair
    const Scenario s = parse_scenario(settle_box(), "case.yaml", ".");
    const auto world = build_world(s);
    CHECK(planned_step_s(s, *world) == Approx(4.312566348e-05).epsilon(1e-9));
}

TEST_CASE("a fill whose spheres the machine's memory cannot hold is refused with the figure", "[scenario][input][unit]")
{
    // 9 x 10^7 spheres of 5 mm: under the 10^8 a fill may hold, but 90 GB at the measured 1 kB a sphere;
    // the run grew to 5.7 GB and died with std::bad_alloc
    const std::string text = std::regex_replace(
        std::regex_replace(settle_box(), std::regex("mass_kg: 46495"), "mass_kg: 21800"), std::regex("radius_m: 0.1,"), "radius_m: 0.0025,");
    CHECK_THAT(check_error(text), Contains("pours[0].mass_kg: the run's 90021477 spheres") && Contains("GB of memory (1000 bytes each)") &&
                                      Contains("make the fills and pours smaller"));
    CHECK(run_memory_bytes(1e6) == Approx(1.064e9));
}

TEST_CASE("mesh files are checked whole before assimp reads them", "[meshes][input][unit]")
{
    // the reproducers: a PLY cut after its first vertex (assimp aborted), headers claiming 10^7 vertices
    // (48 s) and 10^11 with no properties (spun at full CPU), an ASCII STL cut in the middle (half loaded)
    CHECK_THAT(mesh_error(write_file("cut.ply", kPlyHeader + "0 0 0\n")),
               Contains("cut.ply' (ASCII PLY) body: its header claims items that take at least 26 bytes; the file holds 6"));
    CHECK_THAT(mesh_error(write_file("claims.ply", std::regex_replace(kPlyHeader, std::regex("vertex 4"), "vertex 10000000") + "0 0 0\n")),
               Contains("at least 60000002 bytes"));
    CHECK_THAT(mesh_error(write_file("noprop.ply", "ply\nformat ascii 1.0\nelement vertex 99999999999\nelement face 1\n"
                                                   "property list uchar int vertex_indices\nend_header\n0 0 0\n")),
               Contains("the vertex element has no scalar property 'x'"));
    const std::string box = ascii_stl_box();
    CHECK(meshes::load_triangle_mesh(write_file("box.stl", box)).triangle_count() == 12);
    CHECK_THAT(mesh_error(write_file("half.stl", box.substr(0, box.size() / 2))),
               Contains("half.stl' (ASCII STL) line 44: the file ends after 6 complete facets without 'endsolid': it is cut short"));
    CHECK_THAT(mesh_error(write_file("nan.stl", std::regex_replace(box, std::regex("vertex 1 1 1"), "vertex 1 nan 1"))),
               Contains("expected a finite number in facet"));
    // a face that names a vertex the file does not have, a binary PLY cut short, a binary STL one byte short
    CHECK_THAT(mesh_error(write_file("index.ply", kPlyHeader + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 4\n")),
               Contains("face 0 names vertex 4; the file has 4"));
    std::string binary = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    binary += std::string(36, '\0');
    CHECK_THAT(mesh_error(write_file("binary.ply", binary)), Contains("(binary PLY) body"));
    meshes::write_stl(meshes::load_triangle_mesh(write_file("box2.stl", box)), (fs::temp_directory_path() / "box_binary.stl").string());
    std::string stl = test::read_text_file((fs::temp_directory_path() / "box_binary.stl").string());
    REQUIRE(stl.size() == 84 + 50 * 12);
    CHECK(meshes::check_mesh_file(write_file("whole_binary.stl", stl)).faces == 12);
    CHECK_THAT(mesh_error(write_file("short_binary.stl", stl.substr(0, stl.size() - 1))),
               Contains("neither a binary STL (683 bytes where its triangle count asks for 84 + 50 per triangle)"));
    CHECK_THAT(mesh_error(write_file("part.off", "OFF\n")), Contains("is not an STL, OBJ or PLY file"));
    // OBJ: a corner that names a vertex not yet given
    CHECK_THAT(mesh_error(write_file("ahead.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n")), Contains("ahead.obj' (OBJ) line 3: face corner 3"));
}

TEST_CASE("scenario text that once misled the reader is refused where it goes wrong", "[scenario][input][unit]")
{
    const std::string base = settle_box();
    // bytes that are not UTF-8 in the name (summary.json was invalid JSON and the report failed)
    CHECK_THAT(test::scenario_error(std::regex_replace(base, std::regex("name: settle_box"), "name: \"ab\xff\xfe\"")),
               Contains("case.yaml:4:10: the byte 0xFF is not UTF-8"));
    // an unclosed quote swallowed the rest of the file ("time: got nothing")
    CHECK_THAT(test::scenario_error(std::regex_replace(base, std::regex("name: settle_box"), "name: \"settle_box")),
               Contains("case.yaml:4:7: the quoted value that starts here (\") is never closed"));
    // apostrophes and quotes inside plain values and comments are not quotes
    CHECK(test::scenario_error(std::regex_replace(base, std::regex("name: settle_box"), "name: O'Brien's box # the \"old\" one")).empty());
    CHECK_THAT(test::scenario_error(base + "---\nname: other\n"), Contains("case.yaml:30: '---' ends the scenario's YAML document"));
    CHECK_THAT(test::scenario_error(base + "meshes:\n  - {name: m, file: ../../meshes/generated/ground.stl, material: steel, translate_m: [1e300, 0, 0]}\n"),
               Contains("meshes[0].translate_m: got [1e300, 0, 0]; expected a list of 3 numbers each within +-1000000"));
    CHECK_THAT(test::scenario_error(std::regex_replace(base, std::regex("(    - \\{name: lower_half[^\n]*\n)"), "$1$1")),
               Contains("probes.regions[1].name: got \"lower_half\"; expected a name no other region has"));
}

TEST_CASE("a sweep refuses a key swept twice, and a variant refused at its start stops only itself", "[scenario][input][unit]")
{
    const fs::path dir = fs::temp_directory_path() / "dipper_sweep_refused";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "base.yaml") << settle_box(0.005);
    std::ofstream(dir / "twice.yaml") << "dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: seed, values: [1, 2]}\n"
                                         "  - {key: seed, values: [3]}\n";
    CHECK_THROWS_WITH(load_sweep((dir / "twice.yaml").string()), Contains("parameters[1].key: 'seed' is swept already"));
    std::ofstream(dir / "sweep.yaml") << "dipper_sweep: 1\nbase: base.yaml\nparameters:\n"
                                         "  - {key: 'pours[0].box.max_m', values: [[0.21, 0.21, 4.0], [2.5, 2.5, 4.0]]}\n";
    const Sweep sweep = load_sweep((dir / "sweep.yaml").string());
    RunOptions quiet;
    quiet.progress = false;
    CHECK(run_sweep_variants(sweep, (dir / "out").string(), quiet, 0, 1).failed == 1);
    write_sweep_table(sweep, (dir / "out").string());
    const std::string table = test::read_text_file((dir / "out" / "sweep.csv").string());
    CHECK_THAT(table, Contains("\n0,\"[0.21, 0.21, 4.0]\",refused,") && Contains("\n1,\"[2.5, 2.5, 4.0]\",completed,"));
}

TEST_CASE("resume --from a folder says to give a file", "[scenario][input][unit]")
{
    RunOptions quiet;
    quiet.progress = false;
    const fs::path dir = fs::temp_directory_path() / "dipper_from_folder";
    fs::create_directories(dir);
    CHECK_THROWS_WITH(resume_run(dir.string(), quiet, dir.string()), Contains("is a folder; give a checkpoint file"));
}

TEST_CASE("a pile dipper settled and saved loads again with the overlaps it was saved with", "[scenario][unit]")
{
    // under 300 m/s2 a 1 m deep bed of 50 mm spheres rests with overlaps of 1.7 % of a radius, above the
    // 1 % generated placements may have; the reload refused it ("overlap by 1.12 % of radius")
    const fs::path dir = fs::temp_directory_path() / "dipper_pile_overlaps";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string walls = "gravity_m_per_s2: [0, 0, -300]\nplanes:\n"
                              "  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}\n"
                              "  - {name: x0, point_m: [-0.5, 0, 0], normal: [1, 0, 0], material: steel}\n"
                              "  - {name: x1, point_m: [0.5, 0, 0], normal: [-1, 0, 0], material: steel}\n"
                              "  - {name: y0, point_m: [0, -0.5, 0], normal: [0, 1, 0], material: steel}\n"
                              "  - {name: y1, point_m: [0, 0.5, 0], normal: [0, -1, 0], material: steel}\n";
    std::ofstream(dir / "build.yaml") << "dipper_scenario: 1\nthreads: 1\nseed: 3\ntime: {duration_s: 0.8}\n" << walls
                                      << "fills:\n  - {mass_kg: 3000, box: {min_m: [-0.5, -0.5, 0], max_m: [0.5, 0.5, 3.0]}, "
                                         "sizes: [{radius_m: 0.05, mass_fraction: 1.0}]}\n"
                                         "output: {vtk_interval_s: 0, csv_interval_s: 0.1, pile_file: pile.txt}\n";
    std::ofstream(dir / "reuse.yaml") << "dipper_scenario: 1\nthreads: 1\ntime: {duration_s: 0.01}\n" << walls
                                      << "pile: built/pile.txt\noutput: {vtk_interval_s: 0}\n";
    RunOptions quiet;
    quiet.progress = false;
    REQUIRE(run_scenario(load_scenario((dir / "build.yaml").string()), (dir / "built").string(), quiet).status == RunStatus::completed);
    // the saved bed's largest overlap, from its last row of probes.csv (column max_overlap_ratio)
    std::ifstream csv(dir / "built" / "probes.csv");
    std::string line, last;
    while (std::getline(csv, line)) last = line;
    std::stringstream row(last);
    std::string cell;
    for (int c = 0; c < 8; ++c) std::getline(row, cell, ',');
    INFO("largest overlap of the saved bed: " << cell);
    REQUIRE(std::stod(cell) > 0.01);
    CHECK(run_scenario(load_scenario((dir / "reuse.yaml").string()), (dir / "reused").string(), quiet).status == RunStatus::completed);
}

namespace {
/// The "state_hash" entry of a summary.json text.
std::string hash(const std::string& summary_json) { return summary_json.substr(summary_json.find("\"state_hash\""), 32); }

/// The state hash of a run of `s` stopped at stop_s and resumed to its end, in dir/legs_<stop_s>.
std::string resumed_hash(const Scenario& s, const fs::path& dir, double stop_s)
{
    RunOptions quiet;
    quiet.progress = false;
    RunOptions o = quiet;
    o.stop_after_s = stop_s;
    const std::string legs = (dir / concat("legs_", stop_s)).string();
    REQUIRE(run_scenario(s, legs, o).status == RunStatus::interrupted);
    REQUIRE(resume_run(legs, quiet).status == RunStatus::completed);
    return hash(test::read_text_file(legs + "/summary.json"));
}
}  // namespace

TEST_CASE("a gate removed at its time lets a box empty, and a resume across the removal keeps the bits", "[scenario][walls][unit]")
{
    const std::string text = R"(dipper_scenario: 1
name: gate
seed: 4
threads: 1
time: {duration_s: 1.0}
planes:
  - {name: floor, point_m: [0, 0, -3], normal: [0, 0, 1], material: ground}
  - {name: x0, point_m: [0, 0, 0], normal: [1, 0, 0], material: steel}
  - {name: x1, point_m: [1, 0, 0], normal: [-1, 0, 0], material: steel}
  - {name: y0, point_m: [0, 0, 0], normal: [0, 1, 0], material: steel}
  - {name: y1, point_m: [0, 1, 0], normal: [0, -1, 0], material: steel}
  - {name: gate, point_m: [0, 0, 0], normal: [0, 0, 1], material: steel, removed_at_s: 0.3}
fills:
  - {mass_kg: 300, box: {min_m: [0, 0, 0], max_m: [1, 1, 0.8]}, sizes: [{radius_m: 0.1, mass_fraction: 1.0}]}
probes:
  regions:
    - {name: box, min_m: [0, 0, 0], max_m: [1, 1, 2]}
output: {vtk_interval_s: 0, csv_interval_s: 0.05}
)";
    const fs::path dir = fs::temp_directory_path() / "dipper_gate";
    fs::remove_all(dir);
    RunOptions quiet;
    quiet.progress = false;
    const Scenario s = parse_scenario(text, "gate.yaml", ".");
    REQUIRE(run_scenario(s, (dir / "whole").string(), quiet).status == RunStatus::completed);
    // the box's mass: all of it until the gate goes at 0.3 s, none 0.7 s later (a sphere at rest falls 2.4 m)
    const std::string csv = test::read_text_file((dir / "whole" / "probes.csv").string());
    const auto box_mass_at = [&](const std::string& time) {
        const std::size_t row = csv.find("\n" + time);
        REQUIRE(row != std::string::npos);
        const std::string line = csv.substr(row + 1, csv.find('\n', row + 1) - row - 1);
        std::stringstream cells(line);
        std::string cell;
        for (int c = 0; c < 8 + 3 * 6 + 1; ++c) std::getline(cells, cell, ',');  // 8 columns, 6 walls x 3, the region
        return std::stod(cell);
    };
    const double filled = box_mass_at("0.25");
    CHECK(filled > 280.0);
    CHECK(box_mass_at("0.3") == filled);
    const std::string summary = test::read_text_file((dir / "whole" / "summary.json").string());
    CHECK_THAT(summary, Contains("\"region_mass_kg\": {\"box\": 0}"));
    // stopped before and after the removal, resumed: the uninterrupted run's state
    for (const double stop : {0.2, 0.5}) CHECK(resumed_hash(s, dir, stop) == hash(summary));
    // not with rocks or the shovel: Bullet keeps its copy of the walls
    CHECK_THAT(test::scenario_error(std::regex_replace(text, std::regex("fills:\n.*\n"), "fills:\n  - {mass_kg: 300, box: {min_m: [0, 0, 0], max_m: [1, 1, 0.8]}, "
                                                                                     "sizes: [{radius_m: 0.1, mass_fraction: 0.5}], rocks: [{size_m: 0.3, mass_fraction: 0.5}]}\n")),
               Contains("planes[5].removed_at_s: walls are removed for spheres only"));
}

TEST_CASE("a run with a dynamic domain freezes its settled bed, and a resume keeps the bits", "[scenario][dynamic_domain][unit]")
{
    // a box of spheres that settles; saving a pile makes it a co-simulation, whose bodies the dynamic domain freezes
    const std::string text = R"(dipper_scenario: 1
name: frozen_bed
seed: 5
threads: 1
time: {duration_s: 3.0}
planes:
  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
  - {name: x0, point_m: [0, 0, 0], normal: [1, 0, 0], material: steel}
  - {name: x1, point_m: [1, 0, 0], normal: [-1, 0, 0], material: steel}
  - {name: y0, point_m: [0, 0, 0], normal: [0, 1, 0], material: steel}
  - {name: y1, point_m: [0, 1, 0], normal: [0, -1, 0], material: steel}
fills:
  - {mass_kg: 450, box: {min_m: [0, 0, 0], max_m: [1, 1, 0.8]}, sizes: [{radius_m: 0.1, mass_fraction: 1.0}]}
dynamic_domain: {margin_m: 0.3, rest_speed_m_per_s: 0.02, rest_time_s: 0.1}
output: {vtk_interval_s: 0, csv_interval_s: 0.05, pile_file: pile.txt}
)";
    const fs::path dir = fs::temp_directory_path() / "dipper_frozen_bed";
    fs::remove_all(dir);
    RunOptions quiet;
    quiet.progress = false;
    const Scenario s = parse_scenario(text, "frozen_bed.yaml", ".");
    REQUIRE(s.dynamic_domain.enabled);
    REQUIRE(run_scenario(s, (dir / "whole").string(), quiet).status == RunStatus::completed);
    // the last row: most of the bed frozen by the end (it comes to rest from 1.5 s on; a few spheres roll on between
    // the frictionless side walls, 18 of 29 frozen)
    const std::string csv = test::read_text_file((dir / "whole" / "probes.csv").string());
    const std::string header = csv.substr(0, csv.find('\n'));
    REQUIRE_THAT(header, Contains(",frozen_spheres,frozen_rocks,"));
    const std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
    std::stringstream cells(last), names(header);
    std::string cell, name, particles, frozen;
    while (std::getline(names, name, ',') && std::getline(cells, cell, ',')) {
        if (name == "particles") particles = cell;
        if (name == "frozen_spheres") frozen = cell;
    }
    REQUIRE(!particles.empty());
    REQUIRE(!frozen.empty());
    CHECK(2 * std::stoi(frozen) >= std::stoi(particles));
    // stopped while the bed freezes and after, resumed: the uninterrupted run's state
    const std::string summary = test::read_text_file((dir / "whole" / "summary.json").string());
    for (const double stop : {1.0, 2.0}) CHECK(resumed_hash(s, dir, stop) == hash(summary));  // before and after it began to freeze
    // a scenario that is no co-simulation has nothing for it to freeze
    CHECK_THAT(test::scenario_error(std::regex_replace(text, std::regex(", pile_file: pile.txt"), "")),
               Contains("dynamic_domain: it freezes bodies of the co-simulation"));
    CHECK_THAT(test::scenario_error(std::regex_replace(text, std::regex("margin_m: 0.3"), "margin_m: -1")),
               Contains("dynamic_domain.margin_m"));
    CHECK_THAT(test::scenario_error(std::regex_replace(text, std::regex("rest_time_s: 0.1"), "rest_time_s: 0")),
               Contains("dynamic_domain.rest_time_s") && Contains("a time > 0"));
    fs::remove_all(dir);
}
