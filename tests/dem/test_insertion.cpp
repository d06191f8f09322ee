// Particle insertion: random fills by mass fraction, lattice fills, pouring.
#include "dem/insertion.h"
#include "helpers.h"
#include "meshes/triangle_mesh.h"

#include <catch2/catch.hpp>

using namespace dipper;
using namespace dipper::dem;

namespace {
double min_gap_m(const World& w)
{
    const auto& p = w.particles();
    double worst = 1e300;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j)
            worst = std::min(worst, norm(p.position_m[i] - p.position_m[j]) - p.radius_m[i] - p.radius_m[j]);
    return worst;
}
}  // namespace

TEST_CASE("random box fill follows the mass fractions, overlaps nothing, and repeats with its seed", "[dem][insertion][unit]")
{
    const SizeDistribution sizes{{{0.1, 0.6}, {0.05, 0.4}}};
    World a(MaterialTable::aitik_copper_ore(), WorldSettings{});
    const MaterialIndex ore = a.materials().index_of("ore");
    const FillReport report = fill_random(a, BoxRegion({0, 0, 0}, {1.5, 1.5, 1.5}), sizes, ore, 2000.0, 42);
    CHECK(report.placed == report.requested);
    // each class carries its fraction of the mass to within one particle of that class
    double mass_large = 0.0, mass_small = 0.0;
    for (std::size_t i = 0; i < a.particles().size(); ++i)
        (a.particles().radius_m[i] > 0.07 ? mass_large : mass_small) += a.particles().mass_kg[i];
    CHECK(std::abs(mass_large - 0.6 * 2000.0) <= 0.5 * sphere_mass_kg(0.1, 3700.0));
    CHECK(std::abs(mass_small - 0.4 * 2000.0) <= 0.5 * sphere_mass_kg(0.05, 3700.0));
    CHECK(min_gap_m(a) >= 0.0);
    for (std::size_t i = 0; i < a.particles().size(); ++i) {
        const Vec3 x = a.particles().position_m[i];
        const double r = a.particles().radius_m[i];
        CHECK((x.x - r >= 0.0 && x.x + r <= 1.5 && x.z - r >= 0.0 && x.z + r <= 1.5));
    }
    World b(MaterialTable::aitik_copper_ore(), WorldSettings{});
    fill_random(b, BoxRegion({0, 0, 0}, {1.5, 1.5, 1.5}), sizes, ore, 2000.0, 42);
    CHECK(test::state_hash(a) == test::state_hash(b));
}

TEST_CASE("random fill of a region bounded by a mesh keeps every sphere inside", "[dem][insertion][unit]")
{
    const meshes::TriangleMesh box = meshes::make_box_mesh({0.0, 0.0, 0.0}, {1.0, 0.8, 0.6});
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    const FillReport report = fill_random(w, MeshRegion(box), {{{0.05, 1.0}}}, w.materials().index_of("ore"), 300.0, 5);
    CHECK(report.placed > 100);
    for (std::size_t i = 0; i < w.particles().size(); ++i) {
        CHECK(box.contains(w.particles().position_m[i]));
        CHECK(box.distance_m(w.particles().position_m[i]) >= 0.05);
    }
    CHECK(min_gap_m(w) >= 0.0);
}

TEST_CASE("a fill that cannot fit says so", "[dem][insertion][unit]")
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    // 250 kg is 54 % of the box as solid: below the densest packing, beyond what a random fill reaches
    REQUIRE_THROWS_WITH(fill_random(w, BoxRegion({0, 0, 0}, {0.5, 0.5, 0.5}), {{{0.1, 1.0}}}, 0, 250.0, 1, 200),
                        Catch::Contains("too small") && Catch::Contains("250"));
    REQUIRE_THROWS_WITH(fill_random(w, BoxRegion({0, 0, 0}, {1, 1, 1}), {{{0.1, 0.5}, {0.05, 0.3}}}, 0, 10.0, 1),
                        Catch::Contains("sum to 0.8"));
    // more solid than the densest packing of spheres (74 %) leaves room for: refused before any try. 2,000 kg at
    // 3,700 kg/m3 is 0.54 m3, within 0.74 of a 1 m3 box; 2,800 kg is 0.757 m3, beyond it
    World empty(MaterialTable::aitik_copper_ore(), WorldSettings{});
    const double density = empty.materials().material(0).density_kg_per_m3;
    REQUIRE(density == 3700.0);
    REQUIRE_THROWS_WITH(fill_random(empty, BoxRegion({0, 0, 0}, {1, 1, 1}), {{{0.1, 1.0}}}, 0, 2800.0, 1, 1),
                        Catch::Contains("more than the box of 1 m3 holds") && Catch::Contains("2739.85 kg"));
    REQUIRE(empty.particles().size() == 0);
    REQUIRE_NOTHROW(require_mass_fits(2739.0, density, {0, 0, 0}, {1, 1, 1}, "the test"));
    // a count beyond what is made at once is refused with the count, not left to the allocator
    REQUIRE_THROWS_WITH(radii_for_mass({{{1e-6, 1.0}}}, density, 2000.0), Catch::Contains("1.29") && Catch::Contains("particles"));
    REQUIRE(particles_for_mass({{{0.1, 1.0}}}, density, 2000.0) == Approx(2000.0 / sphere_mass_kg(0.1, density)).epsilon(1e-12));
}

TEST_CASE("lattice fill places a regular grid", "[dem][insertion][unit]")
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    const FillReport report = fill_lattice(w, {0, 0, 0}, {1.0, 1.0, 1.0}, 0.1, 0.25, 0, 0.01, 3);
    // first centre at r + jitter = 0.11, then every 0.25 m while centre <= 0.89: 0.11, 0.36, 0.61, 0.86
    CHECK(report.placed == 64);
    CHECK(min_gap_m(w) >= 0.25 - 0.2 - 2.0 * 0.01 * std::sqrt(3.0) - 1e-12);
    REQUIRE_THROWS_WITH(fill_lattice(w, {0, 0, 0}, {1, 1, 1}, 0.1, 0.15, 0), Catch::Contains("spacing_m"));
}

TEST_CASE("pouring delivers its mass at the set rate", "[dem][insertion][unit]")
{
    World w(MaterialTable::aitik_copper_ore(), WorldSettings{});
    w.add_plane({0, 0, 0}, {0, 0, 1}, w.materials().index_of("ground"), "floor");
    Pourer pour(BoxRegion({0, 0, 1.0}, {1.0, 1.0, 1.5}), {{{0.05, 1.0}}}, w.materials().index_of("ore"), 400.0, 100.0,
                {0.0, 0.0, -1.0}, 9);
    std::size_t added = pour.update(w);  // t = 0: the first particle enters at once
    CHECK(added == 1);
    while (!pour.done() && w.time_s() < 2.0) {
        w.step();
        if (w.step_count() % 50 == 0) pour.update(w);
    }
    CHECK(pour.done());
    // 100 kg at 400 kg/s is due by 0.25 s; calls every 50 steps and one particle's mass of rounding
    CHECK(w.time_s() < 0.25 + 60 * w.step_s());
    CHECK(std::abs(pour.poured_mass_kg() - 100.0) <= sphere_mass_kg(0.05, 3700.0));
}

TEST_CASE("a pour with a start time waits for it, then delivers at its rate", "[dem][insertion][unit]")
{
    WorldSettings settings;
    settings.step_s = 2e-5;  // fixed: the world is empty until the pour starts
    World w(MaterialTable::aitik_copper_ore(), settings);
    w.add_plane({0, 0, 0}, {0, 0, 1}, w.materials().index_of("ground"), "floor");
    Pourer pour(BoxRegion({0, 0, 1.0}, {1.0, 1.0, 1.5}), {{{0.05, 1.0}}}, w.materials().index_of("ore"), 400.0, 100.0,
                {0.0, 0.0, -1.0}, 9, 0.1);
    double first_s = -1.0;
    while (!pour.done() && w.time_s() < 2.0) {
        if (pour.update(w) > 0 && first_s < 0.0) first_s = w.time_s();
        w.step();
    }
    REQUIRE(pour.done());
    // the first particle enters at the first call at or after 0.1 s (calls every step), and the 100 kg at
    // 400 kg/s are due 0.25 s later; the last particle's mass is reached one call late at most
    CHECK(first_s >= 0.1);
    CHECK(first_s < 0.1 + 1.5 * w.step_s());
    CHECK(w.time_s() < first_s + 0.25 + 2.0 * w.step_s());
    CHECK(w.time_s() > first_s + 0.25 - sphere_mass_kg(0.05, 3700.0) / 400.0 - w.step_s());
    REQUIRE_THROWS_WITH(Pourer(BoxRegion({0, 0, 1.0}, {1.0, 1.0, 1.5}), {{{0.05, 1.0}}}, w.materials().index_of("ore"), 400.0,
                               100.0, {}, 9, -1.0),
                        Catch::Contains("start_s = -1"));
}
