// Parameter sweeps: a base scenario and the keys to vary (lists of values or ranges); every combination
// is a variant, run into its own folder, and one table collects their summaries.
#pragma once

#include "scenario/runner.h"
#include "scenario/scenario.h"

#include <string>
#include <vector>

namespace dipper::scenario {

/// One varied key: its path in the base scenario (`materials.particle_density_kg_per_m3`,
/// `meshes[0].motion.velocity_m_per_s`) and its values, each as YAML text.
struct SweepParameter {
    std::string key;
    std::vector<std::string> values;
};

/// A key set to a value, as a sweep's variant or a script sets it: `key` a path such as `shovel.rake_angle_deg` or
/// `meshes[0].motion.velocity_m_per_s`, `value` YAML text, `where` what messages about it begin with.
struct KeyValue {
    std::string key, value, where;
};

/// The scenario text with each key set to its value (keys the text leaves out are added, maps included); an
/// InputError names the key if it is no scenario key or the text has no such list item. `text_source` names
/// the text in messages. The result is parsed as any scenario text is.
std::string with_values(const std::string& text, const std::vector<KeyValue>& values, const std::string& text_source);

struct Sweep {
    std::string source;
    std::string base_text, base_source, base_dir;  ///< the base scenario file
    std::vector<SweepParameter> parameters;
    /// Every combination, the first parameter varying slowest; each variant's parameter values.
    std::vector<std::vector<std::string>> variants() const;
    /// The base scenario with the variant's values set (parsed and checked).
    Scenario variant_scenario(std::size_t index) const;
};

/// Reads a sweep file:
///   dipper_sweep: 1
///   base: scenario.yaml                      (relative to the sweep file)
///   parameters:
///     - {key: materials.particle_density_kg_per_m3, values: [3000, 3700]}
///     - {key: time.step_s, from: 1.0e-5, to: 2.0e-5, step: 5.0e-6}
/// Every variant is parsed here, so a bad key or value fails before anything runs.
Sweep load_sweep(const std::string& path);

/// What a rank's share of a sweep came to.
struct SweepOutcome {
    int failed = 0;        ///< variants that did not complete
    bool stopped = false;  ///< a variant was stopped by SIGINT or SIGTERM, and the ones after it were not started
};
/// Runs the variants whose index % ranks == rank into out_dir/variant_NNN (all of them for 1 rank), until one is
/// stopped by a signal.
SweepOutcome run_sweep_variants(const Sweep& sweep, const std::string& out_dir, const RunOptions& options, int rank, int ranks);

/// Writes out_dir/sweep.csv from the variants' summary.json files: variant, parameter values, status,
/// time, steps, particles, mass, kinetic energy, region masses, wall forces. No wall-clock columns, so
/// that the same sweep gives the same table however it was spread over processes.
void write_sweep_table(const Sweep& sweep, const std::string& out_dir);

}  // namespace dipper::scenario
