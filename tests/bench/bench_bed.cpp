// dipper_bench_bed: DEM throughput on a settled bed of equal spheres.
//
// N spheres of r = 0.1 m, Aitik ore (thesis Table 2, rolling resistance on), are placed on a jittered
// lattice in a box with a 10 m x 5 m floor (20 m x 12.5 m from N = 100,000 on; depth about 2.9 m for
// N = 20,000), settled under gravity, then timed over --steps steps at dt = 5e-5 s. The last line is
// `particle-steps/s: <number>`.
//
// usage: dipper_bench_bed [--particles N] [--threads T] [--steps S] [--settle-s SECONDS] [--cache FILE] [--skin F]
// --cache keeps the settled bed (positions and velocities) in FILE: a later run with the same N loads it
// and settles for 0.05 s more, so that contact springs are rebuilt before the timed steps.
#include "dem/insertion.h"
#include "dem/world.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

using namespace dipper;
using namespace dipper::dem;

namespace {

long peak_resident_kib()
{
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0) return std::atol(line.c_str() + 6);
    return -1;
}

[[noreturn]] void usage(const char* message)
{
    std::fprintf(stderr, "dipper_bench_bed: %s\nusage: dipper_bench_bed [--particles N] [--threads T] [--steps S] [--settle-s SECONDS] [--cache FILE] [--skin FRACTION_OF_RADIUS]\n", message);
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv)
{
    long particles = 20000, threads = 1, steps = 2000;
    double settle_s = 1.2;
    std::string cache;
    double skin = WorldSettings{}.skin_fraction_of_radius;
    for (int a = 1; a < argc; ++a) {
        auto value = [&](const char* name) {
            if (a + 1 >= argc) usage((std::string(name) + " needs a value").c_str());
            return argv[++a];
        };
        if (!std::strcmp(argv[a], "--particles")) particles = std::atol(value("--particles"));
        else if (!std::strcmp(argv[a], "--threads")) threads = std::atol(value("--threads"));
        else if (!std::strcmp(argv[a], "--steps")) steps = std::atol(value("--steps"));
        else if (!std::strcmp(argv[a], "--settle-s")) settle_s = std::atof(value("--settle-s"));
        else if (!std::strcmp(argv[a], "--cache")) cache = value("--cache");
        else if (!std::strcmp(argv[a], "--skin")) skin = std::atof(value("--skin"));
        else usage((std::string("unknown option ") + argv[a]).c_str());
    }
    if (particles < 1 || threads < 1 || steps < 1 || !(settle_s >= 0.0) || !(skin > 0.0)) usage("values must be positive");

    const double r = 0.1;
    const double length = particles >= 100000 ? 20.0 : 10.0, width = particles >= 100000 ? 12.5 : 5.0;
    WorldSettings settings;
    settings.step_s = 5e-5;
    settings.threads = static_cast<int>(threads);
    settings.skin_fraction_of_radius = skin;
    World world(MaterialTable::aitik_copper_ore(), settings);
    const auto& m = world.materials();
    world.add_plane({0, 0, 0}, {0, 0, 1}, m.index_of("ground"), "floor");
    world.add_plane({0, 0, 0}, {1, 0, 0}, m.index_of("steel"), "x0");
    world.add_plane({length, 0, 0}, {-1, 0, 0}, m.index_of("steel"), "x1");
    world.add_plane({0, 0, 0}, {0, 1, 0}, m.index_of("steel"), "y0");
    world.add_plane({0, width, 0}, {0, -1, 0}, m.index_of("steel"), "y1");

    using clock = std::chrono::steady_clock;
    const auto settle_start = clock::now();
    std::ifstream cached(cache, std::ios::binary);
    long cached_n = 0;
    if (!cache.empty() && cached && cached.read(reinterpret_cast<char*>(&cached_n), sizeof cached_n) && cached_n == particles) {
        // the settled bed from an earlier run: positions and velocities
        for (long k = 0; k < particles; ++k) {
            Vec3 x, v, w;
            cached.read(reinterpret_cast<char*>(&x), sizeof x).read(reinterpret_cast<char*>(&v), sizeof v).read(reinterpret_cast<char*>(&w), sizeof w);
            world.add_particle({x, v, w, r, m.index_of("ore")}, "bench cache");
        }
        if (!cached) usage("cache file is truncated");
        world.run_steps(static_cast<std::uint64_t>(0.05 / settings.step_s));
    } else {
        // random non-overlapping spheres at a solid fraction of about 0.25, settled under gravity
        const double volume = static_cast<double>(particles) * 4.0 / 3.0 * M_PI * r * r * r;
        const double height = volume / 0.25 / (length * width);
        fill_random(world, BoxRegion({0, 0, 0}, {length, width, height}), {{{r, 1.0}}}, m.index_of("ore"),
                    static_cast<double>(particles) * sphere_mass_kg(r, 3700.0), 1);
        world.run_steps(static_cast<std::uint64_t>(settle_s / settings.step_s));
        if (!cache.empty()) {
            std::ofstream out(cache, std::ios::binary);
            const long n = static_cast<long>(world.particles().size());
            out.write(reinterpret_cast<const char*>(&n), sizeof n);
            for (long k = 0; k < n; ++k) {
                const std::size_t i = static_cast<std::size_t>(k);
                out.write(reinterpret_cast<const char*>(&world.particles().position_m[i]), sizeof(Vec3));
                out.write(reinterpret_cast<const char*>(&world.particles().velocity_m_per_s[i]), sizeof(Vec3));
                out.write(reinterpret_cast<const char*>(&world.particles().angular_velocity_rad_per_s[i]), sizeof(Vec3));
            }
        }
    }
    const double settle_wall_s = std::chrono::duration<double>(clock::now() - settle_start).count();
    if (static_cast<long>(world.particles().size()) != particles) usage("the bed does not hold N particles");

    const std::uint64_t rebuilds_before = world.rebuild_count();
    const PhaseSeconds phases_before = world.phase_seconds();
    const auto start = clock::now();
    world.run_steps(static_cast<std::uint64_t>(steps));
    const double wall_s = std::chrono::duration<double>(clock::now() - start).count();

    double top = 0.0;
    for (const Vec3& x : world.particles().position_m) top = std::max(top, x.z);
    const double rate = static_cast<double>(particles) * static_cast<double>(steps) / wall_s;
    std::printf("particles: %ld  threads: %ld  steps: %ld  dt: %g s\n", particles, threads, steps, settings.step_s);
    std::printf("bed: %.1f m x %.1f m, top sphere at %.2f m; set up and settled in %.1f s wall\n", length, width, top, settle_wall_s);
    std::printf("kinetic energy after settling: %.3g J\n", world.kinetic_energy_J());
    std::printf("contacts per particle: %.2f (sphere pairs x 2 + wall contacts) / N\n",
                (2.0 * static_cast<double>(world.pair_contact_count()) + static_cast<double>(world.wall_contact_count())) /
                    static_cast<double>(particles));
    std::printf("neighbour pairs per particle: %.2f\n", static_cast<double>(world.neighbour_pair_count()) / static_cast<double>(particles));
    std::printf("neighbour rebuilds in timed steps: %llu\n", static_cast<unsigned long long>(world.rebuild_count() - rebuilds_before));
    std::printf("peak memory: %.1f MiB\n", static_cast<double>(peak_resident_kib()) / 1024.0);
    const PhaseSeconds& p = world.phase_seconds();
    std::printf("phases, s: sphere pairs %.3f, walls %.3f, neighbour search %.3f, integration %.3f\n",
                p.pair_forces - phases_before.pair_forces, p.wall_forces - phases_before.wall_forces,
                p.neighbour_search - phases_before.neighbour_search, p.integration - phases_before.integration);
    std::printf("wall time: %.3f s\n", wall_s);
    std::printf("particle-steps/s: %.0f\n", rate);
    return 0;
}
