// Drops one sphere on the ground with the installed library and prints where it came to rest.
#include "dem/world.h"

#include <cstdio>

int main()
{
    using namespace dipper::dem;
    World world(MaterialTable::aitik_copper_ore(), WorldSettings{});
    world.add_plane({0, 0, 0}, {0, 0, 1}, world.materials().index_of("ground"), "ground");
    world.add_particle({{0, 0, 0.5}, {}, {}, 0.1, world.materials().index_of("ore")});
    while (world.time_s() < 1.0) world.step();
    const double z = world.particles().position_m[0].z;
    std::printf("sphere at rest at z = %.4f m\n", z);
    return (z > 0.099 && z < 0.1001) ? 0 : 1;
}
