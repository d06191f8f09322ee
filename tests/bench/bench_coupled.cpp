// A mixed bed of spheres and rocks, coupled: time per simulated second split into phases, for several
// coupling sub-step counts n, against the same bed stepped by the DEM alone (rocks held as fixed surfaces).
// Spheres 200 mm; rocks of Table 1's classes in Table 1's mass ratios among themselves; Aitik ore (Table 2).
// Usage: dipper_bench_coupled [--spheres N] [--rocks N] [--dt S] [--threads N] [--steps N] [--settle-s S]
//                             [--substeps 1,5,10,20] [--cache FILE] [--pairs dipper|bullet] [--runaway-guard on|off]
//                             [--turn N] [--full-mix] [--dynamic-domain 0.01,0.05/0.5]
// --substeps: a list of n; "n:dem_step" runs n with the rocks taking the spheres' forces at every DEM step
// (coupling::RockExchange::dem_step), plain n with the default exchange at Bullet's step.
// --full-mix: the full-size loading model's mix on a tenth of its size (14,500 spheres of 200 mm and 2,000 rocks
// of Table 1, settled 1.5 s, cached in bench_full_mix.state), coupled with the default sub-steps against the same
// bed with the rocks held still, 1,000 timed DEM steps in turns of 100; other options given override these. Its
// last line: "spheres: N rocks: M coupled: X s/s rocks held: Y s/s ratio: R" (wall seconds per simulated second,
// R the median over the turns of coupled / rocks held).
// The bed is filled loosely in a box, settled for --settle-s at n = 10 and saved to --cache (a later run loads
// it); each variant then starts from that state, takes 200 DEM steps to warm up, and times --steps DEM steps.
// --turn N: the variants take turns of N DEM steps each (all their beds in memory) until each has done --steps;
// each coupled turn is then also divided by the DEM alone's turn just before it. The two met the same state of a
// machine whose speed drifts by tens of per cent within minutes, so the median of those ratios is the steadier
// figure. Without --turn each variant runs its --steps in one go.
// --pairs bullet: rock-rock pairs in Bullet's own convex-convex algorithm (RigidSettings::bullet_convex_pairs).
// --dynamic-domain: one more variant per rest speed (m/s) given, at the last --substeps value, with the dynamic
// domain (coupling/dynamic_domain.h; "speed/margin" sets the margin in m, else 1 m; the rest time at its default)
// deciding after each coupling step what is frozen; it prints how much froze. Every variant then warms up for the rest time and 0.05 s more (instead of
// 200 DEM steps), so that what is at rest has frozen before the timing starts.
// Each variant ends with the spheres' state hash (the one summary.json gives): a change that should not move
// results must keep it.
#include "coupling/coupled_world.h"
#include "coupling/dynamic_domain.h"
#include "coupling/mixed_bed.h"
#include "core/errors.h"
#include "meshes/mesh_builder.h"
#include "scenario/runner.h"
#include "tests/bench/options.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

using namespace dipper;

namespace {

struct Bed {
    dem::World dem;
    rigid::RigidWorld rigid;
    coupling::CoupledWorld world;
    Bed(double dt, int threads, int substeps, bool bullet_pairs, bool runaway_guard = false,
        coupling::RockExchange exchange = coupling::RockExchange::coupling_step)
        : dem(dem::MaterialTable::aitik_copper_ore(), [&] {
              dem::WorldSettings s;
              s.step_s = dt;
              s.threads = threads;
              s.initial_overlap_tolerance = s.max_overlap_ratio;  // the cached bed was settled: its overlaps are the run's
              return s;
          }()),
          rigid([&] {
              rigid::RigidSettings s;
              s.contact_pool_size = 8192;
              s.bullet_convex_pairs = bullet_pairs;
              s.threads = threads;
              return s;
          }()),
          world(dem, rigid, coupling::CouplingSettings{substeps, runaway_guard, exchange})
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
    int spheres = 20000, rocks = 1000, threads = 1, steps = 400, turn = 0;
    double dt = 5e-5, settle_s = 0.6;
    std::string cache, substeps_list = "1,5,10,20";
    std::string pairs = "dipper", guard = "off", rest_speeds;
    const char* usage =
        "usage: dipper_bench_coupled [--spheres N] [--rocks N] [--dt S] [--threads N] [--steps N] [--settle-s S]\n"
        "                            [--substeps 1,5,10,20,20:dem_step] [--cache FILE] [--pairs dipper|bullet] [--runaway-guard on|off]\n"
        "                            [--turn N] [--full-mix] [--dynamic-domain 0.01,0.05/0.5]\n";
    // --full-mix is a flag: its settings first, the options given after it override them
    bool full_mix = false;
    std::vector<char*> args{argv[0]};
    for (int k = 1; k < argc; ++k) {
        if (std::string(argv[k]) == "--full-mix") full_mix = true;
        else args.push_back(argv[k]);
    }
    if (full_mix) {
        spheres = 14500;
        rocks = 2000;
        substeps_list = std::to_string(coupling::kDefaultSubsteps);
        settle_s = 1.5;
        steps = 1000;
        turn = 100;
        cache = "bench_full_mix.state";
    }
    const int status = bench::read_options(static_cast<int>(args.size()), args.data(), usage, [&](const std::string& key, const char* value) {
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
        else if (key == "--turn") turn = std::atoi(value);
        else if (key == "--dynamic-domain") rest_speeds = value;
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
    std::vector<coupling::RockExchange> exchanges;
    {
        std::stringstream ss(substeps_list);
        std::string item;
        while (std::getline(ss, item, ',')) {
            const std::size_t colon = item.find(':');
            variants.push_back(std::atoi(item.substr(0, colon).c_str()));
            const std::string exchange = colon == std::string::npos ? "coupling_step" : item.substr(colon + 1);
            if (exchange != "coupling_step" && exchange != "dem_step") {
                std::fprintf(stderr, "--substeps: '%s'; expected n or n:dem_step\n", item.c_str());
                return 2;
            }
            exchanges.push_back(exchange == "dem_step" ? coupling::RockExchange::dem_step : coupling::RockExchange::coupling_step);
        }
    }

    std::vector<coupling::DynamicDomainSettings> domains;
    {
        std::stringstream ss(rest_speeds);
        std::string item;
        while (std::getline(ss, item, ',')) {
            coupling::DynamicDomainSettings dd;
            dd.enabled = true;
            char* end = nullptr;
            dd.rest_speed_m_per_s = std::strtod(item.c_str(), &end);
            bool read = end != item.c_str();
            if (read && *end == '/') {
                const char* margin = end + 1;
                dd.margin_m = std::strtod(margin, &end);
                read = end != margin;
            }
            if (!read || *end != '\0' || !(dd.rest_speed_m_per_s > 0.0) || !std::isfinite(dd.rest_speed_m_per_s) ||
                !(dd.margin_m > 0.0) || !std::isfinite(dd.margin_m)) {
                std::fprintf(stderr, "--dynamic-domain: '%s'; expected rest speeds in m/s > 0, each with a margin in m > 0 if "
                                     "wanted, e.g. 0.01,0.05/0.5\n", item.c_str());
                return 2;
            }
            domains.push_back(dd);
        }
    }

    // Table 1 rock classes in their mass ratios; the sphere fraction follows from the two counts
    const double density = 3700.0, sphere_mass = density * 4.0 / 3.0 * M_PI * 1e-3;
    const std::vector<coupling::RockClass> table1 = coupling::MixedDistribution::thesis_table1().rocks;
    double per_rock_weight = 0.0, rock_count_weight = 0.0;
    for (const coupling::RockClass& c : table1) {
        const double one = density * M_PI / 6.0 * std::pow(c.size_m, 3);
        rock_count_weight += c.mass_fraction / one;
        per_rock_weight += c.mass_fraction;
    }
    const double rock_mass = rocks * per_rock_weight / rock_count_weight;  // total rock mass for `rocks` rocks
    const double total = rock_mass + spheres * sphere_mass;
    coupling::MixedDistribution d;
    d.spheres.mass_fraction = spheres * sphere_mass / total;
    for (std::size_t c = 0; c < table1.size(); ++c) d.rocks[c].mass_fraction = rock_mass / total * table1[c].mass_fraction / per_rock_weight;
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

    // every variant's bed, loaded from the cache and warmed up; then they take turns of --turn DEM steps each
    // until each has timed --steps (one turn by default: each variant in one go, as before)
    variants.insert(variants.begin(), 0);  // 0: the DEM alone
    exchanges.insert(exchanges.begin(), coupling::RockExchange::coupling_step);
    std::vector<coupling::DynamicDomainSettings> variant_domain(variants.size());  // not enabled: none
    for (const coupling::DynamicDomainSettings& dd : domains) {
        variants.push_back(variants.back());
        exchanges.push_back(exchanges.back());
        variant_domain.push_back(dd);
    }
    if (!domains.empty() && variants.back() == 0) {
        std::fprintf(stderr, "--dynamic-domain: the last --substeps value is 0; expected a coupled one\n");
        return 2;
    }
    if (steps < 1) {
        std::fprintf(stderr, "--steps %d: expected a number of timed DEM steps >= 1\n", steps);
        return 2;
    }
    if (turn < 0) {
        std::fprintf(stderr, "--turn %d: expected a number of DEM steps >= 1 (or 0: each variant in one go)\n", turn);
        return 2;
    }
    if (turn == 0) turn = steps;
    if (steps % turn != 0) {
        std::fprintf(stderr, "--turn %d: expected a divisor of --steps %d\n", turn, steps);
        return 2;
    }
    for (int n : variants) {
        if (n < 0) {
            std::fprintf(stderr, "--substeps: %d is negative; expected DEM steps per rigid-body step >= 1 (0: the DEM alone)\n", n);
            return 2;
        }
        if (n > 0 && turn % n != 0) {
            std::fprintf(stderr, "--turn %d: expected a multiple of each --substeps value; %d is not a divisor of it\n", turn, n);
            return 2;
        }
    }
    struct Run {
        int n;
        std::string name;
        std::unique_ptr<Bed> bed;
        dem::PhaseSeconds p0;
        double r0 = 0.0, s0 = 0.0, sim0 = 0.0, wall = 0.0;
        std::vector<double> turn_s;  ///< wall time of each turn
        std::string failed;          ///< the error that stopped it
        std::unique_ptr<coupling::DynamicDomain> domain;  ///< with --dynamic-domain
    };
    std::vector<Run> runs;
    for (std::size_t v = 0; v < variants.size(); ++v) {
        const int n = variants[v];
        const bool at_dem_rate = exchanges[v] == coupling::RockExchange::dem_step;
        Run r;
        r.n = n;
        r.name = n == 0 ? "DEM only" : "n = " + std::to_string(n) + (at_dem_rate ? ", rocks at the DEM's rate" : "");
        if (variant_domain[v].enabled) {
            r.domain = std::make_unique<coupling::DynamicDomain>(variant_domain[v]);
            r.name += concat(", dynamic domain at ", variant_domain[v].rest_speed_m_per_s, " m/s, margin ", variant_domain[v].margin_m, " m");
        }
        r.bed = std::make_unique<Bed>(dt, threads, std::max(n, 1), bullet_pairs, guard == "on", exchanges[v]);
        r.bed->add_box(side, height + 1.0);
        coupling::load_state(r.bed->world, cache);
        runs.push_back(std::move(r));
    }
    auto advance = [](Run& r, int dem_steps) {
        if (!r.failed.empty()) return;
        try {
            if (r.n == 0)
                r.bed->dem.run_steps(static_cast<std::uint64_t>(dem_steps));
            else
                for (int k = 0; k < dem_steps / r.n; ++k) {
                    r.bed->world.step();
                    if (r.domain) r.domain->update(r.bed->world, r.bed->world.coupling_step_s());
                }
        } catch (const SimulationError& e) {
            r.failed = concat("stopped at step ", r.bed->dem.step_count(), ": ", e.what());
        }
    };
    // warm-up: 200 DEM steps, or with a dynamic domain its rest time and 0.05 s more, in whole coupling steps
    int warm_steps = 200;
    if (!domains.empty()) {
        int lcm = 1;
        for (int n : variants)
            if (n > 0) lcm = std::lcm(lcm, n);
        warm_steps = static_cast<int>(std::ceil((coupling::DynamicDomainSettings{}.rest_time_s + 0.05) / dt / lcm)) * lcm;
    }
    for (Run& r : runs) {
        advance(r, warm_steps);
        r.p0 = r.bed->dem.phase_seconds();
        r.r0 = r.bed->world.rigid_seconds();
        r.s0 = r.bed->world.surface_seconds();
        r.sim0 = r.bed->dem.time_s();
    }
    for (int done = 0; done < steps; done += turn)
        for (Run& r : runs) {
            const auto t0 = std::chrono::steady_clock::now();
            advance(r, turn);
            const double s = seconds(t0, std::chrono::steady_clock::now());
            r.wall += s;
            r.turn_s.push_back(s);
        }

    std::printf("\nbed from %s, dt = %g s, %d thread(s), %d timed DEM steps in turns of %d; seconds of wall time per simulated second:\n",
                cache.c_str(), dt, threads, steps, turn);
    std::printf("| variant | total | sphere-sphere | sphere-body and walls | of it sphere-rock | neighbour search | integration | "
                "Bullet | surface motion | x DEM-only | x DEM-only, median turn (range) | sphere-sphere contacts | sphere-body contacts | state hash |\n");
    std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    const Run& alone = runs.front();
    for (const Run& r : runs) {
        if (!r.failed.empty()) {
            std::printf("| %s | %s |\n", r.name.c_str(), r.failed.c_str());
            continue;
        }
        const Bed& bed = *r.bed;
        const double per = 1.0 / (bed.dem.time_s() - r.sim0);
        const dem::PhaseSeconds& p = bed.dem.phase_seconds();
        // each turn against the DEM alone's turn just before it: the two met the same state of the machine
        std::vector<double> ratios;
        if (alone.failed.empty())
            for (std::size_t k = 0; k < r.turn_s.size(); ++k) ratios.push_back(r.turn_s[k] / alone.turn_s[k]);
        std::sort(ratios.begin(), ratios.end());
        char turns[64] = "-";
        if (!ratios.empty())
            std::snprintf(turns, sizeof turns, "%.2f (%.2f-%.2f)", 0.5 * (ratios[(ratios.size() - 1) / 2] + ratios[ratios.size() / 2]),
                          ratios.front(), ratios.back());
        std::size_t body_contacts = 0;
        for (const ContactRecord& c : bed.dem.last_contact_records())
            if (bed.dem.is_mesh(c.surface_id)) ++body_contacts;
        std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.2f | %s | %zu | %zu | %016llx |\n", r.name.c_str(),
                    r.wall * per, (p.pair_forces - r.p0.pair_forces) * per, (p.wall_forces - r.p0.wall_forces) * per,
                    (p.convex_forces - r.p0.convex_forces) * per, (p.neighbour_search - r.p0.neighbour_search) * per,
                    (p.integration - r.p0.integration) * per, (bed.world.rigid_seconds() - r.r0) * per,
                    (bed.world.surface_seconds() - r.s0) * per, alone.failed.empty() ? r.wall / alone.wall : 0.0, turns,
                    bed.dem.pair_contact_count(), body_contacts, static_cast<unsigned long long>(scenario::particle_state_hash(bed.dem)));
        if (r.domain)
            std::printf("  %s: %zu of %zu spheres and %zu of %zu rocks frozen at the end; %zu bodies at rest, %zu moving\n", r.name.c_str(),
                        r.domain->frozen_spheres(), bed.dem.particles().size(), r.domain->frozen_rocks(), bed.world.rocks().size(),
                        r.domain->resting_bodies(), r.domain->moving_bodies());
        if (guard == "on" && r.n > 1)
            std::printf("  %s: runaway guard set off %llu times, %llu coupling steps guarded\n", r.name.c_str(),
                        static_cast<unsigned long long>(bed.world.runaways_caught()),
                        static_cast<unsigned long long>(bed.world.guarded_steps()));
    }
    std::fflush(stdout);
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    std::printf("peak memory %.0f MiB\n", u.ru_maxrss / 1024.0);
    // the full mix's summary, one line per coupled variant (the default's alone: the last line)
    // (the dynamic-domain variants first, so that the last line stays the default's)
    std::vector<std::size_t> order;
    for (std::size_t v = 1; v < runs.size(); ++v)
        if (runs[v].domain) order.push_back(v);
    for (std::size_t v = 1; v < runs.size(); ++v)
        if (!runs[v].domain) order.push_back(v);
    for (std::size_t v : order) {
        if (!full_mix) break;
        const Run& held = runs[0];
        const Run& coupled = runs[v];
        if (!held.failed.empty() || !coupled.failed.empty()) continue;
        std::vector<double> ratios;
        for (std::size_t k = 0; k < coupled.turn_s.size(); ++k) ratios.push_back(coupled.turn_s[k] / held.turn_s[k]);
        std::sort(ratios.begin(), ratios.end());
        const double median = 0.5 * (ratios[(ratios.size() - 1) / 2] + ratios[ratios.size() / 2]);
        if (runs.size() > 2) std::printf("%s: ", coupled.name.c_str());
        std::printf("spheres: %zu rocks: %zu coupled: %.1f s/s rocks held: %.1f s/s ratio: %.2f\n", coupled.bed->dem.particles().size(),
                    coupled.bed->world.rocks().size(), coupled.wall / (coupled.bed->dem.time_s() - coupled.sim0),
                    held.wall / (held.bed->dem.time_s() - held.sim0), median);
    }
    return 0;
}
