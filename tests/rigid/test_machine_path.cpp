// The machine's path from its curves alone against the multibody that follows them, and FCL's crossings of a
// part with a plane and a mesh found where and when the multibody's own parts reach into them.
#include "core/errors.h"
#include "meshes/machine_geometry.h"
#include "rigid/machine_path.h"
#include "rigid/rigid_world.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace dipper;
using namespace dipper::rigid;

namespace {

RigidWorld steel_world()
{
    RigidWorld w;
    w.add_material("steel");
    return w;
}

/// The path's sample nearest to time t.
std::size_t nearest_sample(const PartPath& p, double t)
{
    const auto it = std::lower_bound(p.times_s.begin(), p.times_s.end(), t);
    std::size_t k = static_cast<std::size_t>(it - p.times_s.begin());
    if (k == p.times_s.size() || (k > 0 && t - p.times_s[k - 1] < p.times_s[k] - t)) --k;
    return k;
}

/// The largest distance between the corners of a part's box at two poses.
double largest_gap(const meshes::TriangleMesh& surface, const Mat3& ra, const Vec3& oa, const Mat3& rb, const Vec3& ob)
{
    const Vec3 lo = surface.bounds_min_m(), hi = surface.bounds_max_m();
    double most = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c{(k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z};
        most = std::max(most, norm((ra * c + oa) - (rb * c + ob)));
    }
    return most;
}

}  // namespace

TEST_CASE("the path from the curves alone is where the multibody takes the dipper and the door through a whole pass", "[machine_path]")
{
    const ShovelGeometry g;
    const meshes::Dipper dipper = meshes::make_dipper({});
    const Vec3 position{5.0, -2.0, 0.0};
    const double heading = 30.0;
    const MotionCurves cycle = default_loading_cycle(g, dipper, 2.0);  // with propel after the dump
    const std::vector<PartPath> path = shovel_path(g, dipper, cycle, position, heading, 0.01);
    REQUIRE(path.size() == 5);
    CHECK(path[3].name == "dipper");
    CHECK(path[4].name == "door");
    CHECK(path[3].times_s.front() == 0.0);
    CHECK(path[3].times_s.back() == cycle.duration_s());

    RigidWorld w = steel_world();
    w.add_rope_shovel(dipper, g, cycle, w.material_index("steel"), position, heading);
    double worst_dipper = 0.0, worst_door = 0.0;
    const double dt = 1e-3;
    for (int step = 1; step <= 46000; ++step) {  // the first pass: dig, swing, dump, swing back with propel
        w.step(dt);
        if (step % 500 != 0) continue;
        const double t = step * dt;
        Mat3 r;
        Vec3 o;
        w.dipper_pose(r, o);
        const std::size_t k = nearest_sample(path[3], t);
        REQUIRE(std::abs(path[3].times_s[k] - t) <= 0.025);  // samples at most 0.05 s apart
        worst_dipper = std::max(worst_dipper, largest_gap(dipper.body.surface, r, o, path[3].rotations[k], path[3].origins_m[k]));
        w.door_pose(r, o);
        worst_door = std::max(worst_door, largest_gap(dipper.door.surface, r, o, path[4].rotations[k], path[4].origins_m[k]));
    }
    // The multibody's dipper hangs on ropes that stretch under its weight (about 3 cm at 2.4e8 N of EA) and its
    // drives reach each target a step late while the swing carries the dipper at up to 4 m/s (4 mm per step);
    // the nearest sample is up to 5 ms away. 0.15 m is what the path check can be trusted to.
    INFO("largest distance of a box corner, dipper " << worst_dipper << " m, door " << worst_door << " m");
    CHECK(worst_dipper < 0.15);
    CHECK(worst_door < 0.15);
}

TEST_CASE("a plane and a mesh across the swing are found where and when the multibody's dipper reaches into them", "[machine_path]")
{
    const ShovelGeometry g;
    const meshes::Dipper dipper = meshes::make_dipper({});
    const MotionCurves cycle = default_loading_cycle(g, dipper);
    const std::vector<PartPath> path = shovel_path(g, dipper, cycle, {}, 0.0);

    // the multibody's own dipper: the first time, after the dig, that a corner of its box reaches y > 6 m as it
    // swings towards +y
    RigidWorld w = steel_world();
    w.add_rope_shovel(dipper, g, cycle, w.material_index("steel"));
    const double wall_y = 6.0, depth = 0.02;
    double first_in = -1.0;
    const Vec3 lo = dipper.body.surface.bounds_min_m(), hi = dipper.body.surface.bounds_max_m();
    for (int step = 1; step <= 30000 && first_in < 0.0; ++step) {
        w.step(1e-3);
        Mat3 r;
        Vec3 o;
        w.dipper_pose(r, o);
        for (const Vec3& v : dipper.body.surface.vertices_m())
            if ((r * v + o).y > wall_y + depth) first_in = step * 1e-3;
        (void)lo;
        (void)hi;
    }
    REQUIRE(first_in > 15.0);  // the dig ends at 15 s, then the machine swings

    SECTION("a plane: the steel beyond y = 6 m")
    {
        PathObstacle plane;
        plane.name = "truck side";
        plane.is_plane = true;
        plane.point_m = {0.0, wall_y, 0.0};
        plane.normal = {0.0, -1.0, 0.0};
        const std::vector<PathCrossing> found = find_crossings(path, {plane}, depth);
        const auto dipper_in = std::find_if(found.begin(), found.end(), [](const PathCrossing& c) { return c.part == "dipper"; });
        REQUIRE(dipper_in != found.end());
        INFO(describe(*dipper_in));
        // the curves' path against the multibody's: within the 0.15 m of the test above, at the swing's 4 m/s
        CHECK(std::abs(dipper_in->from_s - first_in) < 0.1);
        CHECK(dipper_in->depth_m > 1.0);  // the swing goes on to 90 deg, far past the wall
        CHECK(dipper_in->to_s > dipper_in->from_s);
        CHECK(describe(*dipper_in).find("into wall 'truck side'") != std::string::npos);
    }
    SECTION("a mesh: a box of steel standing across the swing, removed or not")
    {
        PathObstacle box;
        box.name = "truck body";
        box.surface = meshes::make_box_mesh({-5.0, wall_y, 0.0}, {40.0, wall_y + 3.0, 30.0});
        std::vector<PathCrossing> found = find_crossings(path, {box}, depth);
        const auto dipper_in = std::find_if(found.begin(), found.end(), [](const PathCrossing& c) { return c.part == "dipper"; });
        REQUIRE(dipper_in != found.end());
        INFO(describe(*dipper_in));
        CHECK(std::abs(dipper_in->from_s - first_in) < 0.1);
        CHECK(dipper_in->depth_m > depth);
        box.removed_at_s = 10.0;  // gone before the swing
        CHECK(find_crossings(path, {box}, depth).empty());
        box.removed_at_s = std::numeric_limits<double>::infinity();
        box.translation_m = {0.0, 20.0, 0.0};  // out of reach
        CHECK(find_crossings(path, {box}, depth).empty());
    }
    SECTION("the ground under the crawlers is touched, not crossed")
    {
        PathObstacle ground;
        ground.name = "ground";
        ground.is_plane = true;
        ground.normal = {0.0, 0.0, 1.0};
        CHECK(find_crossings(path, {ground}, depth).empty());
        ground.point_m = {0.0, 0.0, 0.5};  // raised into the crawlers
        const std::vector<PathCrossing> found = find_crossings(path, {ground}, depth);
        REQUIRE(!found.empty());
        CHECK(found[0].part == "crawlers");
        CHECK(found[0].depth_m == Approx(0.5).margin(1e-6));
        CHECK(found[0].from_s == 0.0);
        CHECK(found[0].to_s == cycle.duration_s());
    }
}

TEST_CASE("the path check refuses a bad sampling distance", "[machine_path]")
{
    const meshes::Dipper dipper = meshes::make_dipper({});
    const ShovelGeometry g;
    CHECK_THROWS_WITH(shovel_path(g, dipper, default_loading_cycle(g, dipper), {}, 0.0, 0.0), Catch::Contains("max_move_m is 0"));
}
