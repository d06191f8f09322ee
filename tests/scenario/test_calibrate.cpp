// The repose calibration: its search against closed-form angle functions (where the answer is known),
// and one small real run that writes the calibration table.
#include "core/errors.h"
#include "scenario/calibrate.h"
#include "scenario/helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace dipper;
using namespace dipper::scenario;
namespace fs = std::filesystem;

TEST_CASE("the repose search finds the sliding friction that hits the target for each rolling friction", "[scenario][calibrate]")
{
    // a closed form that rises with both frictions: the pairs on the line 20 mu + 60 mu_r = 19.7 all hit 34.7
    const auto linear = [](double mu, double mur) { return 15.0 + 20.0 * mu + 60.0 * mur; };
    ReposeSearch s;
    s.tolerance_deg = 0.2;
    const ReposeCalibration c = search_repose(linear, s);
    REQUIRE(c.matches.size() == 3);
    for (const ReposeRun& r : c.matches) {
        CHECK(std::abs(r.angle_deg - 34.7) <= 0.2);
        CHECK(r.friction == Approx((19.7 - 60.0 * r.rolling_friction) / 20.0).margin(0.2 / 20.0));
    }
    CHECK(c.notes.empty());
    // on a line regula falsi lands on the answer with its first step: 3 runs per rolling friction
    CHECK(c.runs.size() == 9);

    // a saturating angle: converges within the run budget; a rolling friction too high cannot come down
    const auto saturating = [](double mu, double mur) { return 45.0 * (1.0 - std::exp(-2.5 * mu)) + 80.0 * mur; };
    s.rolling_frictions = {0.05, 0.3};
    s.max_runs_per_rolling = 8;
    s.tolerance_deg = 0.5;
    const ReposeCalibration d = search_repose(saturating, s);
    REQUIRE(d.matches.size() == 1);
    CHECK(std::abs(d.matches[0].angle_deg - 34.7) <= 0.5);
    CHECK(d.matches[0].rolling_friction == 0.05);
    REQUIRE(d.notes.size() == 1);
    CHECK_THAT(d.notes[0], Catch::Contains("rolling friction 0.3") && Catch::Contains("is not in between"));

    s.friction_max = s.friction_min;
    CHECK_THROWS_WITH(search_repose(saturating, s), Catch::Contains("friction range"));
}

TEST_CASE("dipper's repose calibration runs the scenario and writes its table", "[scenario][calibrate]")
{
    const std::string dir = (fs::temp_directory_path() / "dipper_calibrate_repose").string();
    fs::remove_all(dir);
    ReposeSearch s;
    s.rolling_frictions = {0.05};
    s.max_runs_per_rolling = 2;  // the two ends of the friction range only: 2 runs
    s.target_deg = 25.0;
    s.tolerance_deg = 30.0;      // any angle hits: this checks the plumbing, the search is checked above
    RunOptions o;
    o.progress = false;
    o.threads = 1;
    const ReposeCalibration c =
        calibrate_repose(std::string(DIPPER_SOURCE_DIR) + "/tests/data/scenarios/repose_small.yaml", "ore", "ore", s, dir, o);
    REQUIRE(c.runs.size() == 2);  // both ends of the friction range are run first
    REQUIRE(c.matches.size() == 1);
    for (const ReposeRun& r : c.runs) {
        CHECK(r.angle_deg > 5.0);
        CHECK(r.angle_deg < 60.0);
    }
    CHECK(c.runs[0].friction == 0.2);
    CHECK(c.runs[1].friction == 1.2);
    CHECK_THAT(test::read_text_file(dir + "/calibration.csv"), Catch::StartsWith("run,friction,rolling_friction,repose_angle_deg\n0,0.2,0.05,"));
    CHECK(fs::exists(dir + "/run_000/summary.json"));
    CHECK(fs::exists(dir + "/run_001/summary.json"));

    CHECK_THROWS_WITH(calibrate_repose(std::string(DIPPER_SOURCE_DIR) + "/tests/data/scenarios/repose_small.yaml", "ore", "rock", s, dir, o),
                      Catch::Contains("materials.pairs has no entry for ore-rock"));
    fs::remove_all(dir);
}
