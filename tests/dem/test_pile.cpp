// The repose-angle fit against piles of known shape: a slope at a set angle between a flat top and a
// flat run-out, with the spheres placed at random along it.
#include "core/errors.h"
#include "dem/pile.h"
#include "dem/world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

using namespace dipper;
using namespace dipper::dem;

namespace {

/// A pile surface: top at 1.5 m up to x = 0.5, then down at `angle_deg` to 0.1 m, flat after; each
/// 2 cm column along x gets a sphere of radius 0.05 m whose top lies on the surface, at random y, and
/// spheres under it.
World synthetic_pile(double angle_deg, std::uint64_t seed)
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    const MaterialIndex ore = w.materials().index_of("ore");
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> y(0.1, 0.9), jitter(0.0, 0.02);
    const double t = std::tan(angle_deg * M_PI / 180.0), r = 0.05;
    for (double x = 0.0; x < 5.0; x += 0.02) {
        const double xs = x + jitter(rng);
        const double surface = std::clamp(1.5 - t * (xs - 0.5), 0.1, 1.5);
        for (double z = surface - r; z > 0.0; z -= 0.3) w.add_particle({{xs, y(rng), z}, {}, {}, r, ore});
    }
    return w;
}

}  // namespace

TEST_CASE("the repose fit finds the slope of a pile of known angle and ignores its top and toe", "[dem][pile]")
{
    ReposeWindow window;
    window.min_m = {0.0, 0.0, 0.0};
    window.max_m = {5.0, 1.0, 3.0};
    window.bin_m = 0.1;
    for (const double angle : {20.0, 30.0, 34.7, 45.0}) {
        const World w = synthetic_pile(angle, 7);
        const ReposeFit fit = fit_repose_angle(w.particles(), window, "synthetic pile");
        // each bin's top is the surface at a random point of the bin (within 2 cm of the bin's left edge
        // plus the column spacing), so a bin reads up to tan(angle) x 0.1 m off; over 10+ bins the fitted
        // slope is within a few tenths of a degree. Tolerance 0.5 deg.
        CHECK(fit.angle_deg == Approx(angle).margin(0.5));
        CHECK(fit.slope < 0.0);  // downhill along +x
        CHECK(fit.bins_fitted >= 8);
        CHECK(fit.rms_residual_m < 0.05);
        // the line, and which bins made it: the flags count the fitted bins, and the line passes through
        // the slope's top corner (x 0.5 m, z 1.5 m) within the bins' scatter (tan(angle) x 0.1 m, 0.1 m)
        CHECK(std::count(fit.fitted.begin(), fit.fitted.end(), true) == fit.bins_fitted);
        CHECK(fit.fitted.size() == fit.surface_m.size());
        CHECK(fit.intercept_m + fit.slope * 0.5 == Approx(1.5).margin(0.1));
    }
}

TEST_CASE("the repose fit refuses a window without a slope and a bad window", "[dem][pile]")
{
    const World w = synthetic_pile(30.0, 1);
    ReposeWindow flat;
    flat.min_m = {4.0, 0.0, 0.0};  // the run-out only: every bin at the same height
    flat.max_m = {5.0, 1.0, 3.0};
    CHECK_THROWS_WITH(fit_repose_angle(w.particles(), flat, "flat part"), Catch::Contains("flat part") && Catch::Contains("bins lie on the slope"));
    ReposeWindow bad = flat;
    bad.along = 'z';
    CHECK_THROWS_WITH(fit_repose_angle(w.particles(), bad, "window"), Catch::Contains("along = 'z'; expected x or y"));
    bad = flat;
    bad.max_m.x = 3.0;
    CHECK_THROWS_WITH(fit_repose_angle(w.particles(), bad, "window"), Catch::Contains("max_m must exceed min_m"));
}

TEST_CASE("the repose fit reads the surface of rocks from their hull points", "[dem][pile]")
{
    ReposeWindow window;
    window.min_m = {0.0, 0.0, 0.0};
    window.max_m = {5.0, 1.0, 3.0};
    window.bin_m = 0.1;
    // The points of a pile surface at 34.7 deg, one every 2 cm along x, like the vertices of rocks lying
    // on it, with points below them (the rocks' lower vertices).
    const double angle = 34.7, t = std::tan(angle * M_PI / 180.0);
    std::vector<Vec3> points;
    for (double x = 0.0; x < 5.0; x += 0.02) {
        const double surface = std::clamp(1.5 - t * (x - 0.5), 0.1, 1.5);
        points.push_back({x, 0.5, surface});
        points.push_back({x, 0.3, 0.5 * surface});
    }
    points.push_back({2.0, 0.5, 3.5});  // above the window: not part of it

    SECTION("rocks alone")
    {
        const World none(MaterialTable::aitik_copper_ore(), WorldSettings{});
        const ReposeFit fit = fit_repose_angle(none.particles(), window, "rocks", points);
        // every bin's top lies on the surface within one 2 cm point spacing: tan(34.7) x 0.02 m = 14 mm
        // at most, over 20+ bins; 0.3 deg.
        CHECK(fit.angle_deg == Approx(angle).margin(0.3));
        CHECK(fit.bins_fitted >= 10);
    }
    SECTION("rocks lying on top of a lower pile of spheres set the surface")
    {
        const World spheres = synthetic_pile(20.0, 3);
        CHECK(fit_repose_angle(spheres.particles(), window, "spheres").angle_deg == Approx(20.0).margin(0.5));
        // rocks on a 34.7 deg slope with the spheres' toe (x = 0.5 + 1.4 / tan 20 deg) and a top at 2.9 m:
        // steeper through the same toe, they lie above the spheres' surface everywhere up the slope
        const double toe = 0.5 + 1.4 / std::tan(20.0 * M_PI / 180.0);
        std::vector<Vec3> rocks;
        for (double x = 0.0; x < 5.0; x += 0.02) rocks.push_back({x, 0.5, std::clamp(0.1 + t * (toe - x), 0.1, 2.9)});
        const ReposeFit fit = fit_repose_angle(spheres.particles(), window, "spheres and rocks", rocks);
        // as for the rocks alone; 0.3 deg
        CHECK(fit.angle_deg == Approx(angle).margin(0.3));
    }
}

TEST_CASE("the repose fit takes the slope as one run of bins: rocks rolled out past the toe are left out", "[dem][pile]")
{
    ReposeWindow window;
    window.min_m = {0.0, 0.0, 0.0};
    window.max_m = {6.0, 1.0, 3.0};
    window.bin_m = 0.1;
    const World w = synthetic_pile(34.7, 5);  // top 1.5 m to x = 0.5, toe at x = 2.5, run-out at 0.1 m
    const ReposeFit alone = fit_repose_angle(w.particles(), window, "pile");
    REQUIRE(alone.angle_deg == Approx(34.7).margin(0.5));
    // Two large rocks rolled out to x 4-4.3 and 5.2-5.4, 0.45 m high: above the band's low edge (0.1 +
    // 0.15 x 1.4 = 0.31 m), but cut off from the slope by the run-out between
    std::vector<Vec3> rocks;
    for (double x = 4.0; x < 4.3; x += 0.02) rocks.push_back({x, 0.5, 0.45});
    for (double x = 5.2; x < 5.4; x += 0.02) rocks.push_back({x, 0.5, 0.45});
    const ReposeFit with = fit_repose_angle(w.particles(), window, "pile and rolled-out rocks", rocks);
    // the same bins as without the rocks, so the same line to round-off; every bin in the band, as the fit
    // took them before, reads 8.6 deg
    CHECK(with.angle_deg == Approx(alone.angle_deg).margin(1e-9));
    CHECK(with.bins_fitted == alone.bins_fitted);
    for (std::size_t k = 0; k < with.bin_centre_m.size(); ++k)
        if (with.bin_centre_m[k] > 3.5) CHECK_FALSE(with.fitted[k]);
}
