// Measured wear: reading measurement files, comparison statistics, sections, and the one-step calibration.
#include "core/errors.h"
#include "meshes/triangle_mesh.h"
#include "wear/calibration.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

using namespace dipper;
using namespace dipper::wear;

namespace {

std::string temp_file(const std::string& name, const std::string& text)
{
    const auto path = std::filesystem::temp_directory_path() / ("dipper_test_" + name);
    std::ofstream(path) << text;
    return path.string();
}

/// Wear of a 2 x 1 m plate (75 mm elements) from a fixed set of sliding contacts that are densest near
/// x = 0, as on a feeder plate under the drop: the same contact history for any wear constant.
WearSurface worn_plate(double constant)
{
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(2.0, 1.0, 27, 13);
    WearSurface s("feeder plate", plate, WearLaw::from_name("force_work", constant, "test"), 0);
    std::mt19937 rng(5);
    std::exponential_distribution<double> along(1.2);
    std::uniform_real_distribution<double> across(0.0, 1.0), force(100.0, 3000.0);
    for (int k = 0; k < 20000; ++k) {
        const Vec3 p{std::min(1.999, along(rng)), across(rng), 0.0};
        ContactRecord c;
        c.normal_world = {0.0, 0.0, 1.0};
        c.normal_force_N = force(rng);
        c.tangential_force_N = {0.3 * c.normal_force_N, 0.0, 0.0};
        c.relative_displacement_m = {2e-4, 0.0, 0.0};
        c.surface_id = 0;
        c.triangle_id = static_cast<std::int32_t>(locate_on_surface(plate, p).triangle);
        s.accumulate({c}, 1e-4);
    }
    return s;
}

}  // namespace

TEST_CASE("calibration recovers the wear constant that made the measurements (1e-9)", "[wear][calibration][unit]")
{
    const double true_constant = 3.7e-12, trial_constant = 1e-12;
    const double simulated_tonnage = 45.0;
    const WearSurface truth = worn_plate(true_constant);
    const RateMap true_map(truth, simulated_tonnage, 1);

    // 24 measured points on the plate (12 per half, like the feeder's two plates), written to a CSV as a
    // gauge would report them: depth = true rate x tonnage through the feeder, the tonnage chosen so that
    // the mean measured depth is 5 mm (0.1 mm gauge error is then 2 % of a reading)
    std::mt19937 rng(9);
    std::uniform_real_distribution<double> x(0.05, 1.95), y(0.05, 0.95);
    std::vector<Vec3> where;
    double mean_rate = 0.0;
    for (int k = 0; k < 24; ++k) {
        where.push_back({x(rng), y(rng), 0.0});
        mean_rate += true_map.at(where.back(), 1e-6, "p") / 24.0;
    }
    const double measured_tonnage = 5.0 / mean_rate;
    std::ostringstream csv;
    csv.precision(17);
    csv << "# synthetic measurements made with a known constant\nid,x_m,y_m,z_m,depth_mm,tonnage_t\n";
    for (std::size_t k = 0; k < where.size(); ++k)
        csv << "P" << k << ',' << where[k].x << ',' << where[k].y << ",0,"
            << true_map.at(where[k], 1e-6, "p") * measured_tonnage << ',' << measured_tonnage << '\n';
    const std::vector<MeasuredPoint> points = read_measured_points(temp_file("calibration.csv", csv.str()));
    REQUIRE(points.size() == 24);

    const WearSurface trial = worn_plate(trial_constant);
    const CalibrationResult r = calibrate(trial, simulated_tonnage, 1, points, {}, 0.01);
    CHECK(r.trial_constant == trial_constant);
    CHECK(r.calibrated_constant == Approx(true_constant).epsilon(1e-9));
    CHECK(r.scale == Approx(3.7).epsilon(1e-9));
    // after calibration simulated and measured agree at every point (the map is the true map)
    CHECK(r.summary_after.mean_simulated == Approx(r.summary_after.mean_measured).epsilon(1e-9));
    CHECK(r.summary_after.correlation == Approx(1.0).epsilon(1e-9));
    CHECK(r.summary_before.correlation == Approx(1.0).epsilon(1e-9));  // a constant scales the map only
    CHECK(r.summary_after.mean_absolute_relative_error < 1e-9);
    // the spread from the gauge (0.1 mm, independent per point: 0.4 % of the mean) and the position
    // (20 mm on a map whose wear halves over 0.6 m) brackets the constant within a few per cent
    CHECK(r.constant_low < true_constant);
    CHECK(r.constant_high > true_constant);
    CHECK(r.constant_low > 0.9 * true_constant);
    CHECK(r.constant_high < 1.1 * true_constant);
    for (const auto& c : r.after) {
        CHECK(c.measured_sigma == Approx(0.1 / measured_tonnage));
        CHECK(c.simulated_min <= c.simulated_rate);
        CHECK(c.simulated_max >= c.simulated_rate);
    }
}

TEST_CASE("comparison statistics: errors, relative errors and correlation of a known case", "[wear][validation][unit]")
{
    std::vector<PointComparison> cs(3);
    const double measured[3] = {1.0, 2.0, 3.0}, simulated[3] = {2.0, 4.0, 6.0};
    for (int k = 0; k < 3; ++k) {
        cs[static_cast<std::size_t>(k)].measured_rate = measured[k];
        cs[static_cast<std::size_t>(k)].simulated_rate = simulated[k];
    }
    const ComparisonSummary s = summarize(cs);
    CHECK(s.mean_measured == Approx(2.0));
    CHECK(s.mean_simulated == Approx(4.0));
    CHECK(s.mean_absolute_error == Approx(2.0));
    CHECK(s.rms_error == Approx(std::sqrt((1.0 + 4.0 + 9.0) / 3.0)));
    CHECK(s.mean_absolute_relative_error == Approx(1.0));
    CHECK(s.correlation == Approx(1.0));
    cs[2].simulated_rate = 0.0;  // anti-correlated: 2, 4, 0 against 1, 2, 3
    CHECK(summarize(cs).correlation == Approx(-0.5).epsilon(1e-12));
}

TEST_CASE("sections: a polyline across the surface samples the map, measured points near it are placed on it",
          "[wear][validation][unit]")
{
    const WearSurface s = worn_plate(1e-12);
    const RateMap map(s, 45.0, 1);
    const std::vector<Vec3> line{{0.1, 0.5, 0.0}, {1.0, 0.5, 0.0}, {1.0, 0.9, 0.0}};
    const auto profile = sample_section(map, line, 0.05, 0.01, "middle");
    REQUIRE(profile.size() == 27);  // 18 pieces of 0.05 m, then 8: 19 + 8 samples
    CHECK(profile.back().arc_length_m == Approx(1.3));
    for (const auto& p : profile) CHECK(p.simulated_rate == Approx(map.at(p.point_m, 1e-9, "p")).epsilon(1e-12));
    // wear falls off with x along the first leg (contacts are densest near x = 0)
    CHECK(profile.front().simulated_rate > 2.0 * profile[18].simulated_rate);

    std::vector<PointComparison> cs(3);
    cs[0].position_m = {0.5, 0.52, 0.0};  // 20 mm off the first leg, at s = 0.4
    cs[1].position_m = {1.0, 0.7, 0.0};   // on the second leg, at s = 1.1
    cs[2].position_m = {0.5, 0.8, 0.0};   // 0.3 m away: not on the section
    const auto on = points_on_section(line, cs, 0.05);
    REQUIRE(on.size() == 2);
    CHECK(on[0].arc_length_m == Approx(0.4));
    CHECK(on[1].arc_length_m == Approx(1.1));
    CHECK_THROWS_WITH(sample_section(map, {{0.1, 0.5, 0.3}, {1.0, 0.5, 0.3}}, 0.05, 0.01, "lifted"),
                      Catch::Contains("section 'lifted'") && Catch::Contains("0.3 m from the surface"));
}

TEST_CASE("measured wear: bad files and points are clear errors", "[wear][calibration][unit][bad_input]")
{
    const WearSurface s = worn_plate(1e-12);
    const std::string header = "id,x_m,y_m,z_m,depth_mm,tonnage_t\n";

    // a point off the surface names the point, its file line and the distance
    const auto off = read_measured_points(temp_file("off.csv", header + "A1,0.5,0.5,0.0,1.0,100\nA2,0.5,0.5,0.25,1.0,100\n"));
    CHECK_THROWS_WITH(calibrate(s, 45.0, 1, off, {}, 0.01),
                      Catch::Contains("measured point 'A2'") && Catch::Contains("off.csv:3") &&
                          Catch::Contains("0.25 m from the surface") && Catch::Contains("within 0.01 m"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("empty.csv", "")), Catch::Contains("empty.csv' is empty"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("header.csv", header)), Catch::Contains("no measured points"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("negative.csv", header + "A1,0.5,0.5,0,1.0,-5\n")),
                      Catch::Contains("negative.csv:2") && Catch::Contains("tonnage_t is -5") && Catch::Contains("expected > 0"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("nan.csv", header + "A1,0.5,nan,0,1.0,5\n")),
                      Catch::Contains("nan.csv:2") && Catch::Contains("column 'y_m' has 'nan'"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("text.csv", header + "A1,0.5,0.5,0,1.0 mm,5\n")),
                      Catch::Contains("column 'depth_mm' has '1.0 mm'"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("missing.csv", "id,x_m,y_m,z_m,depth_mm\nA1,0,0,0,1\n")),
                      Catch::Contains("missing.csv:1") && Catch::Contains("lacks column 'tonnage_t'"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("unknown.csv", "id,x,y,z,depth_mm,tonnage_t\n")),
                      Catch::Contains("unknown column 'x'"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("twice.csv", header + "A1,0,0,0,1,5\nA1,1,0,0,1,5\n")),
                      Catch::Contains("twice.csv:3") && Catch::Contains("id 'A1' appears twice"));
    CHECK_THROWS_WITH(read_measured_points(temp_file("short.csv", header + "A1,0,0,0,1\n")),
                      Catch::Contains("5 values; the header has 6 columns"));
    CHECK_THROWS_WITH(read_measured_points("/nonexistent/points.csv"), Catch::Contains("cannot open measurement file"));
    CHECK_THROWS_WITH(calibrate(s, 45.0, 1, {}, {}, 0.01), Catch::Contains("at least one measured point"));
    CHECK_THROWS_WITH(RateMap(s, -3.0, 1), Catch::Contains("simulated tonnage is -3 t"));
    // a trial run that did not wear the measured points cannot be scaled to them
    const WearSurface unworn("unworn", meshes::make_plate_mesh(1.0, 1.0, 2, 2), WearLaw{}, 0);
    const auto one = read_measured_points(temp_file("one.csv", header + "A1,0.5,0.5,0,1.0,100\n"));
    CHECK_THROWS_WITH(calibrate(unworn, 45.0, 1, one, {}, 0.01), Catch::Contains("must wear those points"));
}
