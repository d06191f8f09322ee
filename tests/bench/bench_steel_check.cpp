// The rock-in-steel check (CoSimulation::check_tunnelling): is a rock's centre inside a plate of the dipper?
// dipper's own test (a bounding sphere, then each plate's planes: meshes::Plate::contains) against FCL's way
// (the plates as convex solids in a dynamic AABB tree, a point as a sphere of 1 µm collided with the tree).
// The points: 20,000 rock centres at random in the dipper's box grown by 1 m, in the dipper's frame.
// Results: docs/BENCHMARKS.md.
#include "meshes/machine_geometry.h"

#include <benchmark/benchmark.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>

#include <memory>
#include <random>
#include <vector>

namespace {

using namespace dipper;

struct Scene {
    meshes::Dipper dipper = meshes::make_dipper({});
    std::vector<Vec3> points;
    Vec3 centre;
    double radius = 0.0;
    Scene()
    {
        Vec3 lo = dipper.body.surface.bounds_min_m(), hi = dipper.body.surface.bounds_max_m();
        centre = (lo + hi) * 0.5;
        radius = norm(hi - lo) * 0.5;
        std::mt19937_64 random(7);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (int k = 0; k < 20000; ++k)
            points.push_back({lo.x - 1.0 + u(random) * (hi.x - lo.x + 2.0), lo.y - 1.0 + u(random) * (hi.y - lo.y + 2.0),
                              lo.z - 1.0 + u(random) * (hi.z - lo.z + 2.0)});
    }
};

const Scene& scene()
{
    static const Scene s;
    return s;
}

void own_test(benchmark::State& state)
{
    const Scene& s = scene();
    std::size_t inside = 0;
    for (auto _ : state) {
        inside = 0;
        for (const Vec3& x : s.points) {
            if (norm_squared(x - s.centre) > s.radius * s.radius) continue;
            for (const meshes::Plate& p : s.dipper.body.plates)
                if (p.contains(x)) {
                    ++inside;
                    break;
                }
        }
        benchmark::DoNotOptimize(inside);
    }
    state.counters["points_inside"] = static_cast<double>(inside);
    state.counters["ns_per_point"] = benchmark::Counter(static_cast<double>(s.points.size()),
                                                        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void fcl_test(benchmark::State& state)
{
    const Scene& s = scene();
    // each plate's solid as a convex polyhedron: its eight corners and six quadrilateral faces
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> plates;
    fcl::DynamicAABBTreeCollisionManagerd tree;
    for (const meshes::Plate& p : s.dipper.body.plates) {
        const std::vector<Vec3> c = p.solid_corners_m();  // face corners 0-3, then the back 4-7
        auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
        for (const Vec3& v : c) vertices->emplace_back(v.x, v.y, v.z);
        auto faces = std::make_shared<std::vector<int>>(std::vector<int>{
            4, 0, 1, 2, 3, 4, 4, 7, 6, 5, 4, 0, 4, 5, 1, 4, 1, 5, 6, 2, 4, 2, 6, 7, 3, 4, 3, 7, 4, 0});
        auto convex = std::make_shared<fcl::Convexd>(vertices, 6, faces);
        plates.push_back(std::make_unique<fcl::CollisionObjectd>(convex));
        plates.back()->computeAABB();
        tree.registerObject(plates.back().get());
    }
    tree.setup();
    fcl::CollisionObjectd point(std::make_shared<fcl::Sphered>(1e-6));
    struct Hit {
        bool any = false;
    };
    const auto callback = [](fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
        Hit* hit = static_cast<Hit*>(data);
        fcl::CollisionRequestd request;
        fcl::CollisionResultd result;
        fcl::collide(a, b, request, result);
        hit->any = hit->any || result.isCollision();
        return hit->any;  // true stops the query
    };
    std::size_t inside = 0;
    for (auto _ : state) {
        inside = 0;
        for (const Vec3& x : s.points) {
            point.setTranslation(fcl::Vector3d(x.x, x.y, x.z));
            point.computeAABB();
            Hit hit;
            tree.collide(&point, &hit, callback);
            inside += hit.any ? 1 : 0;
        }
        benchmark::DoNotOptimize(inside);
    }
    state.counters["points_inside"] = static_cast<double>(inside);
    state.counters["ns_per_point"] = benchmark::Counter(static_cast<double>(s.points.size()),
                                                        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(own_test)->Unit(benchmark::kMillisecond);
BENCHMARK(fcl_test)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
