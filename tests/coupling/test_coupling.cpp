// Spheres against rigid bodies: the sphere-hull contact against libccd, fixed rock versus mesh copy, momentum
// of a colliding cloud, and bad input.
#include "core/errors.h"
#include "coupled_scene.h"
#include "dem/helpers.h"
#include "dem/insertion.h"
#include "meshes/triangle_mesh.h"
#include "rigid/rock_generator.h"

#include <catch2/catch.hpp>
#include <ccd/ccd.h>

#include <cmath>
#include <limits>
#include <cstdio>
#include <random>

using namespace dipper;
using namespace dipper::test;

namespace {

// libccd's view of the two shapes: support points of a sphere and of the hull's vertices
struct CcdSphere { Vec3 centre; double radius; };
struct CcdHull { const std::vector<Vec3>* vertices; };

void sphere_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out)
{
    const auto* s = static_cast<const CcdSphere*>(obj);
    const Vec3 d{ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir)};
    const Vec3 p = s->centre + normalized(d) * s->radius;
    ccdVec3Set(out, p.x, p.y, p.z);
}

void hull_support(const void* obj, const ccd_vec3_t* dir, ccd_vec3_t* out)
{
    const auto* h = static_cast<const CcdHull*>(obj);
    const Vec3 d{ccdVec3X(dir), ccdVec3Y(dir), ccdVec3Z(dir)};
    Vec3 best = (*h->vertices)[0];
    for (const Vec3& v : *h->vertices)
        if (dot(v, d) > dot(best, d)) best = v;
    ccdVec3Set(out, best.x, best.y, best.z);
}

/// Total linear momentum magnitude scale of a state, for relative errors.
double momentum_scale(const coupling::CoupledWorld& c)
{
    double s = 0.0;
    const auto& p = c.dem().particles();
    for (std::size_t i = 0; i < p.size(); ++i) s += p.mass_kg[i] * norm(p.velocity_m_per_s[i]);
    for (std::size_t b = 0; b < c.rigid().body_count(); ++b) {
        const double m = c.rigid().mass_kg(static_cast<int>(b));
        if (m > 0.0) s += m * norm(c.rigid().state(static_cast<int>(b)).velocity_m_per_s);
    }
    return s;
}

}  // namespace

TEST_CASE("rotation vectors of rotations, including half turns", "[coupling][unit]")
{
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 200; ++k) {
        const Vec3 axis = normalized(Vec3{u(rng), u(rng), u(rng)});
        const double angle = k < 190 ? M_PI * std::abs(u(rng)) : M_PI - 1e-9 * k;
        const Vec3 v = coupling::rotation_vector(rotation_about_axis(axis, angle));
        CHECK(norm(v - axis * angle) < 1e-7);
    }
    CHECK(norm(coupling::rotation_vector(Mat3::identity())) == 0.0);
}

TEST_CASE("sphere-hull contact agrees with libccd's penetration depth and direction", "[coupling][unit]")
{
    // The spheres touch a rock through the exact closest point on its triangulated hull (dem/ sphere-triangle
    // contact, one contact per feature). libccd computes the same penetration independently (GJK + EPA on
    // support functions). With no velocity the contact force is Kn * overlap along the normal, so the wall
    // force of the initial state gives our overlap and normal.
    const rigid::ConvexPolyhedron rock = test_rock(0.4, 17);
    const dem::MaterialTable table = dem::MaterialTable::aitik_copper_ore();
    const double kn = table.material(table.index_of("ore")).bulk_modulus_Pa() * kSphereRadius *
                      table.pair(table.index_of("ore"), table.index_of("rock")).normal_stiffness_scale;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int touching = 0, apart = 0;
    double worst_depth = 0.0, worst_angle = 0.0, worst_separation = 0.0;
    for (int k = 0; k < 300; ++k) {
        const Vec3 dir = normalized(Vec3{u(rng), u(rng), u(rng)});
        const double reach = rock.support_m(dir);
        // on the ray beyond the supporting plane: outside the hull, from touching its surface to 1.15 r away (the
        // DEM stops a run long before a centre could reach the inside: overlap > 0.5 r is a divergence)
        const Vec3 centre = dir * (reach + kSphereRadius * (0.575 + 0.575 * u(rng)));
        dem::World w(table, dem::WorldSettings{});
        w.add_mesh(rock.to_mesh(), table.index_of("rock"), "rock");
        add_sphere(w, centre);
        w.prepare();
        const Vec3 f = w.wall_force_N(0);

        ccd_t ccd;
        CCD_INIT(&ccd);
        ccd.support1 = sphere_support;
        ccd.support2 = hull_support;
        ccd.max_iterations = 1000;
        ccd.epa_tolerance = 1e-12;
        const CcdSphere s{centre, kSphereRadius};
        const CcdHull h{&rock.vertices_m()};
        ccd_real_t depth = 0.0;
        ccd_vec3_t direction, position;
        const bool hit = ccdGJKPenetration(&s, &h, &ccd, &depth, &direction, &position) == 0;
        if (!hit || depth < 1e-7) {
            CHECK(norm(f) < kn * 1e-7);
            ++apart;
            continue;
        }
        ++touching;
        const double overlap = norm(f) / kn;
        worst_depth = std::max(worst_depth, std::abs(overlap - depth));
        // libccd's direction moves the sphere (object 1) out of the hull: the wall force points along it... reversed
        const Vec3 ccd_dir = normalized(Vec3{ccdVec3X(&direction), ccdVec3Y(&direction), ccdVec3Z(&direction)});
        // Our normal n (hull towards sphere) must be an exact separating direction for our depth: moving the sphere
        // by `overlap` along n separates the two, h_H(n) + r - c.n = overlap.
        const Vec3 n = normalized(f) * -1.0;
        worst_separation = std::max(worst_separation, std::abs(rock.support_m(n) + kSphereRadius - dot(centre, n) - overlap));
        worst_angle = std::max(worst_angle, std::acos(std::clamp(std::abs(dot(ccd_dir, normalized(f))), -1.0, 1.0)));
    }
    std::printf("sphere-hull vs libccd: %d touching, %d apart; worst depth difference %.3g m, worst normal angle %.3g rad, "
                "worst separation residual %.3g m\n", touching, apart, worst_depth, worst_angle, worst_separation);
    CHECK(touching > 100);
    CHECK(apart > 50);
    // Our depth and normal are exact to round-off; libccd's EPA approximates the sphere by a polytope and
    // resolves the depth to about 1e-6 m here. A depth resolution d leaves a direction uncertainty of about
    // sqrt(2 d / r) = 4.5e-3 rad, hence the angle bound; the depths agree within 2 um of 10-100 mm overlaps.
    CHECK(worst_separation < 1e-12);
    CHECK(worst_depth < 2e-6);
    CHECK(worst_angle < 1e-2);
}

TEST_CASE("a sphere near a rock's edge or vertex gets the hull's exact closest point", "[coupling][unit]")
{
    // Most closest points of a sphere on a rock that are not inside a face lie on an edge, and the DEM settles
    // those from the two faces of the edge alone; the rest take the search over all faces within reach. Spheres
    // at random places 0.3-1.15 r from a generated rock must each get the overlap r - d and the direction of the
    // hull's exact distance d, found here by brute force over every triangle of the rock (the feature that holds
    // the closest point comes with it, so that edges and vertices are seen to be exercised in numbers). Two rocks:
    // one of the bed's kind, and a long one of few points with sharp edges and corners, where the face across an
    // edge is often out of the sphere's reach and the search over all faces decides.
    const auto [rock, seed] = GENERATE(table<rigid::ConvexPolyhedron, std::uint64_t>(
        {{test_rock(0.4, 29), 31}, {rigid::generate_rock({0.6, 3.0, 4.0, 8}, 32).in_principal_frame(), 33}}));
    const meshes::TriangleMesh mesh = rock.to_mesh();
    const dem::MaterialTable materials = dem::MaterialTable::aitik_copper_ore();
    const double r = 0.3;  // large beside the rock: spheres reach round its edges and corners, where it is least flat
    const double kn = materials.material(materials.index_of("ore")).bulk_modulus_Pa() * r *
                      materials.pair(materials.index_of("ore"), materials.index_of("rock")).normal_stiffness_scale;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-0.8, 0.8);
    int on_face = 0, on_edge = 0, on_vertex = 0, apart = 0;
    double worst_overlap = 0.0, worst_direction = 0.0;
    while (on_face + on_edge + on_vertex + apart < 600) {
        const Vec3 centre{u(rng), u(rng), u(rng)};
        meshes::ClosestPoint best;
        best.distance_squared = std::numeric_limits<double>::infinity();
        for (const auto& t : mesh.triangles()) {
            const meshes::ClosestPoint cp = meshes::closest_point_on_triangle(centre, mesh.vertices_m()[t[0]], mesh.vertices_m()[t[1]],
                                                                              mesh.vertices_m()[t[2]]);
            if (cp.distance_squared < best.distance_squared) best = cp;
        }
        const double d = std::sqrt(best.distance_squared);
        if (mesh.contains(centre) || d < 0.3 * r || d > 1.15 * r) continue;
        dem::World w(materials, dem::WorldSettings{});
        w.add_mesh(mesh, materials.index_of("rock"), "rock");
        add_sphere(w, centre, {}, r);
        w.prepare();
        const Vec3 f = w.wall_force_N(0);
        if (d >= r) {
            CHECK(norm(f) == 0.0);
            ++apart;
            continue;
        }
        // a closest point on a shared edge or vertex is found by several triangles: the first one's feature counts
        (best.feature == meshes::Feature::Face ? on_face : best.feature == meshes::Feature::Edge ? on_edge : on_vertex)++;
        worst_overlap = std::max(worst_overlap, std::abs(norm(f) / kn - (r - d)));
        worst_direction = std::max(worst_direction, norm(normalized(f) * -1.0 - (centre - best.point) * (1.0 / d)));
    }
    std::printf("sphere near a rock: %d on a face, %d on an edge, %d on a vertex, %d apart; worst overlap error %.3g m, "
                "worst direction error %.3g\n", on_face, on_edge, on_vertex, apart, worst_overlap, worst_direction);
    CHECK(on_edge > 50);
    CHECK(on_vertex > 10);
    CHECK(on_face > 50);
    CHECK(apart > 50);
    // the same point from the same or the neighbouring triangle: round-off of coordinates near 0.3 m
    CHECK(worst_overlap < 1e-12);
    CHECK(worst_direction < 1e-9);
}

TEST_CASE("a sphere dropped on a fixed rock rebounds as on a fixed mesh copy of it", "[coupling][unit]")
{
    const rigid::ConvexPolyhedron rock = test_rock(0.6, 23);
    const Vec3 start{0.03, -0.02, rock.support_m({0, 0, 1}) + 0.3};
    // (a) the rock is a static Bullet body coupled to the spheres
    auto a = make_scene(1);
    const rigid::BodyId fixed = a->rigid.add_static_mesh(rock.to_mesh(), a->rigid.material_index("rock"), "fixed rock");
    a->world.couple(fixed, rock.to_mesh(), a->dem.materials().index_of("rock"), "fixed_rock");
    add_sphere(a->dem, start);
    // (b) a DEM-only triangle mesh
    dem::World b(dem::MaterialTable::aitik_copper_ore(), dem::WorldSettings{});
    b.add_mesh(rock.to_mesh(), b.materials().index_of("rock"), "mesh_rock");
    add_sphere(b, start);
    double peak_a = 0.0;
    while (a->dem.time_s() < 0.5) {
        a->world.step();
        b.step();
        peak_a = std::max(peak_a, norm(a->dem.wall_force_N(0)));
    }
    REQUIRE(peak_a > 100.0);  // it did hit the rock
    const Vec3 va = a->dem.particles().velocity_m_per_s[0], vb = b.particles().velocity_m_per_s[0];
    const Vec3 xa = a->dem.particles().position_m[0], xb = b.particles().position_m[0];
    // The same contact routine on the same surface at the same times: identical to round-off.
    CHECK(norm(va - vb) < 1e-12);
    CHECK(norm(xa - xb) < 1e-12);
}

TEST_CASE("resisting its own spin, a sphere rolling over a fixed rock moves as over a fixed mesh copy of it", "[coupling][unit]")
{
    // Under own_spin the sphere-rock pairs sum their rolling resistance in the rock pairs, the mesh walls in the
    // wall contacts: the same law by two paths. The sphere lands spinning and sliding on the rock's top, rolls
    // over it and falls off its side.
    dem::MaterialTable table = dem::MaterialTable::aitik_copper_ore();
    table.set_rolling_resistance(dem::RollingResistance::own_spin);
    const rigid::ConvexPolyhedron rock = test_rock(0.6, 23);
    const Vec3 start{0.03, -0.02, rock.support_m({0, 0, 1}) + 0.15};
    const Vec3 velocity{0.8, 0.3, 0.0}, spin{-3.0, 9.0, 1.0};
    auto a = make_scene(1, {0.0, 0.0, -9.81}, table);
    const rigid::BodyId fixed = a->rigid.add_static_mesh(rock.to_mesh(), a->rigid.material_index("rock"), "fixed rock");
    a->world.couple(fixed, rock.to_mesh(), a->dem.materials().index_of("rock"), "fixed_rock");
    a->dem.add_particle({start, velocity, spin, kSphereRadius, a->dem.materials().index_of("ore")});
    dem::World b(table, dem::WorldSettings{});
    b.add_mesh(rock.to_mesh(), b.materials().index_of("rock"), "mesh_rock");
    b.add_particle({start, velocity, spin, kSphereRadius, b.materials().index_of("ore")});
    double contact_s = 0.0;
    while (a->dem.time_s() < 0.4) {
        a->world.step();
        b.step();
        if (norm(a->dem.wall_force_N(0)) > 0.0) contact_s += a->dem.step_s();
    }
    REQUIRE(contact_s > 0.05);  // it rolled on the rock for a while
    const auto& pa = a->dem.particles();
    const auto& pb = b.particles();
    // the same operations in the same order: identical to round-off
    CHECK(norm(pa.velocity_m_per_s[0] - pb.velocity_m_per_s[0]) < 1e-12);
    CHECK(norm(pa.angular_velocity_rad_per_s[0] - pb.angular_velocity_rad_per_s[0]) < 1e-10);
    CHECK(norm(pa.position_m[0] - pb.position_m[0]) < 1e-12);
}

TEST_CASE("a colliding cloud of spheres and rocks keeps its momentum", "[coupling][analytic]")
{
    // No gravity: spheres and rocks converge on a point, collide with each other (sphere-sphere, sphere-rock in
    // the coupling, rock-rock in Bullet) and fly apart. Linear momentum: every impulse a sphere gets from a
    // rock, the rock gets back (docs/coupling.md), and Bullet's rock-rock impulses are equal and opposite, so
    // it holds to round-off once the contacts are over. Angular momentum: Bullet applies the reaction torque
    // about the centre of mass at the start of its step while the centre moves during it, so it holds to
    // O(v dt) only (measured 1.2e-7, 3.0e-6, 1.4e-5 of the scale for n = 1, 5, 20); the bound keeps a margin of 3.
    // The same with the rocks taking the spheres' forces at every DEM step (RockExchange::dem_step): each impulse
    // passes at once, so linear momentum holds to round-off at once too, and the torques act about the centre
    // where it is at that DEM step; what is left is the rocks' turn over Bullet's step, taken with the inertia of
    // its start (measured 9.7e-8, 6.9e-7, 3.3e-6 of the scale for n = 1, 5, 20, a fifth of the coupling-step
    // exchange's; the bound keeps a margin of 3). The energy the impacts take out no longer depends on n:
    // kinetic energy after / before 0.3211, 0.3221, 0.3228 (0.3214, 0.3337, 0.3877 at the coupling step).
    double energy_at_n1 = 0.0;
    std::printf("cloud: exchange, n, linear momentum error / sum m|v|, angular momentum error / L scale, energy ratio\n");
    for (const auto exchange : {coupling::RockExchange::coupling_step, coupling::RockExchange::dem_step})
    for (int n : {1, 5, 20}) {
        const bool at_dem_rate = exchange == coupling::RockExchange::dem_step;
        auto s = make_scene(n, {0.0, 0.0, 0.0}, dem::MaterialTable::aitik_copper_ore(), false, exchange);
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        const int rock_mat = s->rigid.material_index("rock");
        const auto dem_rock = s->dem.materials().index_of("rock");
        // four rocks drifting together, each with six spheres closing in on it from around
        for (int k = 0; k < 4; ++k) {
            const Vec3 x{2.0 * (k % 2) - 1.0, 2.0 * (k / 2) - 1.0, 0.3 * u(rng)};
            const Vec3 v = x * -0.5;
            s->world.add_rock(test_rock(0.4, 100 + static_cast<std::uint64_t>(k)), 2700.0, rock_mat, dem_rock, x,
                              rotation_about_axis(normalized(Vec3{u(rng), u(rng), u(rng)}), 3.0 * u(rng)), v,
                              Vec3{u(rng), u(rng), u(rng)} * 3.0);
            for (int j = 0; j < 6; ++j) {
                const double sign = j % 2 ? 1.0 : -1.0;
                const Vec3 axis = j / 2 == 0 ? Vec3{sign, 0, 0} : (j / 2 == 1 ? Vec3{0, sign, 0} : Vec3{0, 0, sign});
                const Vec3 dir = normalized(axis + Vec3{u(rng), u(rng), u(rng)} * 0.2);
                add_sphere(s->dem, x + dir * 0.55, v - dir * 2.0 + Vec3{u(rng), u(rng), u(rng)} * 0.3);
            }
        }
        const Vec3 p0 = s->world.linear_momentum_kg_m_per_s();
        const Vec3 l0 = s->world.angular_momentum_kg_m2_per_s();
        const double scale = momentum_scale(s->world);
        const double e0 = s->world.kinetic_energy_J();
        std::size_t peak_wall = 0, peak_pair = 0;
        while (s->world.time_s() < 1.2) {
            s->world.step();
            peak_wall = std::max(peak_wall, s->dem.wall_contact_count());
            peak_pair = std::max(peak_pair, s->dem.pair_contact_count());
        }
        REQUIRE(peak_wall >= 3);                      // spheres did hit rocks
        REQUIRE(s->dem.wall_contact_count() == 0);    // and all contacts are over
        REQUIRE(s->dem.pair_contact_count() == 0);
        REQUIRE(s->rigid.contact_point_count() == 0);
        const double dp = norm(s->world.linear_momentum_kg_m_per_s() - p0) / scale;
        const double dl = norm(s->world.angular_momentum_kg_m2_per_s() - l0) / (scale * 1.5);
        const double e1 = s->world.kinetic_energy_J();
        std::printf("  %s  n = %2d  %.2e  %.2e  %.4f  (peak sphere-rock %zu, sphere-sphere %zu; runaway guard set off %llu times)\n",
                    at_dem_rate ? "DEM step     " : "coupling step", n, dp, dl, e1 / e0, peak_wall, peak_pair,
                    static_cast<unsigned long long>(s->world.runaways_caught()));
        CHECK(dp < 1e-13);
        CHECK(dl < (at_dem_rate ? 1e-5 : 5e-5));
        if (at_dem_rate && n == 1) energy_at_n1 = e1 / e0;
        if (at_dem_rate) CHECK(std::abs(e1 / e0 - energy_at_n1) < 0.005);
        CHECK(e1 < e0);  // damped contacts only take energy out
    }
}

TEST_CASE("coupling bad input: no surface, no coefficients, no substeps", "[coupling][unit]")
{
    CHECK_THROWS_WITH(make_scene(0), Catch::Contains("substeps") && Catch::Contains(">= 1"));
    {
        auto s = make_scene(1);
        const rigid::BodyId rock = s->rigid.add_rock(cube(0.4), 2700.0, s->rigid.material_index("rock"), {0, 0, 1});
        CHECK_THROWS_WITH(s->world.couple(rock, meshes::TriangleMesh{}, s->dem.materials().index_of("rock"), "rock"),
                          Catch::Contains("'rock 0'") && Catch::Contains("no triangles"));
        CHECK_THROWS_WITH(s->world.couple(7, cube(0.4).to_mesh(), 0, "x"), Catch::Contains("no body 7"));
    }
    {
        // a table without the sphere-rock pair
        dem::MaterialTable t;
        t.add({"ore", 3700.0, 45e9, 0.3, false});
        t.add({"granite", 2700.0, 45e9, 0.3, false});
        t.set_pair("ore", "ore", dem::table2::ore_ore);
        auto s = make_scene(1, {0, 0, -9.81}, t);
        s->world.add_rock(cube(0.4), 2700.0, s->rigid.material_index("rock"), 1, {0, 0, 1});
        add_sphere(s->dem, {0, 0, 3});
        CHECK_THROWS_WITH(s->world.step(), Catch::Contains("'rock 0'") && Catch::Contains("'granite'") &&
                                               Catch::Contains("'ore'") && Catch::Contains("set_pair"));
    }
}
