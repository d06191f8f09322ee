#include "scenario/run_limits.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unistd.h>

namespace dipper::scenario {

double planned_step_s(const Scenario& s, const dem::World& world)
{
    if (s.step_s > 0.0) return s.step_s;
    double step = world.particles().size() > 0 ? world.step_s() : std::numeric_limits<double>::infinity();
    const auto sources = [&](const auto& list) {
        for (const ParticleSource& p : list) {
            const dem::MaterialIndex m = world.materials().index_of(p.material);
            for (const auto& c : p.sizes.classes)
                if (c.mass_fraction > 0.0) step = std::min(step, world.default_step_s(c.radius_m, m));
        }
    };
    sources(s.fills);
    sources(s.pours);
    return step;
}

double run_memory_bytes(double spheres)
{
    constexpr double kBytesPerSphere = 1000.0, kBaseBytes = 64e6;
    return kBaseBytes + kBytesPerSphere * spheres;
}

void require_run_fits(const Scenario& s, const dem::World& world)
{
    const double step = planned_step_s(s, world);
    if (std::isfinite(step) && step > 0.0) {
        const struct {
            const char* key;
            double value;
            const std::string& where;
        } intervals[] = {{"output.csv_interval_s", s.output.csv_interval_s, s.output.csv_where},
                         {"output.vtk_interval_s", s.output.vtk_interval_s, s.output.vtk_where},
                         {"output.checkpoint_interval_s", s.output.checkpoint_interval_s, s.output.checkpoint_where}};
        for (const auto& i : intervals)
            if (i.value > 0.0 && i.value < step)
                throw InputError(concat(i.where.empty() ? concat(s.source, ": ", i.key) : i.where, ": got ", i.value,
                                        "; expected at least the time step, ", step, " s"));
    }
    double spheres = 0.0, most = 0.0;
    std::string most_where = s.source;
    const auto count = [&](const auto& list) {
        for (const ParticleSource& p : list) {
            const double n = dem::particles_for_mass(p.sizes, s.materials.material(s.materials.index_of(p.material)).density_kg_per_m3,
                                                     p.mass_kg);
            spheres += n;
            if (n > most) most = n, most_where = p.where;
        }
    };
    count(s.fills);
    count(s.pours);
    spheres = std::max(spheres, static_cast<double>(world.particles().size()));
    const double need = run_memory_bytes(spheres);
    const double have = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
    if (have > 0.0 && need > have)
        throw InputError(concat(most_where, ": the run's ", std::round(spheres), " spheres (", std::round(most),
                                " of them here) need about ", std::round(need / 1e8) / 10.0, " GB of memory (",
                                run_memory_bytes(1.0) - run_memory_bytes(0.0), " bytes each) and this machine has ",
                                std::round(have / 1e8) / 10.0, " GB; make the fills and pours smaller or the spheres larger"));
}

void require_spheres_at_start(const Scenario& s, const dem::World& world)
{
    if (s.step_s > 0.0 || world.particles().size() > 0 || !s.pile.empty()) return;
    std::string where = s.source;
    for (const PourSpec& p : s.pours)
        if (p.start_s == 0.0) {
            where = p.where;
            break;
        }
    throw InputError(concat(where, ": no sphere found room in the pour's box at t = 0, and the default time step comes from "
                                   "the spheres present at t = 0; make the box wider than the largest sphere's diameter by "
                                   "more (each try draws a centre anywhere in the box) or set time.step_s"));
}

std::vector<std::string> require_clear_path(const Scenario& s, const coupling::CoSimulation& sim)
{
    if (!sim.has_shovel()) return {};
    // the walls as the DEM world holds them: the planes, then the meshes, in the scenario's order
    std::vector<rigid::PathObstacle> walls;
    std::vector<bool> material_only;
    for (const PlaneSpec& p : s.planes) {
        rigid::PathObstacle o;
        o.name = p.name;
        o.is_plane = true;
        o.point_m = p.point_m;
        o.normal = p.normal;
        o.removed_at_s = p.removed_at_s;
        walls.push_back(std::move(o));
        material_only.push_back(p.material_only);
    }
    for (std::size_t k = 0; k < s.meshes.size(); ++k) {
        const dem::MeshWall& wall = sim.dem().mesh_wall(static_cast<int>(s.planes.size() + k));
        rigid::PathObstacle o;
        o.name = s.meshes[k].name;
        o.surface = wall.mesh();
        if (wall.motion()) {
            const dem::PrescribedMotion motion = *wall.motion();
            o.pose = [motion](double t, Mat3& r, Vec3& x) { motion.pose(t, r, x); };
        }
        o.removed_at_s = s.meshes[k].removed_at_s;
        walls.push_back(std::move(o));
        material_only.push_back(s.meshes[k].material_only);
    }
    const std::vector<rigid::PartPath> path = sim.shovel_path();
    std::vector<std::string> refused, warnings;
    for (const rigid::PathCrossing& c : rigid::find_crossings(path, walls)) {
        const std::size_t k = static_cast<std::size_t>(
            std::find_if(walls.begin(), walls.end(), [&](const rigid::PathObstacle& o) { return o.name == c.obstacle; }) - walls.begin());
        (material_only[k] ? warnings : refused).push_back(rigid::describe(c));
    }
    if (!refused.empty()) {
        std::string text = concat(s.source, ": the shovel's cycle passes through walls that stand for steel (the machine does not stop "
                                            "at walls, docs/limits.md):");
        constexpr std::size_t kListed = 10;
        for (std::size_t k = 0; k < refused.size() && k < kListed; ++k) text += "\n  " + refused[k];
        if (refused.size() > kListed) text += concat("\n  and ", refused.size() - kListed, " more");
        text += "\nmove the machine, the wall or the motion, or mark a wall that only holds material with material_only: true";
        throw InputError(text);
    }
    for (std::string& w : warnings) w = concat(s.source, ": ", w, " (material_only: the machine passes through)");
    return warnings;
}

std::vector<std::string> repose_wall_warnings(const Scenario& s, const dem::MaterialTable& materials)
{
    std::vector<std::string> warnings;
    if (!s.repose) return warnings;
    const std::size_t across = s.repose->window.along == 'x' ? 1 : 0;  // the horizontal axis across the slope
    std::vector<std::string> held;  // the materials of the fills and pours
    for (const ParticleSource* p : [&] {
             std::vector<const ParticleSource*> v;
             for (const FillSpec& f : s.fills) v.push_back(&f);
             for (const PourSpec& q : s.pours) v.push_back(&q);
             return v;
         }())
        if (std::find(held.begin(), held.end(), p->material) == held.end()) held.push_back(p->material);
    // the slice between two side walls facing each other, against the largest particle it holds: the narrowest
    // slice measured, three diameters, reads the angle of a slice eight times as wide (docs/results.md)
    double largest_m = 0.0;
    for (const FillSpec& f : s.fills) {
        largest_m = std::max(largest_m, 2.0 * f.sizes.max_radius_m());
        for (const coupling::RockClass& r : f.rocks) largest_m = std::max(largest_m, r.size_m);
    }
    for (const PourSpec& q : s.pours) largest_m = std::max(largest_m, 2.0 * q.sizes.max_radius_m());
    const PlaneSpec *low = nullptr, *high = nullptr;  // the side walls bounding the slice from below and above
    for (const PlaneSpec& plane : s.planes) {
        const double n = norm(plane.normal);
        if (!(std::abs(plane.normal[across]) > 0.99 * n)) continue;
        if (plane.normal[across] > 0.0 && (!low || plane.point_m[across] > low->point_m[across])) low = &plane;
        if (plane.normal[across] < 0.0 && (!high || plane.point_m[across] < high->point_m[across])) high = &plane;
    }
    if (low && high && largest_m > 0.0) {
        const double width = high->point_m[across] - low->point_m[across];
        if (width < 3.0 * largest_m)
            warnings.push_back(concat("the repose probe's slice between planes '", low->name, "' and '", high->name, "' is ", width,
                                      " m wide, ", std::round(10.0 * width / largest_m) / 10.0, " times the largest particle (", largest_m,
                                      " m): narrower than the narrowest slice measured (3 diameters, which read the angle of a slice "
                                      "8 times as wide; docs/results.md), so its walls may bias the angle; widen it"));
    }
    for (const PlaneSpec& plane : s.planes) {
        const double n = norm(plane.normal);
        if (!(std::abs(plane.normal[across]) > 0.99 * n)) continue;  // not a side wall of the slope
        for (const std::string& m : held) {
            const dem::PairCoefficients& c = materials.pair(materials.index_of(m), materials.index_of(plane.material));
            if (c.friction > 0.0 || c.rolling_friction > 0.0) {
                warnings.push_back(concat("plane '", plane.name, "' (", plane.material, ") is a side wall of the repose probe's slope and holds '",
                                          m, "' with friction ", c.friction, " and rolling friction ", c.rolling_friction,
                                          ": side walls with friction raise the angle (about 3 deg each in a 0.9 m slice of 150 mm spheres; "
                                          "docs/results.md); frictionless walls (material steel) read the angle of a pile without walls"));
                break;
            }
        }
    }
    return warnings;
}

std::vector<std::string> check_scenario(const Scenario& s)
{
    std::unique_ptr<dem::World> own = build_world(s);  // mesh files are read and checked too
    dem::World* const world = own.get();
    check_pairs(s);
    // Bullet's side: walls rocks meet, the dipper's parameters, the motion file
    std::unique_ptr<coupling::CoSimulation> sim;
    if (s.uses_coupling()) sim = build_co_simulation(s, std::move(own));
    std::vector<std::string> warnings;
    if (sim) warnings = require_clear_path(s, *sim);
    for (std::string& w : repose_wall_warnings(s, world->materials())) warnings.push_back(std::move(w));
    // what the run places at t = 0 before its first step, where the step depends on it: the pours due at 0
    // when no fill or pile brings spheres (the same seeds as the run)
    const bool fills_bring_spheres = std::any_of(s.fills.begin(), s.fills.end(), [](const FillSpec& f) {
        return std::any_of(f.sizes.classes.begin(), f.sizes.classes.end(), [](const auto& c) { return c.mass_fraction > 0.0; });
    });
    if (s.step_s == 0.0 && s.pile.empty() && !fills_bring_spheres) {
        require_run_fits(s, *world);  // before the pours draw their spheres' sizes (9 x 10^7 of them took 6 s and 0.7 GB)
        std::vector<dem::Pourer> pourers = make_pourers(s, *world);
        for (dem::Pourer& p : pourers) p.update(*world);
        require_spheres_at_start(s, *world);
    }
    require_run_fits(s, *world);
    // more than 10^9 steps is a mistake in a stiffness, a radius or the step (the run refuses it too, naming
    // the particle that sets the step)
    constexpr double kMaxSteps = 1e9;
    const double step = planned_step_s(s, *world);
    if (std::isfinite(step) && step > 0.0 && s.duration_s / step > kMaxSteps)
        throw InputError(concat(s.source, ": time.duration_s = ", s.duration_s, " s is ", s.duration_s / step, " steps of ", step,
                                " s (", s.step_s > 0.0 ? "time.step_s" : "the default step of the smallest, stiffest sphere",
                                "); a run takes at most ", kMaxSteps, " steps: check the radii, the Young's moduli and the pairs' C_norm"));
    return warnings;
}

}  // namespace dipper::scenario
