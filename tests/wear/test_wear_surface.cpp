// The wear surface: accumulation on triangles, nodal depth, volume-conserving smoothing, and wear from
// real DEM contacts (a sliding sphere, a bouncing sphere, a flow over meshes of four element sizes).
#include "core/errors.h"
#include "dem/world.h"
#include "meshes/triangle_mesh.h"
#include "wear/wear_surface.h"
#include "../dem/helpers.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace dipper;
using namespace dipper::wear;

namespace {

/// A plate of nx x ny cells whose interior vertices are moved randomly by up to 30 % of a cell: an
/// irregular mesh with triangles of different areas.
meshes::TriangleMesh irregular_plate(int nx, int ny, unsigned seed)
{
    const meshes::TriangleMesh regular = meshes::make_plate_mesh(1.0, 1.0, nx, ny);
    std::vector<Vec3> x = regular.vertices_m();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.3, 0.3);
    for (Vec3& v : x) {
        const bool edge = v.x < 1e-9 || v.y < 1e-9 || v.x > 1.0 - 1e-9 || v.y > 1.0 - 1e-9;
        if (!edge) {
            v.x += jitter(rng) / nx;
            v.y += jitter(rng) / ny;
        }
    }
    return meshes::TriangleMesh(x, regular.triangles(), "irregular plate");
}

ContactRecord sliding_record(std::int32_t triangle, double fn, const Vec3& slip)
{
    ContactRecord c;
    c.normal_world = {0.0, 0.0, 1.0};
    c.normal_force_N = fn;
    c.relative_displacement_m = slip;
    c.surface_id = 3;
    c.triangle_id = triangle;
    return c;
}

}  // namespace

TEST_CASE("smoothing conserves total wear volume to 1e-12 for any number of iterations on an irregular mesh",
          "[wear][smoothing][unit]")
{
    const meshes::TriangleMesh mesh = irregular_plate(12, 9, 7);
    const std::vector<double> area = lumped_node_areas_m2(mesh);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> volume(0.0, 1e-6);
    std::vector<double> v(mesh.vertex_count());
    for (double& x : v) x = volume(rng);
    double total = 0.0;
    for (const double x : v) total += x;
    for (const int iterations : {0, 1, 2, 3, 5, 10, 50}) {
        CAPTURE(iterations);
        const std::vector<double> s = smooth_node_volumes(mesh, area, v, iterations);
        double sum = 0.0;
        for (const double x : s) sum += x;
        CHECK(std::abs(sum - total) <= 1e-12 * total);
        if (iterations > 0) CHECK(s != v);  // it did smooth
    }
    CHECK_THROWS_AS(smooth_node_volumes(mesh, area, v, -1), InputError);
}

TEST_CASE("a single spike spreads to the nodes that share an element with it by the 4:1 weights", "[wear][smoothing][unit]")
{
    const meshes::TriangleMesh mesh = irregular_plate(6, 6, 3);
    const std::vector<double> area = lumped_node_areas_m2(mesh);
    // an interior node: (3, 3) of the 7 x 7 vertex grid
    const std::uint32_t spike = 3 * 7 + 3;
    std::vector<double> v(mesh.vertex_count(), 0.0);
    v[spike] = 1e-6;
    const std::vector<double> s = smooth_node_volumes(mesh, area, v, 1);

    std::vector<bool> neighbour(mesh.vertex_count(), false);
    for (const auto& t : mesh.triangles())
        if (t[0] == spike || t[1] == spike || t[2] == spike)
            for (const std::uint32_t k : t) neighbour[k] = k != spike;
    double w = 4.0 * area[spike];
    int count = 0;
    for (std::size_t k = 0; k < neighbour.size(); ++k)
        if (neighbour[k]) { w += area[k]; ++count; }
    CHECK(count == 6);
    // depth = volume / area: 4 V / W at the spike, V / W at each neighbour, 0 elsewhere
    CHECK(s[spike] / area[spike] == Approx(4.0 * 1e-6 / w).epsilon(1e-12));
    for (std::size_t k = 0; k < neighbour.size(); ++k) {
        if (k == spike) continue;
        CAPTURE(k);
        if (neighbour[k]) {
            CHECK(s[k] / area[k] == Approx(1e-6 / w).epsilon(1e-12));
            CHECK((s[spike] / area[spike]) / (s[k] / area[k]) == Approx(4.0).epsilon(1e-12));
        } else {
            CHECK(s[k] == 0.0);
        }
    }
}

TEST_CASE("Archard from synthetic records: V = K F d to round-off, on one triangle and across an edge",
          "[wear][archard][unit]")
{
    // a sphere pressed with 2 kN slides 0.8 m along y = 0.3 over a 1 m plate of 4 x 4 cells: it crosses
    // cell edges and diagonals; each step's record names the triangle under the contact point
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(1.0, 1.0, 4, 4);
    const double K = 3e-13, F = 2000.0, step = 1e-3;
    WearSurface one("one triangle", plate, WearLaw::from_name("archard", K, "test"), 3);
    WearSurface across("across edges", plate, WearLaw::from_name("archard", K, "test"), 3);

    // one triangle: 0.1 m in small steps inside triangle 0 (the cell [0, 0.25]^2, lower-right half)
    const std::size_t t0 = locate_on_surface(plate, {0.2, 0.02, 0.0}).triangle;
    for (int k = 0; k < 100; ++k) one.accumulate({sliding_record(static_cast<std::int32_t>(t0), F, {step, 0.0, 0.0})}, 1e-4);
    CHECK(one.total_volume_m3() == Approx(K * F * 0.1).epsilon(1e-12));
    CHECK(one.triangle_volume_m3()[t0] == one.total_volume_m3());

    // across edges: the wear of each triangle is K F times the length of path on it
    std::vector<double> path_on(plate.triangle_count(), 0.0);
    for (int k = 0; k < 800; ++k) {
        const Vec3 p{0.1 + (k + 0.5) * step, 0.3, 0.0};
        const std::size_t t = locate_on_surface(plate, p).triangle;
        path_on[t] += step;
        across.accumulate({sliding_record(static_cast<std::int32_t>(t), F, {step, 0.0, 0.0})}, 1e-4);
    }
    CHECK(across.total_volume_m3() == Approx(K * F * 0.8).epsilon(1e-12));
    int touched = 0;
    for (std::size_t t = 0; t < plate.triangle_count(); ++t) {
        CHECK(across.triangle_volume_m3()[t] == Approx(K * F * path_on[t]).epsilon(1e-12).margin(1e-30));
        touched += path_on[t] > 0.0;
    }
    CHECK(touched >= 6);  // the path really crossed triangle edges
    // a record of another surface is ignored; a triangle id outside the mesh is an error
    across.accumulate({[&] { auto c = sliding_record(0, F, {1.0, 0.0, 0.0}); c.surface_id = 4; return c; }()}, 1e-4);
    CHECK(across.total_volume_m3() == Approx(K * F * 0.8).epsilon(1e-12));
    CHECK_THROWS_WITH(across.accumulate({sliding_record(32, F, {step, 0.0, 0.0})}, 1e-4),
                      Catch::Contains("triangle 32") && Catch::Contains("0..31"));
}

TEST_CASE("Archard from the DEM: a sphere sliding into rolling on a meshed plate wears K m v0^2 / 7",
          "[wear][archard][dem][unit]")
{
    // A sphere launched at v0 without spin on a plate with friction mu slides until v = R w: the slip
    // speed falls linearly from v0 to 0 in t* = 2 v0 / (7 mu g), so the slip distance is v0^2 / (7 mu g)
    // and Archard's V = K (m g) (v0^2 / (7 mu g)) = K m v0^2 / (7 mu). No rolling resistance here.
    // Tolerance 1 %: the normal force is m g only to within the elastic ringing at landing (damped in
    // a few contact times) and the tangential spring adds a small elastic slip in the rolling phase.
    // Measured: +5e-4.
    const double mu = 0.4, v0 = 2.0, r = 0.1, K = 1e-13;
    dem::World w(test::two_material_table(test::coefficients(mu, 0.0, 0.9, 0.9, 1.0, 0.27), 2500.0, 1e9, 0.25), {});
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(3.0, 1.0, 24, 8);  // 125 mm cells
    const int floor = w.add_mesh(plate, 1, "plate");
    WearSurface wear("plate", plate, WearLaw::from_name("archard", K, "test"), floor);
    w.set_contact_consumer([&](const std::vector<ContactRecord>& c, double, double dt) { wear.accumulate(c, dt); }, {floor});
    const double m = 4.0 / 3.0 * M_PI * r * r * r * 2500.0;
    w.add_particle({{0.2, 0.5, r}, {}, {}, r, 0});
    while (w.time_s() < 0.1) w.step();  // comes to rest on the plate
    wear = WearSurface("plate", plate, WearLaw::from_name("archard", K, "test"), floor);
    w.particles().velocity_m_per_s[0] = {v0, 0.0, 0.0};
    std::size_t most_contacts = 0;
    while (w.time_s() < 0.5) {
        w.step();
        most_contacts = std::max(most_contacts, w.wall_contact_count());
    }
    // It rolls along y = 0.5, the line between two rows of cells, where each point lies on two triangles: one
    // contact all the way, and over 0.5 m of 125 mm cells at least one triangle of each of 4 cells worn
    CHECK(most_contacts == 1);
    CHECK(w.particles().position_m[0].x > 0.7);
    int touched = 0;
    for (const double v : wear.triangle_volume_m3()) touched += v > 0.0;
    CHECK(touched >= 4);
    CHECK(wear.total_volume_m3() == Approx(K * m * v0 * v0 / (7.0 * mu)).epsilon(0.01));
}

TEST_CASE("DEM records mark each impact once: a bouncing sphere gives one impact per landing", "[wear][dem][unit]")
{
    dem::World w(test::two_material_table(test::coefficients(0.3, 0.0, 0.05, 0.05, 1.0, 0.27), 2500.0, 1e9, 0.25), {});
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(1.0, 1.0, 4, 4);
    const int floor = w.add_mesh(plate, 1, "plate");
    const double K = 1e-12;
    WearSurface impacts("plate", plate, WearLaw::from_name("impact_energy", K, "test"), floor);
    std::vector<double> speeds;
    double last_dt = 0.0;
    w.set_contact_consumer([&](const std::vector<ContactRecord>& c, double, double dt) {
        impacts.accumulate(c, dt);
        for (const auto& rec : c)
            if (rec.first_step) speeds.push_back(norm(rec.relative_displacement_m) / dt);
        last_dt = dt;
    }, {floor});
    const double h = 0.5, r = 0.05;
    w.add_particle({{0.5, 0.5, r + h}, {}, {}, r, 0});
    while (w.time_s() < 0.5) w.step();  // falls 0.5 m in 0.319 s, lands once, rebounds to ~0.4 m
    REQUIRE(speeds.size() == 1);
    std::uint64_t count = 0;
    for (const auto n : impacts.impacts()) count += n;
    CHECK(count == 1);
    // the impact speed is the free-fall speed sqrt(2 g h) to within the one step before the record (1e-3)
    const double v = std::sqrt(2.0 * 9.81 * h);
    CHECK(speeds[0] == Approx(v).epsilon(1e-3));
    const double m = 4.0 / 3.0 * M_PI * r * r * r * 2500.0;
    CHECK(impacts.total_volume_m3() == Approx(K * m * v * v).epsilon(2e-3));
    CHECK(last_dt > 0.0);
}

TEST_CASE("mesh refinement (30, 45, 60, 75 mm) moves local depth but not total wear for the same flow",
          "[wear][mesh_size][dem][unit]")
{
    // 40 spheres of 42-50 mm radius slide and roll down a 25 deg incline of 1.2 x 0.6 m, meshed at four element
    // sizes. On a flat plate the contact force does not depend on the tessellation (one contact per
    // touched feature), so the total wear may change only through round-off that the granular flow
    // amplifies: tolerance 1 % (measured: within 3e-4; the peak depth at 77 mm is 0.15 of that at 30 mm). The largest local depth does change with element size (one element
    // takes a contact's whole wear), which is why maps are smoothed.
    const double tilt = 25.0 * M_PI / 180.0;
    std::vector<double> totals, peaks;
    for (const int cells_per_m : {33, 22, 16, 13}) {  // element sizes 30, 45, 62, 77 mm
        dem::WorldSettings settings;
        settings.gravity_m_per_s2 = {9.81 * std::sin(tilt), 0.0, -9.81 * std::cos(tilt)};
        dem::World w(test::two_material_table(test::coefficients(0.5, 0.0, 0.3, 0.3, 1.0, 0.27), 2500.0, 1e9, 0.25), settings);
        const meshes::TriangleMesh plate =
            meshes::make_plate_mesh(1.2, 0.6, static_cast<int>(1.2 * cells_per_m), static_cast<int>(0.6 * cells_per_m));
        const int floor = w.add_mesh(plate, 1, "plate");
        WearSurface wear("plate", plate, WearLaw::from_name("force_work", 1e-12, "test"), floor);
        w.set_contact_consumer([&](const std::vector<ContactRecord>& c, double, double dt) { wear.accumulate(c, dt); }, {floor});
        for (int i = 0; i < 8; ++i)  // every other sphere starts faster and runs into the one ahead
            for (int j = 0; j < 5; ++j)
                w.add_particle({{0.06 + 0.11 * i, 0.06 + 0.11 * j, 0.06 + 0.02 * ((i + j) % 3)},
                                {0.4 * (i % 2 == 0), 0.0, 0.0}, {}, 0.05 - 0.004 * (j % 3), 0});
        while (w.time_s() < 0.4) w.step();
        totals.push_back(wear.total_volume_m3());
        double peak = 0.0;
        for (const double d : wear.triangle_depth_m()) peak = std::max(peak, d);
        peaks.push_back(peak);
    }
    for (std::size_t k = 1; k < totals.size(); ++k) {
        CAPTURE(k, totals[0], totals[k]);
        CHECK(totals[k] == Approx(totals[0]).epsilon(0.01));
    }
    CHECK(totals[0] > 0.0);
    // finer elements concentrate a contact's wear on a smaller area: the peak depth is larger at 30 mm
    CHECK(peaks.front() > 1.5 * peaks.back());
}
