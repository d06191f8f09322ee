// Triangle-mesh walls: one contact per touched feature, equivalence with planes, moving meshes, records.
#include "core/state_io.h"
#include "dem/world.h"
#include "helpers.h"
#include "meshes/mesh_builder.h"
#include "meshes/triangle_mesh.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <random>

using namespace dipper;
using namespace dipper::dem;

namespace {

const PairCoefficients kSticky = test::coefficients(0.5, 0.0, 1.0, 1.0, 0.05, 0.27);

World sticky_world(double step_s = 0.0)
{
    WorldSettings s;
    s.step_s = step_s;
    return World(test::two_material_table(kSticky, 3700.0, 45e9, 0.3), s);
}

/// Settles one sphere of radius r at (x, y) on a mesh (or plane) floor and returns the world.
World rest_on(const meshes::TriangleMesh* mesh, double x, double y, double r = 0.1)
{
    World w = sticky_world();
    if (mesh) w.add_mesh(*mesh, 1, "floor");
    else w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
    w.add_particle({{x, y, r - 1e-6}, {}, {}, r, 0});
    while (w.time_s() < 0.2) w.step();
    return w;
}

}  // namespace

TEST_CASE("a sphere on a shared vertex, edge or face of a flat mesh gets exactly one contact", "[dem][walls][unit]")
{
    // 4 x 4 cells of 0.5 m, two triangles each: vertex (1, 1) is shared by 6 triangles, the diagonal edge of
    // cell (0, 0) by 2. Each contact must carry the full weight, as on a plane (1e-9: static, round-off).
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(2.0, 2.0, 4, 4);
    const World reference = rest_on(nullptr, 1.0, 1.0);
    const double weight = reference.particles().mass_kg[0] * 9.81;
    struct Place { const char* what; double x, y; };
    for (const Place& place : {Place{"shared vertex", 1.0, 1.0}, Place{"diagonal edge", 0.25, 0.25},
                               Place{"axis-aligned edge", 0.7, 1.0}, Place{"face", 0.3, 0.1}}) {
        CAPTURE(place.what);
        const World w = rest_on(&plate, place.x, place.y);
        CHECK(w.wall_contact_count() == 1);
        CHECK(-w.wall_force_N(0).z == Approx(weight).epsilon(1e-9));
    }
}

TEST_CASE("a sphere on a shared vertex or edge of a turned mesh gets exactly one contact", "[dem][walls][unit]")
{
    // The plate of the test above turned and moved, as a machine part is: the sphere's centre, taken into the
    // mesh's frame, lands within round-off of the vertex or edge, and each triangle around it may then find its
    // closest point inside itself (a face) or on its border. One point of the surface is one contact whichever
    // way the triangles classify it (counted without that rule, the shared vertex has five).
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(2.0, 2.0, 4, 4);
    const Mat3 turn = rotation_about_axis(normalized(Vec3{0.3, -1.0, 0.4}), 0.47);
    const Vec3 shift{21.3, -4.7, 12.9};
    struct Place { const char* what; double x, y; };
    for (const Place& place : {Place{"shared vertex", 1.0, 1.0}, Place{"diagonal edge", 0.25, 0.25},
                               Place{"axis-aligned edge", 0.7, 1.0}, Place{"face", 0.3, 0.1}}) {
        CAPTURE(place.what);
        World w = sticky_world(), plane = sticky_world();
        const int id = w.add_mesh(plate, 1, "plate");
        w.set_mesh_pose(id, turn, shift, shift, {}, {});
        const Vec3 normal = turn * Vec3{0.0, 0.0, 1.0};
        plane.add_plane(shift, normal, 1, "plane");  // the same surface as an analytic plane
        const double r = 0.1, overlap = 1e-4;
        for (World* x : {&w, &plane}) {
            x->add_particle({shift + turn * Vec3{place.x, place.y, r - overlap}, {}, {}, r, 0});
            x->step();
        }
        CHECK(w.wall_contact_count() == 1);
        const auto& records = w.last_contact_records();
        REQUIRE(!records.empty());
        CHECK(norm(records[0].normal_world - normal) < 1e-9);
        // and it pushes as the plane does: one contact's force (five would push five times as hard). The two
        // differ by the round-off of the mesh's transform, 1e-15 m in a 1e-4 m overlap: 1e-9 relative bounds it
        const Vec3 f = w.wall_force_N(id), f_plane = plane.wall_force_N(0);
        REQUIRE(norm(f_plane) > 0.0);
        CHECK(norm(f - f_plane) < 1e-9 * norm(f_plane));
    }
}

TEST_CASE("a sphere on a convex edge or corner of a box gets one contact, in a concave corner two", "[dem][walls][unit]")
{
    const meshes::TriangleMesh box = meshes::make_box_mesh({0.0, 0.0, -1.0}, {1.0, 1.0, 0.0});
    World w = sticky_world();
    w.add_mesh(box, 1, "box");
    const double r = 0.1;
    // on the top edge x = 1 (shared by the top and the +x face triangles), just overlapping, no gravity
    w.add_particle({{1.0 + 0.05, 0.5, std::sqrt(r * r - 0.05 * 0.05) - 1e-5}, {}, {}, r, 0});
    // above the corner (1, 1, 0), shared by 3 faces and 6 triangles
    w.add_particle({{1.0 + 0.05, 1.05, 0.05}, {}, {}, r, 0});
    w.step();
    CHECK(w.wall_contact_count() == 2);
    const auto& records = w.last_contact_records();
    REQUIRE(records.size() == 2);
    for (const ContactRecord& c : records) {
        // the normal points from the feature to the centre
        const Vec3 centre = w.particles().position_m[static_cast<std::size_t>(c.particle_index)];
        CHECK(norm(normalized(centre - c.point_world) - c.normal_world) < 1e-12);
    }

    // concave: floor plate and a vertical plate meeting at x = 0; a sphere in the corner touches both faces
    World corner = sticky_world();
    corner.add_mesh(meshes::make_plate_mesh(2.0, 2.0, 2, 2), 1, "floor");
    meshes::TriangleMesh wall = meshes::make_plate_mesh(2.0, 2.0, 2, 2);
    std::vector<Vec3> v = wall.vertices_m();
    for (Vec3& p : v) p = {0.0, p.x, p.y};  // the plane x = 0, normal +x
    corner.add_mesh(meshes::TriangleMesh(v, wall.triangles(), "wall"), 1, "wall");
    corner.add_particle({{r - 1e-4, 0.5, r - 1e-4}, {}, {}, r, 0});
    corner.step();
    CHECK(corner.wall_contact_count() == 2);
}

TEST_CASE("a sphere bouncing on a mesh floor moves exactly as on a plane", "[dem][walls][analytic]")
{
    const meshes::TriangleMesh plate = meshes::make_plate_mesh(2.0, 2.0, 3, 3);
    World a = sticky_world(), b = sticky_world();
    a.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
    b.add_mesh(plate, 1, "floor");
    for (World* w : {&a, &b}) w->add_particle({{0.6667, 1.0, 0.3}, {0.8, 0.3, -1.0}, {0.0, 5.0, 0.0}, 0.1, 0});
    for (int k = 0; k < 20000; ++k) {
        a.step();
        b.step();
    }
    // The same law on the same geometry: the mesh's contact point and normal come from the closest-point
    // query and differ from the plane's by round-off (1e-16 relative) each step; over 20,000 steps and
    // 1 m of travel that grows to about 1e-9 m. 1e-8 m and 1e-6 rad/s bound it; any real difference in
    // the law (a second contact, a wrong normal or lever arm) is larger by orders.
    CHECK(norm(a.particles().position_m[0] - b.particles().position_m[0]) < 1e-8);
    CHECK(norm(a.particles().angular_velocity_rad_per_s[0] - b.particles().angular_velocity_rad_per_s[0]) < 1e-6);
}

TEST_CASE("a sphere on a moving belt ends rolling at 2/7 of the belt speed", "[dem][walls][analytic]")
{
    // Friction impulse J: m v = J, I omega = J r, rolling when v - omega r = u  ->  v = 2 u / 7 (mu_roll = 0).
    // The tangential spring's stick phase oscillates around the final state and dies with D_t = 1; 0.5 %.
    const double u = 1.0;
    PrescribedMotion belt;
    belt.velocity_m_per_s = {u, 0.0, 0.0};
    World w = sticky_world();
    w.add_mesh(meshes::make_plate_mesh(40.0, 2.0, 40, 2), 1, "belt", belt);
    w.add_particle({{1.0, 1.0, 0.1 - 1e-6}, {}, {}, 0.1, 0});
    while (w.time_s() < 1.0) w.step();
    CHECK(w.particles().velocity_m_per_s[0].x == Approx(2.0 / 7.0 * u).epsilon(5e-3));
    // rolling: contact point moves with the belt
    const double contact_speed = w.particles().velocity_m_per_s[0].x - w.particles().angular_velocity_rad_per_s[0].y * 0.1;
    CHECK(contact_speed == Approx(u).epsilon(5e-3));
}

TEST_CASE("a rotating mesh wall moves its vertices and reports the rigid velocity field", "[dem][walls][unit]")
{
    PrescribedMotion spin;
    spin.angular_velocity_rad_per_s = {0.0, 0.0, 2.0};
    spin.pivot_m = {1.0, 0.0, 0.0};
    WorldSettings s;
    s.step_s = 2.5e-4;
    World w(test::two_material_table(kSticky), s);
    const int id = w.add_mesh(meshes::make_plate_mesh(2.0, 2.0, 1, 1), 1, "turntable", spin);
    w.add_particle({{5.0, 5.0, 5.0}, {}, {}, 0.1, 0});  // far away: only time passes
    w.run_steps(1000);                                   // t = 0.25 s: turned 0.5 rad about (1, 0, 0)
    const MeshWall& m = w.mesh_wall(id);
    const Vec3 corner = m.vertices_world_m()[0];         // body (0, 0, 0), 1 m from the pivot along -x
    CHECK(corner.x == Approx(1.0 - std::cos(0.5)).epsilon(1e-12));
    CHECK(corner.y == Approx(-std::sin(0.5)).epsilon(1e-12));
    const Vec3 v = m.velocity_at({1.0, 1.0, 0.0});
    CHECK(v.x == Approx(-2.0).epsilon(1e-12));
}

TEST_CASE("the bound on a moved mesh's vertex travel is never below the true travel, and exact for a shift",
          "[dem][walls][unit]")
{
    // the neighbour lists rebuild when a mesh may have moved its vertices by the skin: the bound from two
    // poses must cover every vertex; a pure translation moves every vertex by exactly |dT|
    MeshWall m(meshes::make_box_mesh({0.0, 0.0, -1.0}, {2.0, 1.0, 0.5}), 1, "box");
    const Mat3 r0 = rotation_about_axis(normalized(Vec3{1.0, 2.0, 3.0}), 0.7);
    const Vec3 t0{0.3, -1.0, 2.0};
    m.set_pose(r0, t0, {}, {}, {});
    const std::vector<Vec3> before = m.vertices_world_m();
    m.set_pose(r0, t0 + Vec3{0.01, -0.02, 0.005}, {}, {}, {});
    CHECK(m.max_vertex_move_m(r0, t0) == Approx(norm(Vec3{0.01, -0.02, 0.005})).epsilon(1e-12));
    double worst_ratio = 1e300;
    for (int k = 1; k <= 200; ++k) {
        const double angle = 1e-4 * k * k;  // 1e-4 to 4 rad
        const Mat3 r = rotation_about_axis(normalized(Vec3{std::sin(1.0 * k), std::cos(3.0 * k), 0.5}), angle) * r0;
        const Vec3 t = t0 + Vec3{1e-3 * std::sin(2.0 * k), 0.0, 1e-3 * k};
        m.set_pose(r, t, {}, {}, {});
        const auto& after = m.vertices_world_m();
        double travel = 0.0;
        for (std::size_t v = 0; v < after.size(); ++v) travel = std::max(travel, norm(after[v] - before[v]));
        const double bound = m.max_vertex_move_m(r0, t0);
        CHECK(bound >= travel * (1.0 - 1e-12));
        worst_ratio = std::min(worst_ratio, travel / bound);
    }
    // and not wildly conservative: it asks for a rebuild at most about twice as early as needed
    CHECK(worst_ratio > 0.4);
}

TEST_CASE("a contact consumer gets the contacts of its walls alone, as the full records list them", "[dem][walls][unit]")
{
    // A floor plane, an open plate and a convex box (a rock's kind of wall, whose contacts live apart), a sphere
    // on each and one between plate and box; the consumer of some walls gets exactly the full records of those
    // walls, field for field and in the same order, at every step
    World w = sticky_world();
    const int floor = w.add_plane({0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 1, "floor");
    const int plate = w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 4, 4), 1, "plate");
    w.set_mesh_pose(plate, Mat3::identity(), {2.0, 0.0, 0.3}, {}, {}, {});
    const int box = w.add_mesh(meshes::make_box_mesh({3.0, 0.0, 0.0}, {4.0, 1.0, 0.3}), 1, "box");
    REQUIRE(w.mesh_wall(box).convex());
    REQUIRE_FALSE(w.mesh_wall(plate).convex());
    const double r = 0.1;
    for (const Vec3& x : {Vec3{0.5, 0.5, r - 1e-4}, Vec3{2.5, 0.5, 0.3 + r - 1e-4}, Vec3{3.5, 0.5, 0.3 + r - 1e-4},
                          Vec3{3.5, -r + 1e-4, 0.15}})
        w.add_particle({x, {}, {}, r, 0});
    const auto same = [](const ContactRecord& a, const ContactRecord& b) {
        return a.point_world == b.point_world && a.normal_world == b.normal_world && a.normal_force_N == b.normal_force_N &&
               a.tangential_force_N == b.tangential_force_N && a.relative_displacement_m == b.relative_displacement_m &&
               a.overlap_m == b.overlap_m && a.surface_id == b.surface_id && a.triangle_id == b.triangle_id &&
               a.particle_index == b.particle_index && a.particle_mass_kg == b.particle_mass_kg && a.first_step == b.first_step;
    };
    for (const std::vector<int>& walls : {std::vector<int>{plate}, std::vector<int>{box}, std::vector<int>{floor, box},
                                          std::vector<int>{}}) {
        CAPTURE(walls);
        std::vector<ContactRecord> seen;
        w.set_contact_consumer([&](const std::vector<ContactRecord>& records, double, double) { seen = records; }, walls);
        for (int step = 0; step < 3; ++step) {
            w.step();
            std::vector<ContactRecord> expected;
            for (const ContactRecord& c : w.last_contact_records())
                if (std::find(walls.begin(), walls.end(), c.surface_id) != walls.end()) expected.push_back(c);
            CHECK(expected.size() == (walls.empty() ? 0u : walls.size() == 1 && walls[0] == plate ? 1u : walls[0] == box ? 2u : 3u));
            REQUIRE(seen.size() == expected.size());
            const std::vector<ContactRecord> asked = w.contact_records(walls);
            REQUIRE(asked.size() == expected.size());
            for (std::size_t k = 0; k < expected.size(); ++k) {
                CHECK(same(seen[k], expected[k]));
                CHECK(same(asked[k], expected[k]));
            }
        }
    }
    CHECK_THROWS_WITH(w.set_contact_consumer([](const std::vector<ContactRecord>&, double, double) {}, {7}),
                      Catch::Contains("set_contact_consumer: no wall 7; the world has walls 0 to 2"));
}

TEST_CASE("contact records carry force, point and relative displacement of a sliding sphere", "[dem][walls][unit]")
{
    // A sphere pushed along a mesh floor slides at 1 m/s with mu 0.5 (no rolling: spin locked by a high
    // rolling stiffness is not needed, the check is per step): Fn = m g, |Ft| = mu m g, d = v dt.
    WorldSettings s;
    World w(test::two_material_table(test::coefficients(0.5, 0.0, 1.0, 1.0, 0.05, 0.27), 3700.0, 45e9, 0.3), s);
    const int floor = w.add_mesh(meshes::make_plate_mesh(4.0, 2.0, 8, 4), 1, "floor");
    const double r = 0.1;
    w.add_particle({{0.5, 1.0, r - 1e-6}, {}, {}, r, 0});
    while (w.time_s() < 0.1) w.step();
    std::vector<ContactRecord> seen;
    w.set_contact_consumer([&](const std::vector<ContactRecord>& records, double, double) { seen = records; }, {floor});
    w.particles().velocity_m_per_s[0] = {3.0, 0.0, 0.0};
    w.step();
    REQUIRE(seen.size() == 1);
    const ContactRecord& c = seen[0];
    const double weight = w.particles().mass_kg[0] * 9.81;
    CHECK(c.surface_id == floor);
    CHECK(c.triangle_id >= 0);
    CHECK(c.normal_force_N == Approx(weight).epsilon(0.05));
    CHECK(norm(c.tangential_force_N) == Approx(0.5 * c.normal_force_N).epsilon(1e-12));
    CHECK(c.relative_displacement_m.x == Approx(3.0 * w.step_s()).epsilon(0.01));
    CHECK(c.point_world.z == Approx(0.0).margin(1e-12));
}

TEST_CASE("a mesh moved from outside is seen by the neighbour lists", "[dem][walls][unit]")
{
    // A plate 1 m away approaches a free sphere at 1 m/s, moved only through set_mesh_pose (as the coupling
    // moves machine parts). The lists were built when the plate was far beyond the skin: it must still hit
    // the sphere and push it along -x (an elastic push from a massive wall: about twice the plate speed).
    WorldSettings s;
    s.gravity_m_per_s2 = {};
    s.step_s = 5e-6;  // 1/60 of the contact time: the discrete wall motion's error is O((omega dt)^2)
    World w(test::two_material_table(test::coefficients(0.0, 0.0, 0.0, 0.0, 0.05, 0.27), 3700.0, 45e9, 0.3), s);
    meshes::TriangleMesh plate = meshes::make_plate_mesh(1.0, 1.0, 2, 2);
    std::vector<Vec3> v = plate.vertices_m();
    for (Vec3& p : v) p = {0.0, p.x - 0.5, p.y - 0.5};  // the plane x = 0 with normal +x
    const int id = w.add_mesh(meshes::TriangleMesh(v, plate.triangles(), "plate"), 1, "plate");
    w.add_particle({{0.0, 0.0, 0.0}, {}, {}, 0.1, 0});
    const Mat3 face_minus_x = rotation_about_axis({0.0, 0.0, 1.0}, M_PI);  // normal +x turned to -x
    while (w.time_s() < 1.2) {
        const double t = w.time_s() + w.step_s();
        const Vec3 position{1.0 - t, 0.0, 0.0};
        w.set_mesh_pose(id, face_minus_x, position, position, {-1.0, 0.0, 0.0}, {});
        w.step();
    }
    CHECK(w.particles().velocity_m_per_s[0].x == Approx(-2.0).epsilon(1e-3));
}

TEST_CASE("a convex body moved or given a mass from outside is seen by its sphere contacts in the next step",
          "[dem][walls][unit]")
{
    // The wall phase keeps a small record of each body's pose and motion, refreshed when the body is moved or
    // given a mass. A sphere rests on a 1 m box (no gravity, no friction); after the first step the box is
    // raised 20 um and given an upward speed, then a mass, between steps. Each step's contact must be that of
    // the box where it is now: the overlap r minus the centre's distance to the moved surface, and the normal
    // force of eq. 3 and 6 with the relative speed the record reports and the effective mass m M / (m + M).
    // A stale pose would be 20 um off; a stale mass changes the damping term by a factor of 30.
    WorldSettings settings;
    settings.gravity_m_per_s2 = {};
    settings.step_s = 1e-6;
    const PairCoefficients pair = test::coefficients(0.0, 0.0, 0.5, 0.5, 0.05, 0.27);
    const MaterialTable table = test::two_material_table(pair, 3700.0, 45e9, 0.3);
    World w(table, settings);
    const meshes::TriangleMesh box = meshes::make_box_mesh({-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5});
    const int id = w.add_mesh(box, 1, "box");
    const double r = 0.05;
    w.add_particle({{0.1, 0.2, 0.5 + r - 1e-4}, {}, {}, r, 0});
    const double m = w.particles().mass_kg[0];
    const double kn = wall_normal_stiffness(table.material(0).bulk_modulus_Pa(), r, pair.normal_stiffness_scale);

    auto check_contact = [&](const Vec3& box_centre, double body_mass_kg) {
        const auto& records = w.last_contact_records();
        REQUIRE(records.size() == 1);
        const ContactRecord& c = records[0];
        const Vec3 x = w.particles().position_m[0];
        CHECK(c.overlap_m == Approx(r - box.distance_m(x - box_centre)).margin(1e-13));
        const double vn = dot(c.relative_displacement_m, c.normal_world) / w.step_s();
        const double effective = body_mass_kg > 0.0 ? m * body_mass_kg / (m + body_mass_kg) : m;
        const double damping = pair.normal_damping_ratio * 2.0 * std::sqrt(effective * kn);
        CHECK(c.normal_force_N == Approx(kn * c.overlap_m - damping * vn).epsilon(1e-10));
        return damping * std::abs(vn);
    };
    w.step();
    check_contact({}, 0.0);

    const Vec3 raised{0.0, 0.0, 2e-5};
    w.set_mesh_pose(id, Mat3::identity(), raised, raised, {0.0, 0.0, 0.05}, {});
    w.step();
    const double damping_immovable = check_contact(raised, 0.0);
    CHECK(damping_immovable > 1e-3 * kn * 1e-4);  // the damping term is there to be seen

    w.set_wall_mass_kg(id, m / 1000.0);
    w.step();
    const double damping_light = check_contact(raised, m / 1000.0);
    CHECK(damping_light < 0.1 * damping_immovable);
}

TEST_CASE("spheres around a convex mesh touch it exactly where their centre is within a radius of its surface",
          "[dem][walls][unit]")
{
    // A convex mesh lets the search stop at the first candidate face whose plane the centre lies a radius in
    // front of. 400 spheres of r = 50 mm at random places 30-80 mm from a box's surface (overlaps up to 0.4 r,
    // below the 0.5 r the step refuses), none touching another,
    // no gravity: after one step the contacts must be exactly those of the closest-point rule, measured here
    // with the mesh's own distance function, and each touching sphere has exactly one (off edges and corners).
    const meshes::TriangleMesh box = meshes::make_box_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0});
    const meshes::TriangleMesh container = meshes::make_open_box_mesh(1.0, 1.0, 1.0, 0.5);
    CHECK(MeshWall(box, 1, "box").convex());
    CHECK_FALSE(MeshWall(meshes::make_plate_mesh(1.0, 1.0, 2, 2), 1, "plate").convex());  // open: two-sided
    CHECK_FALSE(MeshWall(container, 1, "container").convex());                            // open upwards

    WorldSettings settings;
    settings.gravity_m_per_s2 = {};
    World w(test::two_material_table(kSticky, 3700.0, 45e9, 0.3), settings);
    w.add_mesh(box, 1, "box");
    const double r = 0.05;
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Vec3> placed;
    std::size_t touching = 0;
    while (placed.size() < 400) {
        // a point on the surface of the box grown by d in [30, 80] mm: a random face, then a random spot on it
        const double d = 0.03 + 0.05 * unit(rng);
        const int face = static_cast<int>(6.0 * unit(rng)) % 6, axis = face / 2;
        Vec3 p{-d + (1.0 + 2.0 * d) * unit(rng), -d + (1.0 + 2.0 * d) * unit(rng), -d + (1.0 + 2.0 * d) * unit(rng)};
        (axis == 0 ? p.x : axis == 1 ? p.y : p.z) = face % 2 == 0 ? -d : 1.0 + d;
        bool clear = true;
        for (const Vec3& q : placed) clear = clear && norm(p - q) > 2.0 * r + 1e-3;
        if (!clear) continue;
        placed.push_back(p);
        if (box.distance_m(p) < r) ++touching;
        w.add_particle({p, {}, {}, r, 0});
    }
    REQUIRE(touching > 50);                 // both kinds are there in numbers
    REQUIRE(touching < placed.size() - 50);
    w.step();
    CHECK(w.wall_contact_count() == touching);
    std::vector<int> per_particle(placed.size(), 0);
    for (const ContactRecord& c : w.last_contact_records()) {
        const auto i = static_cast<std::size_t>(c.particle_index);
        ++per_particle[i];
        // the one contact is at the closest point: its overlap is r minus the distance (to round-off of
        // coordinates near 1 m) and its point lies on the surface, a radius minus the overlap from the centre,
        // along the unit normal (over a face, the face's plane gives all three)
        const Vec3 x = w.particles().position_m[i];
        CHECK(c.overlap_m == Approx(r - box.distance_m(x)).margin(1e-12));
        CHECK(box.distance_m(c.point_world) == Approx(0.0).margin(1e-12));
        CHECK(norm(c.point_world - x) == Approx(r - c.overlap_m).margin(1e-12));
        CHECK(norm(c.normal_world) == Approx(1.0).margin(1e-12));
        CHECK(norm(x - c.point_world - c.normal_world * (r - c.overlap_m)) < 1e-12);
    }
    for (std::size_t i = 0; i < placed.size(); ++i)
        CHECK(per_particle[i] == (box.distance_m(w.particles().position_m[i]) < r ? 1 : 0));

    // The same box and spheres turned and moved as one: the same contacts, turned and moved (the search works in
    // the body's frame and hands back world normals and points). Tolerance: round-off of coordinates near 3 m.
    const Mat3 turn = rotation_about_axis(normalized(Vec3{1.0, 2.0, 3.0}), 0.7);
    const Vec3 shift{2.0, -1.0, 0.5};
    World turned(test::two_material_table(kSticky, 3700.0, 45e9, 0.3), settings);
    const int id = turned.add_mesh(box, 1, "box");
    turned.set_mesh_pose(id, turn, shift, shift, {}, {});
    for (const Vec3& p : placed) turned.add_particle({turn * p + shift, {}, {}, r, 0});
    turned.step();
    // the records by the spheres' stable ids (each world orders its spheres by its own grid)
    auto by_id = [](const World& world) {
        std::map<std::uint32_t, ContactRecord> out;
        for (const ContactRecord& c : world.last_contact_records())
            out[world.particles().id[static_cast<std::size_t>(c.particle_index)]] = c;
        return out;
    };
    const auto plain = by_id(w), moved = by_id(turned);
    REQUIRE(moved.size() == plain.size());
    for (const auto& [sphere, a] : plain) {
        REQUIRE(moved.count(sphere) == 1);
        const ContactRecord& b = moved.at(sphere);
        CHECK(b.overlap_m == Approx(a.overlap_m).margin(1e-12));
        CHECK(norm(b.normal_world - turn * a.normal_world) < 1e-12);
        CHECK(norm(b.point_world - (turn * a.point_world + shift)) < 1e-11);
    }
}

TEST_CASE("contacts on a convex body keep their history over neighbour-list rebuilds and checkpoints", "[dem][walls][unit]")
{
    // Four spheres roll down the top of a box (a convex body) with gravity tilted 20 deg. Friction keeps them from
    // slipping through the tangential spring, and the rolling spring holds its limit: both are contact history.
    // A world that rebuilds its lists every step, and one restored from a checkpoint half-way, must move bit for
    // bit as one that rebuilds only when the skin is used up, and give the box the same reaction, on one thread and
    // on two (the threads' shares of the pairs come from the pairs' state). A contact that lost its history at a
    // rebuild would restart both springs from zero, and its sphere would slip and roll differently.
    const int threads = GENERATE(1, 2);
    const double r = 0.05, tilt = 20.0 * 3.14159265358979323846 / 180.0;
    auto make = [&]() {
        WorldSettings settings;
        settings.threads = threads;
        settings.gravity_m_per_s2 = {9.81 * std::sin(tilt), 0.0, -9.81 * std::cos(tilt)};
        World w(test::two_material_table(test::coefficients(0.5, 0.1, 0.3, 0.3, 0.05), 3700.0, 45e9, 0.3), settings);
        w.add_mesh(meshes::make_box_mesh({0.0, 0.0, 0.0}, {4.0, 1.0, 1.0}), 1, "box");
        for (int k = 0; k < 4; ++k) w.add_particle({{0.3, 0.15 + 0.2 * k, 1.0 + r - 1e-6}, {}, {}, r, 0});
        return w;
    };
    // position, velocity and spin of each particle, by id (a rebuild reorders the particles)
    auto state = [](const World& w) {
        std::vector<std::pair<std::uint32_t, std::array<Vec3, 3>>> out;
        const ParticleStore& p = w.particles();
        for (std::size_t i = 0; i < p.size(); ++i)
            out.push_back({p.id[i], {p.position_m[i], p.velocity_m_per_s[i], p.angular_velocity_rad_per_s[i]}});
        std::sort(out.begin(), out.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        return out;
    };
    auto same = [](const std::array<Vec3, 3>& x, const std::array<Vec3, 3>& y) {
        for (int q = 0; q < 3; ++q)
            if (!(x[q].x == y[q].x && x[q].y == y[q].y && x[q].z == y[q].z)) return false;
        return true;
    };
    constexpr int kSteps = 3000;
    World plain = make(), rebuilt = make(), first_half = make();
    for (int s = 0; s < kSteps; ++s) {
        plain.step();
        rebuilt.request_rebuild();
        rebuilt.step();
        if (s < kSteps / 2) first_half.step();
        if (s >= kSteps / 2) REQUIRE(rebuilt.wall_contact_count() == 4);  // settled on the box by then
    }
    const std::string path = (std::filesystem::temp_directory_path() / "dipper_convex_history.state").string();
    StateWriter writer;
    first_half.write_state(writer);
    writer.save(path, "dipper-test 1");
    World restored = make();
    {
        StateReader reader(path, "dipper-test 1");
        restored.read_state(reader);
        reader.finish();
    }
    std::filesystem::remove(path);
    for (int s = kSteps / 2; s < kSteps; ++s) restored.step();

    INFO("threads " << threads << ", step " << plain.step_s() << " s, time " << plain.time_s() << " s");
    for (const World* other : {&rebuilt, &restored}) {
        const Vec3 f = plain.wall_force_N(0), t = plain.wall_torque_N_m(0);
        CHECK((f.x == other->wall_force_N(0).x && f.y == other->wall_force_N(0).y && f.z == other->wall_force_N(0).z));
        CHECK((t.x == other->wall_torque_N_m(0).x && t.y == other->wall_torque_N_m(0).y && t.z == other->wall_torque_N_m(0).z));
    }
    CHECK(rebuilt.rebuild_count() >= static_cast<std::uint64_t>(kSteps));
    CHECK(plain.rebuild_count() < 20);
    const auto a = state(plain), b = state(rebuilt), c = state(restored);
    REQUIRE(a.size() == 4);
    for (std::size_t k = 0; k < a.size(); ++k) {
        INFO("particle " << a[k].first);
        CHECK(a[k].second[1].x > 0.1);  // rolling down the slope, not sliding off at once nor held
        CHECK(a[k].second[1].x < 9.81 * std::sin(tilt) * plain.time_s());
        CHECK(same(a[k].second, b[k].second));
        CHECK(same(a[k].second, c[k].second));
    }
}

TEST_CASE("a sphere whose centre lies inside a convex body is pushed out through the nearest face and stops the run",
          "[dem][walls][unit]")
{
    // A centre behind every face plane of a convex body gets one contact on the face whose plane is nearest: the
    // normal of that face, the point on its plane, an overlap of r plus the depth. That overlap exceeds the radius,
    // so the overlap limit (at most 1 r) always stops the run with a diagnosis naming the body and the depth.
    // Box [0, 1]^3, r = 0.1 m, centre (0.99, 0.5, 0.98): 0.01 m inside the side x = 1 and 0.02 m below the top,
    // both within the skin (0.03 m) so both are candidates; the side is nearest: normal +x, point x = 1, overlap
    // 0.11 m. The records and the diagnosis come from the end of the step, after the push has moved the centre
    // out by about a millimetre: the overlap is then r + (1 - x) at that centre (to round-off of coordinates near
    // 1 m, hence the 1e-12 margins).
    WorldSettings settings;
    settings.gravity_m_per_s2 = {};
    World w(test::two_material_table(kSticky, 3700.0, 45e9, 0.3), settings);
    const int box = w.add_mesh(meshes::make_box_mesh({0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}), 1, "box");
    const double r = 0.1;
    w.add_particle({{0.99, 0.5, 0.98}, {}, {}, r, 0});
    std::vector<ContactRecord> seen;
    w.set_contact_consumer([&](const std::vector<ContactRecord>& records, double, double) { seen = records; }, {box});
    std::string message;
    try {
        w.step();
    } catch (const SimulationError& e) {
        message = e.what();
    }
    INFO(message);
    REQUIRE(seen.size() == 1);
    CHECK(seen[0].normal_world.x == Approx(1.0).margin(1e-12));
    CHECK(std::abs(seen[0].normal_world.y) + std::abs(seen[0].normal_world.z) < 1e-12);
    const Vec3 x = w.particles().position_m[0];
    CHECK(x.x > 0.99);  // pushed out along +x, the nearest face, not through the top
    CHECK(x.x < 1.0);
    CHECK(x.z == Approx(0.98).margin(1e-12));
    CHECK(seen[0].point_world.x == Approx(1.0).margin(1e-12));
    CHECK(seen[0].point_world.z == Approx(0.98).margin(1e-12));
    CHECK(seen[0].overlap_m == Approx(r + (1.0 - x.x)).margin(1e-12));
    CHECK(seen[0].overlap_m > 0.1);
    CHECK(seen[0].normal_force_N > 0.0);
    CHECK_THAT(message, Catch::Contains("overlaps wall 'box'"));
    const std::size_t by = message.find(" by ");
    REQUIRE(by != std::string::npos);
    CHECK(std::stod(message.substr(by + 4)) == Approx(seen[0].overlap_m / r).margin(1e-5));  // printed to 6 digits
}

TEST_CASE("an open plate is touched from both sides", "[dem][walls][unit]")
{
    // An open surface is two-sided (a door or a pan is met from either side): a sphere resting 40 mm into a
    // flat plate from above and one from below each get one contact, pushing them apart from the plate.
    WorldSettings settings;
    settings.gravity_m_per_s2 = {};
    World w(test::two_material_table(kSticky, 3700.0, 45e9, 0.3), settings);
    w.add_mesh(meshes::make_plate_mesh(1.0, 1.0, 4, 4), 1, "plate");  // z = 0, normal +z
    const double r = 0.05;
    w.add_particle({{0.3, 0.3, r - 0.004}, {}, {}, r, 0});
    w.add_particle({{0.6, 0.6, -(r - 0.004)}, {}, {}, r, 0});
    w.step();
    REQUIRE(w.wall_contact_count() == 2);
    CHECK(w.particles().velocity_m_per_s[0].z > 0.0);
    CHECK(w.particles().velocity_m_per_s[1].z < 0.0);
}
