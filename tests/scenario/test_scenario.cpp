// Scenario files: every class of input error names the file, line, column, key path, value and what
// was expected; the key table and docs/scenario.md agree; runs resume bit for bit from checkpoints;
// a diverging run stops with a diagnosis and keeps its files.
#include "core/errors.h"
#include "core/state_io.h"
#include "scenario/keys.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/helpers.h"
#include "scenario/sweep.h"

#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <utility>

using namespace dipper;
using namespace dipper::scenario;
namespace fs = std::filesystem;

namespace {

/// A small valid scenario: 60 spheres poured into a 1 m box with a moving mesh paddle.
std::string small_scenario(const std::string& extra = "", double duration_s = 0.3)
{
    return concat(R"(dipper_scenario: 1
name: small
seed: 7
threads: 1
time:
  duration_s: )", duration_s, R"(
planes:
  - {name: floor, point_m: [0, 0, 0], normal: [0, 0, 1], material: ground}
  - {name: wall_x0, point_m: [0, 0, 0], normal: [1, 0, 0], material: bucket}
  - {name: wall_x1, point_m: [1, 0, 0], normal: [-1, 0, 0], material: bucket}
  - {name: wall_y0, point_m: [0, 0, 0], normal: [0, 1, 0], material: bucket}
  - {name: wall_y1, point_m: [0, 1, 0], normal: [0, -1, 0], material: bucket}
meshes:
  - name: paddle
    file: )", DIPPER_SOURCE_DIR, R"(/meshes/generated/ground.stl
    material: bucket
    scale: 0.02
    translate_m: [0.5, 0.5, 0.6]
    motion: {velocity_m_per_s: [0, 0, -0.3], angular_velocity_rad_per_s: [0, 0, 2.0], pivot_m: [0.5, 0.5, 0.6]}
fills:
  - mass_kg: 300
    box: {min_m: [0, 0, 0], max_m: [1, 1, 0.5]}
    sizes: [{radius_m: 0.05, mass_fraction: 0.5}, {radius_m: 0.04, mass_fraction: 0.5}]
pours:
  - mass_kg: 100
    rate_kg_per_s: 1000
    velocity_m_per_s: [0, 0, -1]
    box: {min_m: [0, 0, 0.8], max_m: [1, 1, 1.2]}
    sizes: [{radius_m: 0.05, mass_fraction: 1.0}]
probes:
  regions: [{name: low, min_m: [0, 0, 0], max_m: [1, 1, 0.3]}]
output:
  vtk_interval_s: 0.1
  csv_interval_s: 0.01
)", extra);
}

std::string error_of(const std::string& text) { return test::scenario_error(text); }

std::string read_file(const std::string& path) { return test::read_text_file(path); }

std::string summary_value(const std::string& dir, const std::string& key)
{
    const std::string text = read_file(dir + "/summary.json");
    const std::regex re("\"" + key + "\": \"?([^\",\n]*)");
    std::smatch m;
    REQUIRE(std::regex_search(text, m, re));
    return m[1];
}

/// probes.csv without its last two columns (wall-clock seconds per step and in all, which no two runs share).
std::string probes_without_clock(const std::string& dir)
{
    std::istringstream in(read_file(dir + "/probes.csv"));
    std::string line, out;
    while (std::getline(in, line)) {
        line = line.substr(0, line.rfind(','));
        out += line.substr(0, line.rfind(',')) + "\n";
    }
    return out;
}

RunOptions quiet()
{
    RunOptions o;
    o.progress = false;
    return o;
}

}  // namespace

TEST_CASE("a valid scenario parses with its values and the table's defaults", "[scenario]")
{
    const Scenario s = parse_scenario(small_scenario(), "small.yaml", ".");
    CHECK(s.name == "small");
    CHECK(s.seed == 7);
    CHECK(s.duration_s == 0.3);
    CHECK(s.step_s == 0.0);                       // default
    CHECK(s.gravity_m_per_s2 == Vec3{0, 0, -9.81});  // default
    CHECK(s.planes.size() == 5);
    REQUIRE(s.meshes.size() == 1);
    REQUIRE(s.meshes[0].motion);
    CHECK(s.meshes[0].motion->angular_velocity_rad_per_s == Vec3{0, 0, 2.0});
    CHECK(s.fills[0].material == "ore");          // default
    CHECK(s.fills[0].sizes.classes.size() == 2);
    CHECK(s.output.checkpoint_interval_s == 0.0);
    CHECK(s.output.progress_interval_s == 10.0);
    CHECK(s.materials.size() == dem::MaterialTable::aitik_copper_ore().size());
}

TEST_CASE("every class of scenario error names file, line, column, key, value and expectation", "[scenario]")
{
    // unknown key: a typo is an error that lists the valid keys of its map
    std::string e = error_of(small_scenario() + "outptu: {}\n");
    CHECK_THAT(e, Catch::Contains("case.yaml:") && Catch::Contains("unknown key 'outptu'") &&
                      Catch::Contains("valid keys are: dipper_scenario, name, seed"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("duration_s"), "duration"));
    CHECK_THAT(e, Catch::Contains("case.yaml:6:3: unknown key 'time.duration'") && Catch::Contains("duration_s, step_s"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("radius_m: 0.04"), "radius: 0.04"));
    CHECK_THAT(e, Catch::Contains("unknown key 'fills[0].sizes[1].radius'"));

    // wrong type, with the value received
    e = error_of(std::regex_replace(small_scenario(), std::regex("duration_s: 0.3"), "duration_s: fast"));
    CHECK_THAT(e, Catch::Contains("case.yaml:6:15: time.duration_s: got \"fast\"; expected a finite number"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("normal: \\[0, 0, 1\\]"), "normal: [0, 1]"));
    CHECK_THAT(e, Catch::Contains("case.yaml:8:47: planes[0].normal: got [0, 1]; expected a list of 3 finite numbers"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("seed: 7"), "seed: 7.5"));
    CHECK_THAT(e, Catch::Contains("case.yaml:3:7: seed: got \"7.5\"; expected an integer"));

    // missing required key
    e = error_of(std::regex_replace(small_scenario(), std::regex("    rate_kg_per_s: 1000\n"), ""));
    CHECK_THAT(e, Catch::Contains("pours[0].rate_kg_per_s: got nothing; expected a number (this key is required)"));
    e = error_of("dipper_scenario: 1\nfills: []\n");
    CHECK_THAT(e, Catch::Contains("time: got nothing; expected a map (this key is required)"));

    // out-of-range values
    e = error_of(std::regex_replace(small_scenario(), std::regex("mass_kg: 300"), "mass_kg: -300"));
    CHECK_THAT(e, Catch::Contains("mass_kg must be > 0 and finite; got -300") && Catch::Contains("fills[0].mass_kg"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("mass_fraction: 1.0"), "mass_fraction: 0.9"));
    CHECK_THAT(e, Catch::Contains("pours[0].sizes"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("max_m: \\[1, 1, 0.5\\]"), "max_m: [1, 1, -0.5]"));
    CHECK_THAT(e, Catch::Contains("fills[0].box.max_m: got [1, 1, -0.5]; expected each coordinate above min_m"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("    rate_kg_per_s: 1000\n"), "    rate_kg_per_s: 1000\n    start_s: -2\n"));
    CHECK_THAT(e, Catch::Contains("pours[0].start_s") && Catch::Contains("-2"));
    // only pours, the first at 0.5 s: no particle to derive the default step from
    const std::string late_pour = std::regex_replace(
        std::regex_replace(small_scenario(), std::regex("fills:\n  - mass_kg: 300\n    box: \\{min_m: \\[0, 0, 0\\], max_m: \\[1, 1, 0.5\\]\\}\n    sizes: \\[\\{radius_m: 0.05, mass_fraction: 0.5\\}, \\{radius_m: 0.04, mass_fraction: 0.5\\}\\]\n"), ""),
        std::regex("    rate_kg_per_s: 1000\n"), "    rate_kg_per_s: 1000\n    start_s: 0.5\n");
    REQUIRE(late_pour.find("fills:") == std::string::npos);
    CHECK_THAT(error_of(late_pour), Catch::Contains("first pour starts at t = 0.5 s") && Catch::Contains("time.step_s"));
    // a mass no box or memory can hold: refused as it is read, before any particle is made (1e12 kg of 40-50 mm
    // spheres would be 10^15 of them; before, the fill died in the allocator with "std::bad_alloc")
    e = error_of(std::regex_replace(small_scenario(), std::regex("mass_kg: 300"), "mass_kg: 1e12"));
    CHECK_THAT(e, Catch::Contains("fills[0].mass_kg: 1e+12 kg at") && Catch::Contains("more than the box of 0.5 m3 holds") &&
                      Catch::Contains("make the box larger or the mass smaller"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("radius_m: 0.05"), "radius_m: 1e-6"));
    CHECK_THAT(e, Catch::Contains("fills[0].mass_kg: got 300; expected a mass of at most 100000000 particles"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("mass_kg: 300"), "mass_kg: 0.01"));
    CHECK_THAT(e, Catch::Contains("fills[0].mass_kg: got 0.01; expected a mass of at least one particle"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("mass_kg: 100\n"), "mass_kg: 1e12\n"));
    CHECK_THAT(e, Catch::Contains("pours[0].mass_kg: got 1e+12; expected a mass of at most 100000000 particles"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("dipper_scenario: 1"), "dipper_scenario: 2"));
    CHECK_THAT(e, Catch::Contains("case.yaml:1:18: dipper_scenario: got 2; expected 1"));

    // names that do not exist, or of the wrong kind
    e = error_of(std::regex_replace(small_scenario(), std::regex("material: ground"), "material: gravel"));
    CHECK_THAT(e, Catch::Contains("planes[0].material: got \"gravel\"; expected one of the surface materials: ground, bucket"));
    e = error_of(small_scenario() + "fills:\n  - {material: bucket, mass_kg: 1, box: {min_m: [0,0,0], max_m: [1,1,1]}, sizes: [{radius_m: 0.1, mass_fraction: 1}]}\n");
    CHECK_THAT(e, Catch::Contains("case.yaml:35:1: key 'fills' appears twice (first on line 20)"));
    e = error_of(std::regex_replace(small_scenario(), std::regex("name: wall_y1"), "name: wall_y0"));
    CHECK_THAT(e, Catch::Contains("wall name 'wall_y0' is used twice"));

    // not YAML at all
    e = error_of("dipper_scenario: 1\ntime: {duration_s: 1\n");
    CHECK_THAT(e, Catch::Contains("case.yaml:") && Catch::Contains("not valid YAML"));
    e = error_of("- just\n- a list\n");
    CHECK_THAT(e, Catch::Contains("the file: got") && Catch::Contains("expected a map of keys"));

    // pair coefficients for a material that does not exist
    e = error_of(small_scenario() + "materials:\n  pairs:\n    - {materials: [ore, granite], friction: 0.5}\n");
    CHECK_THAT(e, Catch::Contains("materials.pairs[0].materials") && Catch::Contains("granite"));

    // a form of rolling resistance that dipper does not have
    e = error_of(small_scenario() + "materials:\n  rolling_resistance: constant\n");
    CHECK_THAT(e, Catch::Contains("materials.rolling_resistance: got \"constant\"; expected relative_spring or own_spin"));
    e = error_of(small_scenario() + "coupling:\n  rock_exchange: sometimes\n");
    CHECK_THAT(e, Catch::Contains("coupling.rock_exchange: got \"sometimes\"; expected coupling_step or dem_step"));
}

TEST_CASE("a mesh file that cannot be read names the scenario entry", "[scenario]")
{
    const Scenario s = parse_scenario(std::regex_replace(small_scenario(), std::regex("ground.stl"), "no_such.stl"), "case.yaml", ".");
    try {
        build_world(s);
        FAIL("no error");
    } catch (const InputError& e) {
        CHECK_THAT(std::string(e.what()), Catch::Contains("case.yaml:15:11: meshes[0].file") && Catch::Contains("no_such.stl"));
    }
}

TEST_CASE("materials from the file extend the preset, missing pair coefficients are named", "[scenario]")
{
    const std::string extra = R"(materials:
  add:
    - {name: liner, surface: true, density_kg_per_m3: 7800, youngs_modulus_Pa: 2.0e11, poisson_ratio: 0.3}
  pairs:
    - {materials: [ore, ground], friction: 0.4}
)";
    const Scenario s = parse_scenario(small_scenario(extra), "case.yaml", ".");
    const auto ore = s.materials.index_of("ore"), ground = s.materials.index_of("ground");
    CHECK(s.materials.pair(ore, ground).friction == 0.4);
    // the other coefficients of the pair keep the preset's values (Table 2: ground rolling friction 0.3)
    CHECK(s.materials.pair(ore, ground).rolling_friction ==
          dem::MaterialTable::aitik_copper_ore().pair(ore, ground).rolling_friction);
    CHECK_FALSE(s.materials.has_pair(ore, s.materials.index_of("liner")));

    const Scenario t = parse_scenario(std::regex_replace(small_scenario(extra), std::regex("material: ground"), "material: liner"),
                                      "case.yaml", ".");
    CHECK_THROWS_WITH(check_pairs(t), Catch::Contains("materials 'ore' and 'liner' meet but have no pair coefficients"));
}

TEST_CASE("fills keep clear of planes and of mesh walls inside their box", "[scenario]")
{
    // the paddle moved into the fill box and a sloping plane cutting through it
    std::string text = std::regex_replace(small_scenario(), std::regex("translate_m: \\[0.5, 0.5, 0.6\\]"), "translate_m: [0.5, 0.5, 0.25]");
    text = std::regex_replace(text, std::regex("  - \\{name: wall_y1"),
                              "  - {name: slope, point_m: [0, 0, 0.3], normal: [0, 1, 1], material: bucket}\n  - {name: wall_y1");
    text = std::regex_replace(text, std::regex("mass_kg: 300"), "mass_kg: 150");
    const Scenario s = parse_scenario(text, "case.yaml", ".");
    const auto world = build_world(s);
    build_particles(s, *world);
    const dem::ParticleStore& p = world->particles();
    REQUIRE(p.size() > 100);
    int near_paddle = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3 c = p.position_m[i];
        const double r = p.radius_m[i];
        for (std::size_t w = 0; w < world->wall_count(); ++w) {
            const int id = static_cast<int>(w);
            if (world->is_mesh(id)) {
                const double d = world->mesh_wall(id).mesh().distance_m(c);  // body frame = world frame at t = 0
                CHECK(d >= r);
                near_paddle += d < 2.0 * r;
            } else {
                const dem::PlaneWall& plane = world->plane_wall(id);
                CHECK(dot(c - plane.point_m, plane.normal) >= r);
            }
        }
    }
    CHECK(near_paddle > 0);  // the paddle sits inside the bed, so spheres do come close to it
}

TEST_CASE("docs/scenario.md lists exactly the keys the parser reads, with their types and defaults", "[scenario]")
{
    const std::string doc = read_file(std::string(DIPPER_SOURCE_DIR) + "/docs/scenario.md");
    REQUIRE_FALSE(doc.empty());
    // table rows: | `path` | type | `default` | meaning |
    const std::regex row(R"(\| `([^`]+)` \| (\w+) \| `([^`]*)` \| )");
    std::vector<std::tuple<std::string, std::string, std::string>> documented;
    for (auto it = std::sregex_iterator(doc.begin(), doc.end(), row); it != std::sregex_iterator(); ++it)
        documented.emplace_back((*it)[1], (*it)[2], (*it)[3]);
    const auto& keys = scenario_keys();
    REQUIRE(documented.size() == keys.size());
    for (std::size_t k = 0; k < keys.size(); ++k) {
        INFO("key " << keys[k].path);
        CHECK(std::get<0>(documented[k]) == keys[k].path);
        CHECK(std::get<1>(documented[k]) == keys[k].type);
        CHECK(std::get<2>(documented[k]) == keys[k].default_value);
    }
}

TEST_CASE("library messages reach the user with the scenario keys of the settings they name", "[scenario][unit]")
{
    // every setting the library names is set by a key that exists, and the message names that key instead
    for (const auto& [setting, key] : library_settings_as_keys()) {
        INFO(setting << " -> " << key);
        CHECK(find_key(key) != nullptr);
        const std::string m = in_scenario_keys("reduce " + setting + " or " + setting + ".");
        CHECK(m == "reduce " + key + " or " + key + ".");
    }
    CHECK(in_scenario_keys("the runaway guard (CouplingSettings::runaway_guard) or fewer DEM steps per rigid-body step "
                           "(CouplingSettings::substeps); reduce WorldSettings::step_s") ==
          "the runaway guard (coupling.runaway_guard) or fewer DEM steps per rigid-body step (coupling.substeps); reduce time.step_s");
}

TEST_CASE("a run stopped at a checkpoint and resumed ends bit for bit as the uninterrupted run", "[scenario]")
{
    const fs::path base = fs::temp_directory_path() / "dipper_test_resume";
    fs::remove_all(base);
    const Scenario s = parse_scenario(small_scenario(), "small.yaml", ".");

    const RunResult whole = run_scenario(s, (base / "whole").string(), quiet());
    REQUIRE(whole.status == RunStatus::completed);

    RunOptions stop = quiet();
    stop.stop_after_s = 0.137;  // mid-pour, mid-interval, paddle moving
    const RunResult first = run_scenario(s, (base / "parts").string(), stop);
    REQUIRE(first.status == RunStatus::interrupted);
    CHECK(first.time_s < 0.3);
    CHECK(summary_value((base / "parts").string(), "status") == "interrupted");
    const RunResult rest = resume_run((base / "parts").string(), quiet());
    REQUIRE(rest.status == RunStatus::completed);

    CHECK(rest.steps == whole.steps);
    CHECK(summary_value((base / "parts").string(), "state_hash") == summary_value((base / "whole").string(), "state_hash"));
    CHECK(probes_without_clock((base / "parts").string()) == probes_without_clock((base / "whole").string()));
    CHECK(read_file((base / "parts" / "particles.pvd").string()) == read_file((base / "whole" / "particles.pvd").string()));
    CHECK(read_file((base / "parts" / "particles_000003.vtp").string()) ==
          read_file((base / "whole" / "particles_000003.vtp").string()));
    fs::remove_all(base);
}

TEST_CASE("a run that ended is resumed with a later end (--until) and ends bit for bit as the longer run", "[scenario]")
{
    // a pile saved while still creeping is run on to rest: only time.duration_s moves, so the two legs end where
    // one run with the later end from the start ends, and the later checkpoints carry the new end
    const fs::path base = fs::temp_directory_path() / "dipper_test_until";
    fs::remove_all(base);
    const Scenario longer = parse_scenario(small_scenario(), "small.yaml", ".");
    REQUIRE(longer.duration_s == 0.3);
    const Scenario shorter = parse_scenario(std::regex_replace(small_scenario(), std::regex("duration_s: 0.3"), "duration_s: 0.15"),
                                            "small.yaml", ".");
    const RunResult whole = run_scenario(longer, (base / "whole").string(), quiet());
    REQUIRE(whole.status == RunStatus::completed);
    REQUIRE(run_scenario(shorter, (base / "legs").string(), quiet()).status == RunStatus::completed);
    CHECK(summary_value((base / "legs").string(), "state_hash") != summary_value((base / "whole").string(), "state_hash"));

    RunOptions later = quiet();
    later.until_s = "0.1";  // before the end: refused, naming the end
    CHECK_THROWS_WITH(resume_run((base / "legs").string(), later),
                      Catch::Contains("--until 0.1 s: the run ends at time.duration_s = 0.15 s already"));
    later.until_s = "soon";
    CHECK_THROWS_WITH(resume_run((base / "legs").string(), later), Catch::Contains("--until needs a time in seconds; got 'soon'"));
    later.until_s = "0.3";
    const RunResult rest = resume_run((base / "legs").string(), later);
    REQUIRE(rest.status == RunStatus::completed);
    CHECK(rest.steps == whole.steps);
    CHECK(summary_value((base / "legs").string(), "state_hash") == summary_value((base / "whole").string(), "state_hash"));
    CHECK(read_file((base / "legs" / "scenario.yaml").string()).find("--until 0.3") != std::string::npos);
    // the checkpoint at the new end holds the new end: a plain resume finds the run ended at 0.3 s
    const RunResult again = resume_run((base / "legs").string(), quiet());
    CHECK(again.steps == whole.steps);
    CHECK_THAT(again.message, Catch::Contains("already ended"));
    CHECK(summary_value((base / "legs").string(), "duration_s") == "0.3");
    fs::remove_all(base);
}

TEST_CASE("resisting each sphere's own spin, a run resumed from a checkpoint ends bit for bit", "[scenario]")
{
    // the spin resistance is summed anew at each step from the contacts; the torque it adds is in the checkpoint
    const fs::path base = fs::temp_directory_path() / "dipper_test_resume_own_spin";
    fs::remove_all(base);
    const Scenario s = parse_scenario(small_scenario("materials: {rolling_resistance: own_spin}\n"), "small.yaml", ".");
    const RunResult whole = run_scenario(s, (base / "whole").string(), quiet());
    REQUIRE(whole.status == RunStatus::completed);
    RunOptions stop = quiet();
    stop.stop_after_s = 0.137;
    REQUIRE(run_scenario(s, (base / "parts").string(), stop).status == RunStatus::interrupted);
    REQUIRE(resume_run((base / "parts").string(), quiet()).status == RunStatus::completed);
    CHECK(summary_value((base / "parts").string(), "state_hash") == summary_value((base / "whole").string(), "state_hash"));
    // and the form changes the run: the same scenario with the relative spring ends elsewhere
    const RunResult spring = run_scenario(parse_scenario(small_scenario(), "small.yaml", "."), (base / "spring").string(), quiet());
    REQUIRE(spring.status == RunStatus::completed);
    CHECK(summary_value((base / "spring").string(), "state_hash") != summary_value((base / "whole").string(), "state_hash"));
    fs::remove_all(base);
}

TEST_CASE("a truncated or corrupt checkpoint is refused and the previous one is named", "[scenario]")
{
    const fs::path base = fs::temp_directory_path() / "dipper_test_corrupt";
    fs::remove_all(base);
    const Scenario s = parse_scenario(small_scenario("", 0.2), "small.yaml", ".");
    RunOptions stop = quiet();
    stop.stop_after_s = 0.05;
    REQUIRE(run_scenario(s, (base / "a").string(), stop).status == RunStatus::interrupted);
    stop.stop_after_s = 0.1;
    REQUIRE(resume_run((base / "a").string(), stop).status == RunStatus::interrupted);
    const fs::path cp = base / "a" / "checkpoint.bin", prev = base / "a" / "checkpoint.prev.bin";
    REQUIRE(fs::exists(prev));

    const auto size = fs::file_size(cp);
    fs::copy_file(cp, base / "good.bin");
    fs::resize_file(cp, size / 2);  // truncated
    CHECK_THROWS_WITH(resume_run((base / "a").string(), quiet()),
                      Catch::Contains("checkpoint.bin' is corrupt or truncated") &&
                          Catch::Contains("the previous checkpoint is kept: dipper resume") && Catch::Contains("checkpoint.prev.bin"));
    fs::copy_file(base / "good.bin", cp, fs::copy_options::overwrite_existing);
    {
        std::fstream f(cp, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(static_cast<std::streamoff>(size / 3));
        f.put('\x5a');  // one flipped byte
    }
    CHECK_THROWS_WITH(resume_run((base / "a").string(), quiet()), Catch::Contains("corrupt or truncated"));
    {
        std::ofstream f(cp, std::ios::binary | std::ios::trunc);
        f << "something else entirely\n";
    }
    CHECK_THROWS_WITH(resume_run((base / "a").string(), quiet()),
                      Catch::Contains("is not a state file of this kind") && Catch::Contains("dipper-checkpoint 9"));
    // the previous checkpoint still resumes
    const RunResult r = resume_run((base / "a").string(), quiet(), prev.string());
    CHECK(r.status == RunStatus::completed);
    fs::remove_all(base);
}

TEST_CASE("the progress line's rate follows the last minute, not the average since the start", "[scenario]")
{
    CHECK(progress_rate(0.0, 40.0, 10.0, 10.0) == 40.0);  // the first line: its own rate
    // a run that slowed from 40 to 4 steps/s an hour in: each 10 s line moves the rate a sixth of the way, so
    // after 10 minutes it is within 0.1 % of 4 steps/s (the average since the start would still say about 35)
    double rate = 40.0;
    for (int line = 0; line < 60; ++line) rate = progress_rate(rate, 4.0, 10.0, 3600.0 + 10.0 * line);
    CHECK(rate == Approx(4.0 + 36.0 * std::pow(5.0 / 6.0, 60)).epsilon(1e-12));
    CHECK(rate < 4.004);
    // early in a run the span is the time since the start: the average of the lines so far
    CHECK(progress_rate(40.0, 10.0, 10.0, 20.0) == Approx(25.0).epsilon(1e-12));
    // a line longer than a minute takes its own rate
    CHECK(progress_rate(40.0, 10.0, 120.0, 3600.0) == 10.0);
    CHECK(progress_rate(40.0, 10.0, 0.0, 3600.0) == 40.0);  // a last line right after the one before
}

TEST_CASE("a run of more than 10^9 steps is refused with what sets the step", "[scenario]")
{
    // C_norm 1e30 instead of 0.05 (a typo in an exponent) makes the default step about 1e-20 s: 0.3 s would be
    // 10^19 steps, and the run went on for ever with an ETA of millions of hours as the only sign
    const fs::path dir = fs::temp_directory_path() / "dipper_test_step_count";
    fs::remove_all(dir);
    const std::string stiff = small_scenario() + "materials:\n  pairs:\n    - {materials: [ore, ore], normal_stiffness_scale: 1e30}\n";
    CHECK_THROWS_WITH(run_scenario(parse_scenario(stiff, "stiff.yaml", "."), dir.string(), quiet()),
                      Catch::Contains("stiff.yaml: 0.3 s of simulated time is") && Catch::Contains("steps at the default step") &&
                          Catch::Contains("set by particle") && Catch::Contains("radius 0.04 m, material 'ore'") &&
                          Catch::Contains("a run takes at most 1000000000 steps"));
    // a step given in the file is named as such
    const std::string tiny = std::regex_replace(small_scenario(), std::regex("duration_s: 0.3"), "duration_s: 0.3\n  step_s: 1e-12");
    CHECK_THROWS_WITH(run_scenario(parse_scenario(tiny, "tiny.yaml", "."), dir.string(), quiet()),
                      Catch::Contains("3e+11 steps at time.step_s = 1e-12 s"));
    fs::remove_all(dir);
}

TEST_CASE("a diverging run stops with a diagnosis and keeps what it wrote", "[scenario]")
{
    // the paddle driven down at 40 m/s into the bed: overlaps beyond half a radius within a few steps
    const fs::path dir = fs::temp_directory_path() / "dipper_test_diverge";
    fs::remove_all(dir);
    const std::string text = std::regex_replace(small_scenario(), std::regex("velocity_m_per_s: \\[0, 0, -0.3\\]"),
                                                "velocity_m_per_s: [0, 0, -40]");
    const RunResult r = run_scenario(parse_scenario(text, "fast.yaml", "."), dir.string(), quiet());
    REQUIRE(r.status == RunStatus::diverged);
    CHECK(exit_code(r) == 3);
    CHECK_THAT(r.message, Catch::Contains("step ") && Catch::Contains("particle") && Catch::Contains("overlap") &&
                              Catch::Contains("of the smaller radius (limit 0.5)") && Catch::Contains("reduce time.step_s, e.g. to"));
    CHECK(summary_value(dir.string(), "status") == "diverged");
    CHECK(read_file((dir / "summary.json").string()).find("nan") == std::string::npos);  // JSON has no NaN: null
    CHECK(fs::exists(dir / "particles_000000.vtp"));
    CHECK(fs::file_size(dir / "probes.csv") > 100);
    fs::remove_all(dir);
}

TEST_CASE("state files refuse what does not fit the reader", "[scenario]")
{
    const fs::path path = fs::temp_directory_path() / "dipper_state_io.bin";
    StateWriter w;
    w.tag("section");
    w.array(std::vector<double>{1.0, 2.0});
    w.save(path.string(), "dipper-test 1");
    {
        StateReader r(path.string(), "dipper-test 1");
        r.tag("section");
        std::vector<double> v;
        r.array(v);
        CHECK(v == std::vector<double>{1.0, 2.0});
        r.finish();
    }
    {
        StateReader r(path.string(), "dipper-test 1");
        CHECK_THROWS_WITH(r.tag("other"), Catch::Contains("expected section 'other', found 'section'"));
    }
    CHECK_THROWS_WITH(StateReader(path.string(), "dipper-test 2"), Catch::Contains("is not a state file of this kind"));
    CHECK_THROWS_WITH(StateReader((path.string() + ".missing"), "dipper-test 1"), Catch::Contains("cannot open state file"));
    fs::remove(path);
}

namespace {

/// A class with a part of its own, its checkpoint fields listed once (core/state_io.h).
struct Part {
    std::vector<std::uint32_t> ids;
    void write_state(StateWriter& out) const { out(ids); }
    void read_state(StateReader& in) { in(ids); }
};
struct Listed {
    double time_s = 0.0;
    std::vector<Vec3> positions;
    std::string name;
    bool started = false;
    std::vector<Part> parts;

    template <class IO, class Self>
    static void state_fields(IO& io, Self& s)
    {
        io.tag("listed");
        io(s.time_s, s.positions, s.name, s.started);
        io.count(s.parts.size(), "parts");
        for (auto& p : s.parts) io.object(p);
    }
};

}  // namespace

TEST_CASE("a class's checkpoint fields, listed once, are written and read back as they were", "[scenario]")
{
    const fs::path path = fs::temp_directory_path() / "dipper_state_fields.bin";
    Listed a;
    a.time_s = 0.1 + 0.2;  // not a round number: the bits must survive
    a.positions = {{1.0, -2.0, 3.5}, {0.0, 1e-300, -0.0}};
    a.name = "dipper";
    a.started = true;
    a.parts = {Part{{7, 8, 9}}, Part{{}}};
    StateWriter w;
    Listed::state_fields(w, std::as_const(a));
    w.save(path.string(), "dipper-test 1");

    Listed b;
    b.parts.resize(2);
    {
        StateReader r(path.string(), "dipper-test 1");
        Listed::state_fields(r, b);
        r.finish();
    }
    CHECK(b.time_s == a.time_s);
    REQUIRE(b.positions.size() == 2);
    CHECK(std::memcmp(b.positions.data(), a.positions.data(), 2 * sizeof(Vec3)) == 0);
    CHECK(b.name == "dipper");
    CHECK(b.started);
    CHECK(b.parts[0].ids == std::vector<std::uint32_t>{7, 8, 9});
    CHECK(b.parts[1].ids.empty());

    // a reader built with another number of parts is refused with both counts
    Listed c;
    c.parts.resize(3);
    StateReader r(path.string(), "dipper-test 1");
    CHECK_THROWS_WITH(Listed::state_fields(r, c), Catch::Contains("the state has 2 parts, the world built from its input 3"));
    fs::remove(path);
}

TEST_CASE("sweep files: variants by values and ranges, and errors that name the key", "[scenario]")
{
    const fs::path dir = fs::temp_directory_path() / "dipper_test_sweep";
    fs::remove_all(dir);
    fs::create_directories(dir);
    fs::copy_file(std::string(DIPPER_SOURCE_DIR) + "/tests/data/scenarios/sweep_base.yaml", dir / "base.yaml");
    const auto sweep_error = [&](const std::string& text) -> std::string {
        std::ofstream(dir / "s.yaml") << text;
        try {
            load_sweep((dir / "s.yaml").string());
        } catch (const InputError& e) {
            return e.what();
        }
        return "";
    };
    CHECK(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: time.step_s, from: 1.0e-5, to: 2.0e-5, step: 5.0e-6}\n")
              .empty());
    Sweep s = load_sweep((dir / "s.yaml").string());
    REQUIRE(s.variants().size() == 3);
    CHECK(s.variants()[2][0] == "2e-05");
    CHECK(s.variant_scenario(1).step_s == 1.5e-5);

    std::ofstream(dir / "s.yaml") << "dipper_sweep: 1\nbase: base.yaml\nparameters:\n"
                                     "  - {key: materials.particle_density_kg_per_m3, values: [3000, 3700]}\n"
                                     "  - {key: \"planes[0].normal\", values: [[0, 0, 1], [0, 0.1, 1]]}\n";
    s = load_sweep((dir / "s.yaml").string());
    REQUIRE(s.variants().size() == 4);
    const Scenario v3 = s.variant_scenario(3);
    CHECK(v3.materials.material(v3.materials.index_of("ore")).density_kg_per_m3 == 3700.0);
    CHECK(v3.planes[0].normal.y > 0.09);
    CHECK(v3.fills[0].mass_kg == 30.0);  // the rest as in the base

    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: time.stepsize, values: [1]}\n"),
               Catch::Contains("s.yaml:4:") && Catch::Contains("key 'time.stepsize' is not a scenario key"));
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: time.step_s, value: [1]}\n"),
               Catch::Contains("unknown key 'parameters[0].value'; valid keys are: key, values, from, to, step"));
    // the count of variants is checked before they are listed: three ranges of 10,000 are 10^12 (it took minutes,
    // listing them, before it said so)
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: seed, from: 1, to: 10000, step: 1}\n"
                           "  - {key: time.duration_s, from: 1, to: 10000, step: 1}\n  - {key: gravity_m_per_s2, from: 1, to: 10000, step: 1}\n"),
               Catch::Contains("1e+12 variants, 10000 (seed) x 10000 (time.duration_s) x 10000 (gravity_m_per_s2); at most 10000"));
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: time.step_s, from: 2, to: 1, step: 1}\n"),
               Catch::Contains("expected from <= to and step > 0; got from 2, to 1, step 1"));
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: time.duration_s, values: [-1]}\n"),
               Catch::Contains("variant 0") && Catch::Contains("duration_s must be > 0 and finite; got -1"));
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: missing.yaml\nparameters:\n  - {key: seed, values: [1]}\n"),
               Catch::Contains("cannot open base scenario") && Catch::Contains("missing.yaml"));
    CHECK_THAT(sweep_error("dipper_sweep: 1\nbase: base.yaml\nparameters:\n  - {key: \"meshes[0].scale\", values: [2]}\n"),
               Catch::Contains("has no list 'meshes'"));
    fs::remove_all(dir);
}
