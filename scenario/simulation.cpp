#include "scenario/simulation.h"

#include "scenario/run_limits.h"

#include <array>
#include <cmath>
#include <optional>

namespace dipper::scenario {

Simulation::Simulation(Scenario scenario, int threads) : scenario_(std::move(scenario))
{
    if (threads > 0) scenario_.threads = threads;
    build();
    if (sim_) warnings_ = require_clear_path(scenario_, *sim_);  // before any particle: a cycle into steel is refused
    if (!scenario_.pile.empty()) place_pile();  // errors name file and line
    require_run_fits(scenario_, *world_);  // before the fills claim the memory
    build_particles(scenario_, *world_);
    if (sim_) {
        fill_rocks(scenario_, *sim_);
        add_wear(scenario_, *sim_);
    }
    pourers_ = make_pourers(scenario_, *world_);
    for (dem::Pourer& p : pourers_) p.update(*world_);
    require_spheres_at_start(scenario_, *world_);
    world_->prepare();
}

Simulation::Simulation(Scenario scenario, int threads, StateReader& in) : scenario_(std::move(scenario))
{
    if (threads > 0) scenario_.threads = threads;
    build();
    if (sim_) {
        // the bodies in the order of the run: walls and shovel, the rocks, then the wear surfaces
        sim_->coupled().read_rocks(in);
        add_wear(scenario_, *sim_);
    }
    pourers_ = make_pourers(scenario_, *world_);
    world_->read_state(in);
    if (sim_) sim_->read_state(in);
    in.tag("pours");
    for (dem::Pourer& p : pourers_) p.read_state(in);
    require_run_fits(scenario_, *world_);  // the scenario inside a checkpoint is checked as a file is
}

Simulation::~Simulation() = default;

void Simulation::place_pile()
{
    const coupling::CoSimulation& sim = *sim_;
    const std::optional<Scenario::PileRegion>& region = scenario_.pile_region;
    // which faces of the region cut the pile: some body lay beyond them and was left out
    std::array<bool, 6> cuts{};  // -x, +x, -y, +y, -z, +z
    auto inside = [&](const Vec3& c) {
        bool in = true;
        for (int a = 0; a < 3; ++a) {
            const bool below = c[a] < region->min_m[a], above = c[a] > region->max_m[a];
            if (below) cuts[static_cast<std::size_t>(2 * a)] = true;
            if (above) cuts[static_cast<std::size_t>(2 * a + 1)] = true;
            in = in && !below && !above;
        }
        return in;
    };
    pile_ = coupling::load_state(sim_->coupled(), scenario_.pile, [&](const Vec3& c, double r) {
        if (region && !inside(c)) return false;
        return sim.clear_of_machine(c, r);
    });
    if (!region) return;
    const std::size_t spheres = world_->particles().size(), rocks = sim_->coupled().rocks().size();
    if (spheres + rocks == 0)
        throw InputError(concat(scenario_.source, ": pile_region [", region->min_m.x, ", ", region->min_m.y, ", ", region->min_m.z, "] to [",
                                region->max_m.x, ", ", region->max_m.y, ", ", region->max_m.z, "] m keeps none of the pile's bodies"));
    // the bodies within hold_m of a cutting face, by their centres (a rock's centroid, as the region judged it)
    auto held = [&](const Vec3& c) {
        for (int a = 0; a < 3; ++a) {
            if (cuts[static_cast<std::size_t>(2 * a)] && c[a] - region->min_m[a] < region->hold_m) return true;
            if (cuts[static_cast<std::size_t>(2 * a + 1)] && region->max_m[a] - c[a] < region->hold_m) return true;
        }
        return false;
    };
    std::vector<std::size_t> held_spheres, held_rocks;
    for (std::size_t i = 0; i < spheres; ++i)
        if (held(world_->particles().position_m[i])) held_spheres.push_back(i);
    const std::vector<coupling::RockRecord>& all = sim_->coupled().rocks();
    for (std::size_t k = 0; k < rocks; ++k)
        if (held(sim_->rigid().position_m(all[k].body))) held_rocks.push_back(k);
    sim_->hold(held_spheres, held_rocks);
}

void Simulation::build()
{
    std::unique_ptr<dem::World> world = build_world(scenario_);
    world_ = world.get();
    if (scenario_.uses_coupling()) sim_ = build_co_simulation(scenario_, std::move(world));
    else own_world_ = std::move(world);
}

void Simulation::write_state(StateWriter& out) const
{
    if (sim_) sim_->coupled().write_rocks(out);
    world_->write_state(out);
    if (sim_) sim_->write_state(out);
    out.tag("pours");
    for (const dem::Pourer& p : pourers_) p.write_state(out);
}

void Simulation::remove_walls_due()
{
    // build_world adds the planes, then the meshes, first
    for (std::size_t k = 0; k < scenario_.planes.size() + scenario_.meshes.size(); ++k) {
        const bool plane = k < scenario_.planes.size();
        const double at = plane ? scenario_.planes[k].removed_at_s : scenario_.meshes[k - scenario_.planes.size()].removed_at_s;
        const int id = static_cast<int>(k);
        if (std::isfinite(at) && !world_->wall_removed(id) && reached(at)) world_->remove_wall(id);
    }
}

void Simulation::step()
{
    remove_walls_due();
    const std::uint64_t before = world_->step_count();
    if (sim_) sim_->step();
    else world_->step();
    if (world_->step_count() / kPourEvery != before / kPourEvery)
        for (dem::Pourer& p : pourers_) p.update(*world_);
}

void Simulation::run_until(double t_s)
{
    while (!reached(t_s)) step();
}

}  // namespace dipper::scenario
