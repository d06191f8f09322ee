// A DEM world, a Bullet world and their coupling, built together for the coupling tests.
#pragma once

#include "coupling/coupled_world.h"
#include "dem/world.h"
#include "rigid/rigid_world.h"

#include <memory>

namespace dipper::test {

struct CoupledScene {
    dem::World dem;
    rigid::RigidWorld rigid;
    coupling::CoupledWorld world;

    CoupledScene(dem::MaterialTable table, dem::WorldSettings ds, rigid::RigidSettings rs, int substeps, bool runaway_guard = false)
        : dem(std::move(table), ds), rigid(rs), world(dem, rigid, coupling::CouplingSettings{substeps, runaway_guard})
    {
        rigid::add_aitik_copper_ore_materials(rigid);
    }
};

inline std::unique_ptr<CoupledScene> make_scene(int substeps, const Vec3& gravity = {0.0, 0.0, -9.81},
                                                dem::MaterialTable table = dem::MaterialTable::aitik_copper_ore(),
                                                bool runaway_guard = false)
{
    dem::WorldSettings ds;
    ds.gravity_m_per_s2 = gravity;
    rigid::RigidSettings rs;
    rs.gravity_m_per_s2 = gravity;
    return std::make_unique<CoupledScene>(std::move(table), ds, rs, substeps, runaway_guard);
}

}  // namespace dipper::test
