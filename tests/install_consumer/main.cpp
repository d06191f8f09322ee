// Uses the installed library the way an engineering tool would: drops a sphere on the ground (dem), a rock
// on the ground (rigid, Bullet inside), and wears a plate (wear); checks each result.
#include "dem/world.h"
#include "meshes/triangle_mesh.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"
#include "wear/wear_surface.h"

#include <cmath>
#include <cstdio>

int main()
{
    using namespace dipper;
    dem::World world(dem::MaterialTable::aitik_copper_ore(), dem::WorldSettings{});
    world.add_plane({0, 0, 0}, {0, 0, 1}, world.materials().index_of("ground"), "ground");
    world.add_particle({{0, 0, 0.5}, {}, {}, 0.1, world.materials().index_of("ore")});
    while (world.time_s() < 1.0) world.step();
    const double z = world.particles().position_m[0].z;
    std::printf("sphere at rest at z = %.4f m\n", z);

    rigid::RigidWorld rocks;
    rocks.add_material("rock");
    rocks.add_material("ground");
    rocks.set_pair("rock", "ground", 0.9, 0.0);
    rocks.add_ground_plane(0.0, 1, "ground");
    const rigid::BodyId rock = rocks.add_rock(rigid::generate_rock({0.4, 1.0, 1.5, 20}, 7), 2700.0, 0, {0, 0, 1.0});
    for (int k = 0; k < 1500; ++k) rocks.step(1e-3);
    const double rock_z = rocks.state(rock).position_m.z;
    std::printf("rock at rest with its centre at z = %.4f m\n", rock_z);

    wear::WearSurface plate("plate", meshes::make_plate_mesh(1.0, 1.0, 2, 2), wear::WearLaw::from_name("archard", 1e-12, "consumer"), 0);
    ContactRecord c;
    c.normal_force_N = 1000.0;
    c.relative_displacement_m = {0.01, 0.0, 0.0};
    c.normal_world = {0.0, 0.0, 1.0};
    c.surface_id = 0;
    c.triangle_id = 0;
    plate.accumulate({c}, 1e-3);
    std::printf("wear volume %.3g m^3\n", plate.total_volume_m3());
    const bool ok = z > 0.099 && z < 0.1001 && rock_z > 0.05 && rock_z < 0.4 && std::abs(plate.total_volume_m3() - 1e-11) < 1e-20;
    return ok ? 0 : 1;
}
