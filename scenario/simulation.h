// A scenario's model and how a run steps it, without the run's files: the DEM world, the co-simulation when
// the scenario has rocks, the shovel, wear or a pile, and the pours. `dipper run` writes its outputs around
// one of these; a program or the Python module steps it directly and reaches the same bits.
#pragma once

#include "core/state_io.h"
#include "coupling/co_simulation.h"
#include "coupling/mixed_bed.h"
#include "dem/insertion.h"
#include "dem/world.h"
#include "scenario/scenario.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace dipper::scenario {

class Simulation {
public:
    /// The model at t = 0: the walls, the pile, the fills (spheres, then rocks clear of the machine), the wear
    /// surfaces and the pours due at t = 0, prepared for the first step. `threads` > 0 replaces the scenario's.
    /// Refuses (InputError) what the run could not go through (require_run_fits, require_spheres_at_start) and a
    /// shovel whose cycle passes through steel (require_clear_path).
    explicit Simulation(Scenario scenario, int threads = 0);
    /// The model as a checkpoint saved it: `in` stands after the checkpoint's run header (checkpoint_header) and
    /// is left before the run's own outputs.
    Simulation(Scenario scenario, int threads, StateReader& in);
    ~Simulation();
    Simulation(const Simulation&) = delete;
    Simulation& operator=(const Simulation&) = delete;

    /// One step as `dipper run` takes it: walls due for removal taken out, one coupling step (or one DEM step
    /// without a co-simulation), and every kPourEvery steps the pours' due particles placed.
    void step();
    /// Steps until time_s() reaches t_s, as a run stopped at t_s would.
    void run_until(double t_s);
    /// Whether time_s() has reached t_s: within a millionth of a step, as the run's schedules count.
    bool reached(double t_s) const { return world_->time_s() >= t_s - 1e-6 * world_->step_s(); }

    /// The model's state for a checkpoint: the rocks, the DEM world, the co-simulation and the pours.
    void write_state(StateWriter& out) const;

    const Scenario& scenario() const { return scenario_; }
    dem::World& world() { return *world_; }
    const dem::World& world() const { return *world_; }
    /// The co-simulation; null for a scenario of spheres and walls only (Scenario::uses_coupling).
    coupling::CoSimulation* co_simulation() { return sim_.get(); }
    const coupling::CoSimulation* co_simulation() const { return sim_.get(); }
    const std::vector<dem::Pourer>& pourers() const { return pourers_; }
    /// What the scenario's pile placed and left out where the dipper stands, when this model was built at t = 0
    /// (a model read from a checkpoint has none: the run keeps it with its outputs).
    const coupling::LoadedState& pile() const { return pile_; }
    double time_s() const { return world_->time_s(); }
    /// The shovel's crossings of walls marked material_only, found when this model was built at t = 0.
    const std::vector<std::string>& warnings() const { return warnings_; }

    static constexpr std::uint64_t kPourEvery = 20;  ///< steps between pour insertions

private:
    void build();
    /// Places the scenario's pile, cut to its region (the bodies held there along the cuts) and clear of the machine.
    void place_pile();
    void remove_walls_due();

    Scenario scenario_;
    dem::World* world_ = nullptr;              ///< own_world_'s or sim_'s
    std::unique_ptr<dem::World> own_world_;    ///< spheres and walls only
    std::unique_ptr<coupling::CoSimulation> sim_;
    std::vector<dem::Pourer> pourers_;
    coupling::LoadedState pile_;
    std::vector<std::string> warnings_;
};

}  // namespace dipper::scenario
