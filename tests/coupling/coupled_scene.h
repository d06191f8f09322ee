// A DEM world, a Bullet world and their coupling, built together for the coupling tests.
#pragma once

#include "coupling/coupled_world.h"
#include "dem/world.h"
#include "rigid/rigid_world.h"

#include <memory>

namespace dipper::test {

/// Rigid materials of thesis Table 2 as Bullet sees them: rock-rock and rock-ground mu 0.85 and 0.9,
/// rock-bucket 0.53; restitution 0.2 (Bullet's impulse solver needs one; rocks barely bounce).
inline void add_rigid_table2(rigid::RigidWorld& w)
{
    w.add_material("rock");
    w.add_material("ground");
    w.add_material("bucket");
    w.set_pair("rock", "rock", 0.85, 0.2);
    w.set_pair("rock", "ground", 0.9, 0.2);
    w.set_pair("rock", "bucket", 0.53, 0.2);
}

struct CoupledScene {
    dem::World dem;
    rigid::RigidWorld rigid;
    coupling::CoupledWorld world;

    CoupledScene(dem::MaterialTable table, dem::WorldSettings ds, rigid::RigidSettings rs, int substeps)
        : dem(std::move(table), ds), rigid(rs), world(dem, rigid, coupling::CouplingSettings{substeps})
    {
        add_rigid_table2(rigid);
    }
};

inline std::unique_ptr<CoupledScene> make_scene(int substeps, const Vec3& gravity = {0.0, 0.0, -9.81},
                                                dem::MaterialTable table = dem::MaterialTable::aitik_copper_ore())
{
    dem::WorldSettings ds;
    ds.gravity_m_per_s2 = gravity;
    rigid::RigidSettings rs;
    rs.gravity_m_per_s2 = gravity;
    return std::make_unique<CoupledScene>(std::move(table), ds, rs, substeps);
}

}  // namespace dipper::test
