// Rock piles in Bullet: cost per rock per step of a settled pile, memory, and the ground reaction against
// the pile's weight. Rocks of the thesis' size classes (Table 1 mass fractions 300/400/600/850 mm =
// 10/9/19/25) are dropped from a loose lattice onto the ground and settled; then steps are timed.
// Usage: dipper_bench_rock_pile [--rocks N] [--dt S] [--settle-s S] [--settle-dt S] [--steps N] [--point-count N]
//                               [--iterations N] [--margin-fraction F] [--pool N] [--pairs dipper|bullet] [--threads N]
// The pile settles at --settle-dt (default 1e-3 s), then takes 100 steps at --dt before the timed ones.
// --dt may list several steps (--dt 1e-3,1e-4): the settled pile is timed at each in turn, so a large
// pile settles once. --pairs bullet steps hull pairs with Bullet's own convex-convex algorithm instead of
// dipper's (RigidSettings::bullet_convex_pairs), for comparison. --threads: the narrow phase's threads
// (RigidSettings::threads; the same pile to the bit on any number).
#include "coupling/mixed_bed.h"
#include "rigid/rigid_world.h"
#include "rigid/rock_generator.h"
#include "tests/bench/options.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

using namespace dipper;
using namespace dipper::rigid;

int main(int argc, char** argv)
{
    int rocks = 1000, steps = 200, point_count = 20, iterations = 10, pool = 4096, threads = 1;
    double settle_s = 2.0, settle_dt = 1e-3, margin_fraction = 0.05;
    std::string pairs = "dipper";
    std::vector<double> dts{1e-3};
    const char* help = "usage: dipper_bench_rock_pile [--rocks N] [--dt S[,S...]] [--settle-s S] [--settle-dt S] [--steps N]\n"
                        "                              [--point-count N] [--iterations N] [--pool N] [--margin-fraction F]\n"
                       "                              [--pairs dipper|bullet] [--threads N]\n";
    const int status = bench::read_options(argc, argv, help, [&](const std::string& key, const char* value) {
        if (key == "--rocks") rocks = std::atoi(value);
        else if (key == "--dt") {
            dts.clear();
            const std::string list = std::string(value) + ",";
            for (std::size_t at = 0, comma; (comma = list.find(',', at)) != std::string::npos; at = comma + 1)
                dts.push_back(std::atof(list.substr(at, comma - at).c_str()));
        }
        else if (key == "--settle-s") settle_s = std::atof(value);
        else if (key == "--settle-dt") settle_dt = std::atof(value);
        else if (key == "--steps") steps = std::atoi(value);
        else if (key == "--point-count") point_count = std::atoi(value);
        else if (key == "--iterations") iterations = std::atoi(value);
        else if (key == "--pool") pool = std::atoi(value);
        else if (key == "--margin-fraction") margin_fraction = std::atof(value);
        else if (key == "--pairs") pairs = value;
        else if (key == "--threads") threads = std::atoi(value);
        else return false;
        return true;
    });
    if (status >= 0) return status;
    if (pairs != "dipper" && pairs != "bullet") {
        std::fprintf(stderr, "--pairs is '%s'; expected dipper or bullet\n", pairs.c_str());
        return 2;
    }
    if (threads < 1) {
        std::fprintf(stderr, "--threads is %d; expected a whole number >= 1\n", threads);
        return 2;
    }
    const bool bullet_pairs = pairs == "bullet";
    RigidSettings settings;
    settings.solver_iterations = iterations;
    settings.contact_pool_size = pool;
    settings.rock_margin_fraction = margin_fraction;
    settings.bullet_convex_pairs = bullet_pairs;
    settings.threads = threads;
    RigidWorld w(settings);
    w.add_material("rock");
    w.add_material("ground");
    w.set_pair("rock", "rock", kTable2RockFriction.rock, 0.0);
    w.set_pair("rock", "ground", kTable2RockFriction.ground, 0.0);
    const BodyId ground = w.add_ground_plane(0.0, 1, "ground");

    // size classes by count from the mass fractions (mass per rock ~ size^3)
    const std::vector<coupling::RockClass> table1 = coupling::MixedDistribution::thesis_table1().rocks;
    double weights[4], total = 0.0;
    for (int c = 0; c < 4; ++c) total += weights[c] = table1[c].mass_fraction / std::pow(table1[c].size_m, 3);
    std::mt19937_64 rng(1);
    std::discrete_distribution<int> pick(weights, weights + 4);
    const int side = static_cast<int>(std::ceil(std::sqrt(rocks / 4.0)));
    const double spacing = 1.0;
    double weight = 0.0;
    for (int k = 0; k < rocks; ++k) {
        const int layer = k / (side * side), i = (k / side) % side, j = k % side;
        const ConvexPolyhedron r = generate_rock({table1[static_cast<std::size_t>(pick(rng))].size_m, 1.0, 2.0, point_count}, 1000 + static_cast<std::uint64_t>(k));
        const BodyId id = w.add_rock(r, 2700.0, 0, {i * spacing, j * spacing, 0.6 + layer * spacing},
                                     rotation_about_axis({0.0, 0.0, 1.0}, 0.37 * k));
        weight += w.mass_kg(id) * 9.81;
    }
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const int settle_steps = static_cast<int>(std::lround(settle_s / settle_dt));
    for (int k = 0; k < settle_steps; ++k) w.step(settle_dt);
    const double settle_wall = std::chrono::duration<double>(clock::now() - t0).count();
    std::printf("rocks %d  settled %.1f s at %g s (%.1f s wall), %d thread(s)\n", rocks, settle_s, settle_dt, settle_wall, threads);

    for (const double dt : dts) {
        if (!(dt > 0.0)) {
            std::fprintf(stderr, "--dt needs steps > 0\n");
            return 2;
        }
        for (int k = 0; k < 100; ++k) w.step(dt);  // let the contact impulses adapt to the new step
        std::vector<double> per_step;
        double reaction = 0.0;
        for (int k = 0; k < steps; ++k) {
            const auto a = clock::now();
            w.step(dt);
            per_step.push_back(std::chrono::duration<double>(clock::now() - a).count());
            reaction += -w.contact_force_N(ground).z;
        }
        std::sort(per_step.begin(), per_step.end());
        const double median = per_step[per_step.size() / 2];
        rusage usage{};
        getrusage(RUSAGE_SELF, &usage);
        std::printf("rocks %d  dt %g s\n", rocks, dt);
        std::printf("  median step %.3f ms = %.1f us per rock per step; contact points %zu\n", median * 1e3,
                    median / rocks * 1e6, w.contact_point_count());
        const RigidWorld::PairCounts pc = w.pair_counts();
        std::printf("  broad-phase pairs %zu, manifolds %zu (%zu with points)\n", pc.broadphase_pairs, pc.manifolds, pc.touching_manifolds);
        std::printf("  ground reaction / weight %.5f (mean of %d steps); kinetic energy %.4g J; deepest overlap %.2f mm\n",
                    reaction / steps / weight, steps, w.kinetic_energy_J(), w.max_penetration_m() * 1e3);
        std::printf("  peak memory %.1f MB (%.1f kB per rock)\n", usage.ru_maxrss / 1024.0, usage.ru_maxrss / static_cast<double>(rocks));
    }
    return 0;
}
