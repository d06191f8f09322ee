// A mixed bed of spheres and rocks, coupled: time per simulated second split into phases, for several
// coupling sub-step counts n, against the same bed stepped by the DEM alone (rocks held as fixed surfaces).
// Spheres 200 mm; rocks of Table 1's classes in Table 1's mass ratios among themselves; Aitik ore (Table 2).
// Usage: dipper_bench_coupled [--spheres N] [--rocks N] [--dt S] [--threads N] [--steps N] [--settle-s S]
//                             [--substeps 1,5,10,20] [--cache FILE] [--pairs dipper|bullet] [--runaway-guard on|off]
// The bed is filled loosely in a box, settled for --settle-s at n = 10 and saved to --cache (a later run loads
// it); each variant then starts from that state, takes 200 DEM steps to warm up, and times --steps DEM steps.
// --pairs bullet: rock-rock pairs in Bullet's own convex-convex algorithm (RigidSettings::bullet_convex_pairs).
// Each variant ends with the spheres' state hash (the one summary.json gives): a change that should not move
// results must keep it.
#include "coupling/coupled_world.h"
#include "coupling/mixed_bed.h"
#include "core/errors.h"
#include "meshes/mesh_builder.h"
#include "scenario/runner.h"
#include "tests/bench/options.h"

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace dipper;

namespace {

struct Bed {
    dem::World dem;
    rigid::RigidWorld rigid;
    coupling::CoupledWorld world;
    Bed(double dt, int threads, int substeps, bool bullet_pairs, bool runaway_guard = false)
        : dem(dem::MaterialTable::aitik_copper_ore(), [&] {
              dem::WorldSettings s;
              s.step_s = dt;
              s.threads = threads;
              return s;
          }()),
          rigid([&] {
              rigid::RigidSettings s;
              s.contact_pool_size = 8192;
              s.bullet_convex_pairs = bullet_pairs;
              s.threads = threads;
              return s;
          }()),
          world(dem, rigid, coupling::CouplingSettings{substeps, runaway_guard})
    {
        rigid::add_aitik_copper_ore_materials(rigid);
    }
    /// Floor and sides in both worlds: DEM planes (ground floor, frictionless steel sides) and, for the rocks,
    /// Bullet's ground plane and a fixed open box.
    void add_box(double side_m, double height_m)
    {
        const auto& m = dem.materials();
        dem.add_plane({0, 0, 0}, {0, 0, 1}, m.index_of("ground"), "floor");
        dem.add_plane({0, 0, 0}, {1, 0, 0}, m.index_of("steel"), "x0");
        dem.add_plane({side_m, 0, 0}, {-1, 0, 0}, m.index_of("steel"), "x1");
        dem.add_plane({0, 0, 0}, {0, 1, 0}, m.index_of("steel"), "y0");
        dem.add_plane({0, side_m, 0}, {0, -1, 0}, m.index_of("steel"), "y1");
        rigid.add_ground_plane(0.0, rigid.material_index("ground"), "ground");
        rigid.add_static_mesh(meshes::make_open_box_mesh(side_m, side_m, height_m, side_m), rigid.material_index("ground"), "box");
    }
};

double seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b)
{
    return std::chrono::duration<double>(b - a).count();
}

}  // namespace

int main(int argc, char** argv)
{
    int spheres = 20000, rocks = 1000, threads = 1, steps = 400;
    double dt = 5e-5, settle_s = 0.6;
    std::string cache, substeps_list = "1,5,10,20";
    std::string pairs = "dipper", guard = "off";
    const char* usage =
        "usage: dipper_bench_coupled [--spheres N] [--rocks N] [--dt S] [--threads N] [--steps N] [--settle-s S]\n"
        "                            [--substeps 1,5,10,20] [--cache FILE] [--pairs dipper|bullet] [--runaway-guard on|off]\n";
    const int status = bench::read_options(argc, argv, usage, [&](const std::string& key, const char* value) {
        if (key == "--spheres") spheres = std::atoi(value);
        else if (key == "--rocks") rocks = std::atoi(value);
        else if (key == "--dt") dt = std::atof(value);
        else if (key == "--threads") threads = std::atoi(value);
        else if (key == "--steps") steps = std::atoi(value);
        else if (key == "--settle-s") settle_s = std::atof(value);
        else if (key == "--substeps") substeps_list = value;
        else if (key == "--cache") cache = value;
        else if (key == "--pairs") pairs = value;
        else if (key == "--runaway-guard") guard = value;
        else return false;
        return true;
    });
    if (status >= 0) return status;
    if (pairs != "dipper" && pairs != "bullet") {
        std::fprintf(stderr, "--pairs is '%s'; expected dipper or bullet\n", pairs.c_str());
        return 2;
    }
    if (guard != "on" && guard != "off") {
        std::fprintf(stderr, "--runaway-guard is '%s'; expected on or off\n", guard.c_str());
        return 2;
    }
    const bool bullet_pairs = pairs == "bullet";
    std::vector<int> variants;
    {
        std::stringstream ss(substeps_list);
        std::string item;
        while (std::getline(ss, item, ',')) variants.push_back(std::atoi(item.c_str()));
    }

    // Table 1 rock classes in their mass ratios; the sphere fraction follows from the two counts
    const double density = 3700.0, sphere_mass = density * 4.0 / 3.0 * M_PI * 1e-3;
    const double sizes[4] = {0.3, 0.4, 0.6, 0.85}, table1[4] = {10, 9, 19, 25};
    double per_rock_weight = 0.0, rock_count_weight = 0.0;
    for (int c = 0; c < 4; ++c) {
        const double one = density * M_PI / 6.0 * std::pow(sizes[c], 3);
        rock_count_weight += table1[c] / one;
        per_rock_weight += table1[c];
    }
    const double rock_mass = rocks * per_rock_weight / rock_count_weight;  // total rock mass for `rocks` rocks
    const double total = rock_mass + spheres * sphere_mass;
    coupling::MixedDistribution d;
    d.sphere_mass_fraction = spheres * sphere_mass / total;
    for (int c = 0; c < 4; ++c) d.rocks[static_cast<std::size_t>(c)].mass_fraction = rock_mass / total * table1[c] / per_rock_weight;
    const double solid_m3 = total / density;
    const double side = std::ceil(std::cbrt(solid_m3 / 0.3 / 0.9));  // loose fill at a solid fraction of 0.3, 0.9 as deep as wide
    const double height = solid_m3 / 0.3 / (side * side);

    if (cache.empty() || !std::filesystem::exists(cache)) {
        const auto t0 = std::chrono::steady_clock::now();
        Bed bed(dt, threads, 10, bullet_pairs);
        bed.add_box(side, height + 1.0);
        const auto materials = coupling::MixedMaterials{bed.dem.materials().index_of("ore"), bed.dem.materials().index_of("rock"),
                                                        bed.rigid.material_index("rock"), density};
        const auto report = coupling::fill_mixed(bed.world, {0, 0, 0}, {side, side, height}, d, materials, total, 1);
        std::size_t placed_rocks = 0;
        for (auto n : report.rocks_per_class) placed_rocks += n;
        std::printf("filled a %.0f x %.0f x %.1f m box: %zu spheres, %zu rocks (%zu/%zu/%zu/%zu), %.0f t\n", side, side, height,
                    report.spheres, placed_rocks, report.rocks_per_class[0], report.rocks_per_class[1],
                    report.rocks_per_class[2], report.rocks_per_class[3], (report.sphere_mass_kg + report.rock_mass_kg) / 1000.0);
        while (bed.world.time_s() < settle_s) bed.world.step();
        std::printf("settled %.2f s in %.0f s of wall time\n", settle_s, seconds(t0, std::chrono::steady_clock::now()));
        if (cache.empty()) cache = "bench_coupled_bed.state";
        coupling::save_state(bed.world, cache);
    }

    std::printf("\nbed from %s, dt = %g s, %d thread(s), %d timed DEM steps; seconds of wall time per simulated second:\n",
                cache.c_str(), dt, threads, steps);
    std::printf("| variant | total | sphere-sphere | sphere-body and walls | of it sphere-rock | neighbour search | integration | "
                "Bullet | surface motion | x DEM-only | sphere-sphere contacts | sphere-body contacts | state hash |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    double dem_only_total = 0.0;
    variants.insert(variants.begin(), 0);  // 0: the DEM alone
    for (int n : variants) {
        Bed bed(dt, threads, std::max(n, 1), bullet_pairs, guard == "on");
        bed.add_box(side, height + 1.0);
        coupling::load_state(bed.world, cache);
        const int warm = 200;
        auto run = [&](int dem_steps) {
            if (n == 0)
                bed.dem.run_steps(static_cast<std::uint64_t>(dem_steps));
            else
                for (int k = 0; k < dem_steps / n; ++k) bed.world.step();
        };
        const std::string name = n == 0 ? "DEM only" : "n = " + std::to_string(n);
        auto guard_line = [&] {
            if (guard == "on" && n > 1)
                std::printf("  %s: runaway guard set off %llu times, %llu coupling steps guarded\n", name.c_str(),
                            static_cast<unsigned long long>(bed.world.runaways_caught()),
                            static_cast<unsigned long long>(bed.world.guarded_steps()));
        };
        dem::PhaseSeconds p0;
        double r0 = 0.0, s0 = 0.0, sim0 = 0.0, wall = 0.0;
        try {
            run(warm);
            p0 = bed.dem.phase_seconds();
            r0 = bed.world.rigid_seconds();
            s0 = bed.world.surface_seconds();
            sim0 = bed.dem.time_s();
            const auto t0 = std::chrono::steady_clock::now();
            run(steps);
            wall = seconds(t0, std::chrono::steady_clock::now());
        } catch (const SimulationError& e) {
            std::printf("| %s | stopped at step %llu: %s |\n", name.c_str(), static_cast<unsigned long long>(bed.dem.step_count()), e.what());
            guard_line();
            std::fflush(stdout);
            continue;
        }
        const double sim = bed.dem.time_s() - sim0;
        const dem::PhaseSeconds& p = bed.dem.phase_seconds();
        const double per = 1.0 / sim;
        if (n == 0) dem_only_total = wall * per;
        std::size_t body_contacts = 0;
        for (const ContactRecord& r : bed.dem.last_contact_records())
            if (bed.dem.is_mesh(r.surface_id)) ++body_contacts;
        std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | %zu | %zu | %016llx |\n", name.c_str(), wall * per,
                    (p.pair_forces - p0.pair_forces) * per, (p.wall_forces - p0.wall_forces) * per,
                    (p.convex_forces - p0.convex_forces) * per, (p.neighbour_search - p0.neighbour_search) * per,
                    (p.integration - p0.integration) * per, (bed.world.rigid_seconds() - r0) * per,
                    (bed.world.surface_seconds() - s0) * per, wall * per / dem_only_total, bed.dem.pair_contact_count(),
                    body_contacts, static_cast<unsigned long long>(scenario::particle_state_hash(bed.dem)));
        guard_line();
        std::fflush(stdout);
    }
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    std::printf("peak memory %.0f MiB\n", u.ru_maxrss / 1024.0);
    return 0;
}
