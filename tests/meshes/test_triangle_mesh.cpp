// Triangle meshes: closest-point features, topology, inside tests, file loading.
#include "meshes/mesh_builder.h"
#include "meshes/mesh_io.h"
#include "meshes/triangle_locator.h"
#include "meshes/triangle_mesh.h"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <random>

using namespace dipper;
using namespace dipper::meshes;

TEST_CASE("closest point on a triangle is found on the right feature", "[meshes][unit]")
{
    const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    struct Case { Vec3 p; Feature f; int index; Vec3 q; };
    for (const Case& k : {Case{{0.2, 0.2, 0.5}, Feature::Face, 0, {0.2, 0.2, 0}},
                          Case{{0.5, -0.3, 0.1}, Feature::Edge, 0, {0.5, 0, 0}},
                          Case{{0.8, 0.8, -0.2}, Feature::Edge, 1, {0.5, 0.5, 0}},
                          Case{{-0.3, 0.5, 0.0}, Feature::Edge, 2, {0, 0.5, 0}},
                          Case{{-1, -1, 1}, Feature::Vertex, 0, a},
                          Case{{2, -0.1, 0}, Feature::Vertex, 1, b},
                          Case{{-0.1, 3, 0}, Feature::Vertex, 2, c}}) {
        const ClosestPoint cp = closest_point_on_triangle(k.p, a, b, c);
        CHECK(cp.feature == k.f);
        if (k.f != Feature::Face) CHECK(cp.local_index == k.index);
        CHECK(norm(cp.point - k.q) < 1e-15);
        CHECK(cp.distance_squared == Approx(norm_squared(k.p - k.q)).epsilon(1e-14));
    }
}

TEST_CASE("shared edges are numbered once", "[meshes][unit]")
{
    // a plate of nx x ny cells: (nx+1) ny + nx (ny+1) grid edges and nx ny diagonals
    const TriangleMesh plate = make_plate_mesh(2.0, 1.0, 4, 3);
    CHECK(plate.triangle_count() == 24);
    CHECK(plate.vertex_count() == 20);
    CHECK(plate.edge_count() == 5 * 3 + 4 * 4 + 12);
    CHECK(plate.total_area_m2() == Approx(2.0).epsilon(1e-14));
    // a closed box: Euler V - E + F = 2
    const TriangleMesh box = make_box_mesh({0, 0, 0}, {1, 2, 3});
    CHECK(box.vertex_count() - box.edge_count() + box.triangle_count() == 2);
    CHECK(box.total_area_m2() == Approx(2.0 * (2 + 3 + 6)).epsilon(1e-14));
    for (std::size_t t = 0; t < box.triangle_count(); ++t) {
        // outward normals: the centre lies behind every face
        const Vec3 on_face = box.vertices_m()[box.triangles()[t][0]];
        CHECK(dot(Vec3{0.5, 1.0, 1.5} - on_face, box.triangle_normal(t)) < 0.0);
    }
}

TEST_CASE("inside test and distance of a closed mesh", "[meshes][unit]")
{
    const TriangleMesh box = make_box_mesh({0, 0, 0}, {1, 2, 3});
    CHECK(box.contains({0.5, 1.0, 1.5}));
    CHECK(box.contains({0.01, 0.01, 0.01}));
    CHECK_FALSE(box.contains({1.5, 1.0, 1.5}));
    CHECK_FALSE(box.contains({-0.01, 1.0, 1.5}));
    CHECK(box.distance_m({0.5, 1.0, 1.5}) == Approx(0.5).epsilon(1e-14));
    CHECK(box.distance_m({2.0, 1.0, 1.5}) == Approx(1.0).epsilon(1e-14));
}

TEST_CASE("STL, OBJ and PLY files load into the same mesh", "[meshes][unit]")
{
    const TriangleMesh box = make_box_mesh({0, 0, 0}, {1, 2, 3});
    const std::filesystem::path dir = std::filesystem::temp_directory_path();
    write_stl(box, (dir / "dipper_box_roundtrip.stl").string());
    const TriangleMesh from_stl = load_triangle_mesh((dir / "dipper_box_roundtrip.stl").string());
    CHECK(from_stl.triangle_count() == 12);
    CHECK(from_stl.vertex_count() == 8);  // identical vertices merged, so edges are shared
    CHECK(from_stl.edge_count() == 18);
    CHECK(from_stl.total_area_m2() == Approx(box.total_area_m2()).epsilon(1e-12));

    {
        std::ofstream obj(dir / "dipper_square.obj");
        obj << "v 0 0 0\nv 1000 0 0\nv 1000 1000 0\nv 0 1000 0\nf 1 2 3\nf 1 3 4\n";
        std::ofstream ply(dir / "dipper_square.ply");
        ply << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n";
    }
    const TriangleMesh from_obj = load_triangle_mesh((dir / "dipper_square.obj").string(), 0.001);  // file in millimetres
    const TriangleMesh from_ply = load_triangle_mesh((dir / "dipper_square.ply").string());
    CHECK(from_obj.total_area_m2() == Approx(1.0).epsilon(1e-12));
    CHECK(from_ply.total_area_m2() == Approx(1.0).epsilon(1e-12));
    CHECK(from_obj.edge_count() == 5);
    CHECK(from_ply.edge_count() == 5);
}

TEST_CASE("the triangle locator finds the same nearest triangle as a search of all triangles", "[meshes][unit]")
{
    const meshes::TriangleMesh box = meshes::make_open_box_mesh(2.0, 1.5, 0.8, 0.075);
    const meshes::TriangleLocator locator(box);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> x(-0.5, 2.5), y(-0.5, 2.0), z(-0.5, 1.3);
    for (int k = 0; k < 500; ++k) {
        const Vec3 p{x(rng), y(rng), z(rng)};
        double best = 1e300;
        for (const auto& t : box.triangles()) {
            const auto c = meshes::closest_point_on_triangle(p, box.vertices_m()[t[0]], box.vertices_m()[t[1]], box.vertices_m()[t[2]]);
            best = std::min(best, c.distance_squared);
        }
        const auto hit = locator.nearest(p);
        CAPTURE(p.x, p.y, p.z);
        REQUIRE(hit.triangle >= 0);
        CHECK(hit.distance_m == Approx(std::sqrt(best)).margin(1e-12));
    }
    // a point far outside the grid still finds its nearest triangle
    CHECK(locator.nearest({10.0, 0.5, 0.4}).distance_m == Approx(8.0).margin(1e-12));
}
