// A DEM world, a Bullet world and their coupling, built together for the coupling tests.
#pragma once

#include "coupling/coupled_world.h"
#include "dem/world.h"
#include "rigid/rigid_world.h"
#include "meshes/triangle_mesh.h"
#include "rigid/convex_polyhedron.h"
#include "rigid/rock_generator.h"

#include <memory>

namespace dipper::test {

struct CoupledScene {
    dem::World dem;
    rigid::RigidWorld rigid;
    coupling::CoupledWorld world;

    CoupledScene(dem::MaterialTable table, dem::WorldSettings ds, rigid::RigidSettings rs, int substeps, bool runaway_guard = false,
                 coupling::RockExchange exchange = coupling::RockExchange::coupling_step)
        : dem(std::move(table), ds), rigid(rs), world(dem, rigid, coupling::CouplingSettings{substeps, runaway_guard, exchange})
    {
        rigid::add_aitik_copper_ore_materials(rigid);
    }
};

inline std::unique_ptr<CoupledScene> make_scene(int substeps, const Vec3& gravity = {0.0, 0.0, -9.81},
                                                dem::MaterialTable table = dem::MaterialTable::aitik_copper_ore(),
                                                bool runaway_guard = false,
                                                coupling::RockExchange exchange = coupling::RockExchange::coupling_step)
{
    dem::WorldSettings ds;
    ds.gravity_m_per_s2 = gravity;
    rigid::RigidSettings rs;
    rs.gravity_m_per_s2 = gravity;
    return std::make_unique<CoupledScene>(std::move(table), ds, rs, substeps, runaway_guard, exchange);
}

inline constexpr double kSphereRadius = 0.1;  // the thesis' 200 mm spheres

inline rigid::ConvexPolyhedron test_rock(double size_m, std::uint64_t seed)
{
    return rigid::generate_rock({size_m, 1.0, 1.6, 24}, seed).in_principal_frame();
}

inline rigid::ConvexPolyhedron cube(double a)
{
    return rigid::ConvexPolyhedron::from_mesh(meshes::make_box_mesh({-a / 2, -a / 2, -a / 2}, {a / 2, a / 2, a / 2}));
}

inline std::uint32_t add_sphere(dem::World& w, const Vec3& x, const Vec3& v = {}, double r = kSphereRadius)
{
    return w.add_particle({x, v, {}, r, w.materials().index_of("ore")});
}

}  // namespace dipper::test
