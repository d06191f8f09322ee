// dipper_demo_settle: pours Aitik copper ore (thesis Table 2; 200 mm spheres of Table 1) into a box,
// lets it settle, and reports the settled bulk density and the forces on the walls. Writes ParaView
// files (particles.pvd) and a CSV time series.
//
// usage: dipper_demo_settle [--out DIR] [--particles N] [--threads T]
#include "core/errors.h"
#include "dem/insertion.h"
#include "dem/output.h"
#include "dem/world.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace dipper;
using namespace dipper::dem;

namespace {

/// Volume of the part of a sphere (centre height z, radius r) that lies between heights lo and hi.
double sphere_volume_between(double z, double r, double lo, double hi)
{
    // integral of pi (r^2 - (s - z)^2) ds over [max(lo, z - r), min(hi, z + r)]
    const double a = std::max(lo, z - r) - z, b = std::min(hi, z + r) - z;
    if (b <= a) return 0.0;
    return M_PI * (r * r * (b - a) - (b * b * b - a * a * a) / 3.0);
}

[[noreturn]] void usage(const std::string& message)
{
    std::fprintf(stderr, "dipper_demo_settle: %s\nusage: dipper_demo_settle [--out DIR] [--particles N] [--threads T]\n",
                 message.c_str());
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv)
{
    std::string out = "out/demo_settle";
    long particles = 3000;
    int threads = 0;
    for (int a = 1; a < argc; ++a) {
        const std::string arg = argv[a];
        if (a + 1 >= argc) usage(arg + " needs a value");
        if (arg == "--out") out = argv[++a];
        else if (arg == "--particles") particles = std::atol(argv[++a]);
        else if (arg == "--threads") threads = std::atoi(argv[++a]);
        else usage("unknown option " + arg);
    }
    if (particles < 10 || threads < 0) usage("--particles must be >= 10 and --threads >= 0");

    try {
        // the box: 2.5 m x 2.5 m ground floor (Table 2: ground-DE mu 0.9, mu_roll 0.3) and bucket-steel walls
        // (bucket-DE mu 0.53, mu_roll 0.05)
        const double side = 2.5, r = 0.1;
        WorldSettings settings;
        settings.threads = threads;
        World world(MaterialTable::aitik_copper_ore(), settings);
        const MaterialTable& m = world.materials();
        const MaterialIndex ore = m.index_of("ore"), ground = m.index_of("ground"), wall = m.index_of("bucket");
        const int floor = world.add_plane({0, 0, 0}, {0, 0, 1}, ground, "floor");
        const int x0 = world.add_plane({0, 0, 0}, {1, 0, 0}, wall, "wall_x0");
        world.add_plane({side, 0, 0}, {-1, 0, 0}, wall, "wall_x1");
        const int y0 = world.add_plane({0, 0, 0}, {0, 1, 0}, wall, "wall_y0");
        world.add_plane({0, side, 0}, {0, -1, 0}, wall, "wall_y1");

        // pour from a region above the box for 1.2 s, then let the bed come to rest
        const double mass = static_cast<double>(particles) * sphere_mass_kg(r, m.material(ore).density_kg_per_m3);
        const double pour_s = 1.2, end_s = 3.0;
        Pourer pour(BoxRegion({0, 0, 2.0}, {side, side, 4.0}), {{{r, 1.0}}}, ore, mass / pour_s, mass, {0, 0, -2.0}, 2024);

        ParaViewSeries series(out);
        WorldCsv csv(out + "/world.csv", world);
        std::printf("dipper_demo_settle: %ld spheres of r = %.2f m (%.1f t of Aitik ore) into a %.1f m x %.1f m box\n",
                    particles, r, mass / 1000.0, side, side);
        const auto start = std::chrono::steady_clock::now();
        double next_frame = 0.0;
        pour.update(world);
        while (world.time_s() < end_s) {
            world.step();
            if (world.step_count() % 20 == 0) pour.update(world);
            if (world.time_s() >= next_frame) {
                series.write(world);
                csv.write_row(world);
                std::printf("  t = %4.2f s  particles %5zu  kinetic energy %10.3f J  contacts %6zu\n", world.time_s(),
                            world.particles().size(), world.kinetic_energy_J(),
                            world.pair_contact_count() + world.wall_contact_count());
                std::fflush(stdout);
                next_frame += 0.1;
            }
        }
        const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

        // bulk density: solid fraction of horizontal slices through the lower bed, times particle density
        const ParticleStore& p = world.particles();
        double top = 0.0, weight = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            top = std::max(top, p.position_m[i].z + p.radius_m[i]);
            weight += p.mass_kg[i] * 9.81;
        }
        std::vector<double> fraction;
        const double slice = 0.05;
        for (double z = 0.0; z + slice <= top; z += slice) {
            double solid = 0.0;
            for (std::size_t i = 0; i < p.size(); ++i)
                solid += sphere_volume_between(p.position_m[i].z, p.radius_m[i], z, z + slice);
            fraction.push_back(solid / (side * side * slice));
        }
        // the bed's own height: solid volume over floor area and the mean solid fraction of its middle part
        double solid_volume = 0.0;
        for (double f : fraction) solid_volume += f * side * side * slice;
        double bulk_fraction = 0.0;
        int counted = 0;
        const double rough_height = solid_volume / (side * side * 0.55);
        for (std::size_t k = 0; k < fraction.size(); ++k) {
            const double z = (static_cast<double>(k) + 0.5) * slice;
            if (z > 2.0 * r && z < rough_height - 2.0 * r) {
                bulk_fraction += fraction[k];
                ++counted;
            }
        }
        if (counted == 0) throw SimulationError("the bed is too shallow to measure a bulk density; pour more particles");
        bulk_fraction /= counted;
        const double density = m.material(ore).density_kg_per_m3;
        const double bed_height = solid_volume / (side * side * bulk_fraction);

        const Vec3 floor_force = world.wall_force_N(floor);
        double support = 0.0;  // vertical force of all walls on the particles
        for (int w = 0; w < static_cast<int>(world.wall_count()); ++w) support -= world.wall_force_N(w).z;
        std::printf("\nsettled after %.1f s of simulated time (%.1f s wall, %d threads, dt = %.3g s)\n", world.time_s(), wall_s,
                    world.threads(), world.step_s());
        std::printf("particles:           %zu (%.1f t)\n", p.size(), world.total_mass_kg() / 1000.0);
        std::printf("bed height:          %.3f m\n", bed_height);
        std::printf("solid fraction:      %.3f (slices %.2f m to %.2f m above the floor)\n", bulk_fraction, 2.0 * r,
                    rough_height - 2.0 * r);
        std::printf("bulk density:        %.0f kg/m3 (particle density %.0f kg/m3; thesis target after scaling: 1903)\n",
                    bulk_fraction * density, density);
        std::printf("total weight:        %.1f kN; floor and walls together hold %.4f of it\n", weight / 1000.0,
                    support / weight);
        std::printf("floor force:         %.1f kN vertical (%.4f of the weight; the rest is wall friction)\n",
                    -floor_force.z / 1000.0, -floor_force.z / weight);
        std::printf("side wall forces:    %.1f kN (x = 0) and %.1f kN (y = 0) horizontal, mean pressure %.1f kPa\n",
                    -world.wall_force_N(x0).x / 1000.0, -world.wall_force_N(y0).y / 1000.0,
                    -world.wall_force_N(x0).x / (side * bed_height) / 1000.0);
        std::printf("kinetic energy:      %.3g J\n", world.kinetic_energy_J());
        std::printf("ParaView files:      %s/particles.pvd; time series: %s/world.csv\n", out.c_str(), out.c_str());
        return 0;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "dipper_demo_settle: %s\n", error.what());
        return 1;
    }
}
