// What a run needs before its first step, checked by `dipper check`, at the start of a run and on resume:
// a time step, output intervals the step can keep, the memory and the step count a machine can hold.
#pragma once

#include "coupling/co_simulation.h"
#include "dem/world.h"
#include "scenario/scenario.h"

#include <string>
#include <vector>

namespace dipper::scenario {

/// The time step the run will take: time.step_s, or the default of the stiffest, smallest sphere present
/// in the world or brought by a fill or pour (infinite when none is known, e.g. before a pile is read).
double planned_step_s(const Scenario& scenario, const dem::World& world);
/// The bytes a run of this many spheres holds at most (measured: 0.74 kB per sphere on a loose bed of
/// 1 and 2 million, plus the longer neighbour lists of a packed bed).
double run_memory_bytes(double spheres);
/// Throws an InputError naming the key and value if the run could not go through: an output interval
/// shorter than the step (at 1e-17 s the schedule stopped advancing and the run hung), or more spheres
/// than the machine's memory holds (the fills' and pours' count, or the world's when larger).
void require_run_fits(const Scenario& scenario, const dem::World& world);
/// Throws an InputError naming the first pour if the world has no sphere once the fills and the pours due
/// at t = 0 are placed and the scenario sets no time.step_s: the default step comes from the spheres.
void require_spheres_at_start(const Scenario& scenario, const dem::World& world);
/// The shovel's path against the scenario's planes and meshes (rigid::find_crossings): throws an InputError
/// naming the part, the wall, the time and the depth of each place where a part would pass into a wall that
/// stands for steel, and returns one warning for each crossing of a wall marked `material_only`. Nothing
/// without a shovel.
std::vector<std::string> require_clear_path(const Scenario& scenario, const coupling::CoSimulation& sim);
/// A repose probe's slope between side walls that hold the particles by friction reads high: one warning per
/// such plane (a vertical plane facing across the slope whose pair with a fill's or pour's material has sliding
/// or rolling friction), with the coefficients. Measured: about 3 deg per wall in a 0.9 m slice of 150 mm spheres,
/// none from frictionless walls at any width (docs/results.md). Nothing without a repose probe.
std::vector<std::string> repose_wall_warnings(const Scenario& scenario, const dem::MaterialTable& materials);
/// What `dipper check` does past parsing: builds the world with its mesh files and Bullet's side, checks the
/// material pairs, places the pours due at t = 0 where the time step depends on them, and checks the
/// intervals against the step and the memory against the machine's, and the shovel's path against the walls;
/// an InputError for what the run would refuse at its start. Returns the warnings (require_clear_path,
/// repose_wall_warnings).
std::vector<std::string> check_scenario(const Scenario& scenario);

}  // namespace dipper::scenario
