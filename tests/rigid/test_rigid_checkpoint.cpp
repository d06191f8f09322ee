// A rigid world continued from its checkpoint takes the same steps as the world that went on, bit for bit:
// rocks on rocks, on the ground plane, on a triangle mesh and on plates, rocks frozen in place, and the rope
// shovel with rocks landing in its dipper, on one thread and on two.
#include "core/state_io.h"
#include "meshes/machine_geometry.h"
#include "meshes/triangle_mesh.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <vector>

using namespace dipper;
using namespace dipper::rigid;

namespace {

struct Scene {
    RigidWorld world;
    RigidWorld::ShovelParts parts;
    std::vector<BodyId> rocks;
};

Scene build(int threads)
{
    RigidSettings s;
    s.threads = threads;
    Scene scene{RigidWorld(s), {}, {}};
    RigidWorld& w = scene.world;
    for (const char* m : {"rock", "steel", "ground"}) w.add_material(m);
    w.set_pair("rock", "rock", kTable2RockFriction.rock, 0.0);
    w.set_pair("rock", "steel", kTable2RockFriction.bucket, 0.0);
    w.set_pair("rock", "ground", kTable2RockFriction.ground, 0.0);
    w.set_pair("steel", "ground", 0.5, 0.0);
    w.set_pair("steel", "steel", 0.5, 0.0);
    w.add_ground_plane(0.0, w.material_index("ground"), "ground");
    w.add_static_mesh(meshes::make_box_mesh({20.0, -2.0, 0.0}, {24.0, 2.0, 0.5}), w.material_index("steel"), "step");
    meshes::Plate chute;
    chute.corners_m = {Vec3{26.0, -2.0, 0.2}, Vec3{29.0, -2.0, 1.0}, Vec3{29.0, 2.0, 1.0}, Vec3{26.0, 2.0, 0.2}};
    chute.thickness_m = 0.1;
    w.add_plates({chute}, w.material_index("steel"), "chute", false);
    // rocks over the step, over the chute and over the dipper (which lies at x 13 to 17.5, z 0.1 to 3.8)
    const double x0[3] = {20.6, 26.4, 13.6}, z0[3] = {1.2, 1.8, 4.4};
    for (int region = 0; region < 3; ++region)
        for (int k = 0; k < 16; ++k) {
            const ConvexPolyhedron r = generate_rock({0.35 + 0.1 * (k % 3), 1.0, 1.6, 16}, 900 + static_cast<std::uint64_t>(16 * region + k));
            const Vec3 at{x0[region] + 0.8 * (k % 4), -1.2 + 0.8 * ((k / 4) % 4), z0[region] + 0.3 * (k % 2)};
            scene.rocks.push_back(w.add_rock(r, 2700.0, w.material_index("rock"), at));
        }
    const meshes::Dipper dipper = meshes::make_dipper({});
    ShovelGeometry g;
    scene.parts = w.add_rope_shovel(dipper, g, default_loading_cycle(g, dipper), w.material_index("steel"));
    return scene;
}

/// One step and everything it gives out, as numbers: every body's state, the dipper's contact records, the
/// shovel's forces.
std::vector<double> step(Scene& s)
{
    s.world.step(1e-3);
    std::vector<double> out;
    for (std::size_t b = 0; b < s.world.body_count(); ++b) {
        const BodyState st = s.world.state(static_cast<BodyId>(b));
        for (const Vec3& v : {st.position_m, st.velocity_m_per_s, st.angular_velocity_rad_per_s}) out.insert(out.end(), {v.x, v.y, v.z});
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) out.push_back(st.rotation.m[i][j]);
    }
    for (const ContactRecord& c : s.world.surface_contacts(s.parts.dipper, 1))
        out.insert(out.end(), {c.point_world.x, c.point_world.y, c.point_world.z, c.normal_force_N, c.tangential_force_N.x, c.first_step ? 1.0 : 0.0});
    const ShovelReading& r = s.world.shovel_reading();
    out.insert(out.end(), {r.dig_force_filtered_N, r.rope_tension_N[0], r.rope_tension_N[1]});
    return out;
}

}  // namespace

TEST_CASE("a rigid world continued from its checkpoint takes the same steps bit for bit", "[rigid][checkpoint][unit]")
{
    // Bullet carries its broad phase, pair order, manifolds with their warm-starting impulses and dipper's pair
    // bounds from step to step; a checkpoint without them parts from the run that went on at the first step
    // after it. Exact equality is the test: the same build and thread count make the same operations.
    const int threads = GENERATE(1, 2);
    CAPTURE(threads);
    Scene a = build(threads);
    for (int k = 0; k < 700; ++k) step(a);
    // the rocks come to rest on the step and the chute: the slowest are frozen in place, as the dynamic domain does
    int frozen = 0;
    for (BodyId r : a.rocks) {
        const BodyState st = a.world.state(r);
        if (norm(st.velocity_m_per_s) < 0.05 && st.position_m.x > 19.0 && frozen < 6) {
            a.world.set_frozen(r, true);
            ++frozen;
        }
    }
    REQUIRE(frozen > 0);
    for (int k = 0; k < 100; ++k) step(a);
    const RigidWorld::PairCounts counts = a.world.pair_counts();
    REQUIRE(counts.touching_manifolds > 20);  // the checkpoint holds contacts to carry
    const std::string path = (std::filesystem::temp_directory_path() / ("dipper_test_rigid_checkpoint_" + std::to_string(threads))).string();
    StateWriter out;
    a.world.write_state(out);
    out.save(path, "rigid test");

    Scene b = build(threads);
    StateReader in(path, "rigid test");
    b.world.read_state(in);
    in.finish();
    std::filesystem::remove(path);
    int differing = 0, first = -1;
    for (int k = 0; k < 400; ++k) {
        const bool same = step(a) == step(b);
        if (!same && first < 0) first = k;
        differing += same ? 0 : 1;
    }
    CAPTURE(first);
    CHECK(differing == 0);
    CHECK(a.world.frozen(a.rocks[0]) == b.world.frozen(b.rocks[0]));
}
