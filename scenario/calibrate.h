// Calibration of the ore's pair coefficients against a measured angle of repose (thesis Paper A §3.1):
// a scenario with a repose probe is run with the sliding and rolling friction of one material pair
// varied until the fitted angle hits the target. Sliding and rolling friction trade off against each
// other (the thesis warns that the calibrated pair is not unique), so the search runs for several rolling
// frictions and reports the sliding friction that hits the target with each.
#pragma once

#include "scenario/runner.h"

#include <functional>
#include <string>
#include <vector>

namespace dipper::scenario {

struct ReposeRun {
    double friction = 0.0, rolling_friction = 0.0;
    double angle_deg = 0.0;      ///< the mean over the trial's seeds
    double angle_sd_deg = 0.0;   ///< sample standard deviation over the seeds (0 with one seed)
    std::vector<double> seed_angles_deg;  ///< one per seed, in seed order
};

struct ReposeSearch {
    double target_deg = 34.7, tolerance_deg = 1.0;
    std::vector<double> rolling_frictions{0.05, 0.1, 0.2};
    double friction_min = 0.2, friction_max = 1.2;
    int max_runs_per_rolling = 6;
    /// Runs per trial, with the scenario's seed, seed + 1, ...: the trial's angle is their mean. One small
    /// pile scatters by a few degrees from seed to seed, so a tolerance of 1 deg needs several.
    int seeds = 1;
};

struct ReposeCalibration {
    std::vector<ReposeRun> runs;     ///< every run, in order
    std::vector<ReposeRun> matches;  ///< per rolling friction that reached the target: the run that hit it
    std::vector<std::string> notes;  ///< rolling frictions that could not reach it, and why
};

/// The search itself, on any angle function (a run of the scenario, or a closed form in the tests): for
/// each rolling friction, the angle at the ends of the friction range, then regula falsi on friction
/// (the angle grows with friction) until within tolerance or out of runs. angle_of(friction, rolling,
/// k) is the angle of seed k; a trial calls it for k = 0 .. search.seeds - 1 and takes the mean.
ReposeCalibration search_repose(const std::function<double(double friction, double rolling, int seed_index)>& angle_of,
                                const ReposeSearch& search);

/// Runs `scenario_file` (which must have probes.repose and a materials.pairs entry for the pair a-b) in
/// out_dir/run_NNN for each trial (out_dir/run_NNN_seed_K with several seeds) and writes out_dir/calibration.csv and out_dir/calibration.md.
ReposeCalibration calibrate_repose(const std::string& scenario_file, const std::string& material_a, const std::string& material_b,
                                   const ReposeSearch& search, const std::string& out_dir, const RunOptions& options);

}  // namespace dipper::scenario
