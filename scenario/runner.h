// Running a scenario: the time loop with its outputs (ParaView series, probes.csv, summary.json),
// progress lines, checkpoints (at an interval, on SIGINT/SIGTERM and at the end) and resuming from one.
#pragma once

#include "scenario/run_limits.h"
#include "scenario/scenario.h"
#include "scenario/simulation.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace dipper::scenario {

enum class RunStatus { completed, interrupted, diverged };

struct RunOptions {
    int threads = -1;         ///< > 0 replaces the scenario's threads (resume: the checkpoint's count)
    bool progress = true;     ///< progress lines on stderr
    double stop_after_s = 0;  ///< > 0: stop with a checkpoint once simulated time reaches this (tests, batch queues)
    /// resume only: the run's end (time.duration_s) moved later to this time, as YAML text ("7"); empty keeps it.
    /// A run that stopped at its end goes on (a pile still creeping); later checkpoints keep the new end.
    std::string until_s;
    /// Called after every step with the simulated time and the step count; false stops the run with a checkpoint
    /// as SIGINT does (a front end's progress display and stop button).
    std::function<bool(double time_s, std::uint64_t steps)> on_step;
};

struct RunResult {
    RunStatus status = RunStatus::completed;
    std::string message;      ///< the diagnosis of a diverged run
    double time_s = 0.0;
    std::uint64_t steps = 0;
    bool stopped_by_signal = false;  ///< interrupted by SIGINT or SIGTERM: a sweep stops with it
};

/// Runs a scenario from t = 0, writing into out_dir (created; files of an earlier run there are replaced).
RunResult run_scenario(const Scenario& scenario, const std::string& out_dir, const RunOptions& options);
/// Continues the run in out_dir from its checkpoint (out_dir/checkpoint.bin, or `checkpoint_file` if given).
RunResult resume_run(const std::string& out_dir, const RunOptions& options, const std::string& checkpoint_file = "");
/// The model of a run's checkpoint (out_dir/checkpoint.bin, or `checkpoint_file`) as it was saved, to read or step
/// on without the run's files; on `threads` (> 0) or the checkpoint's own count.
std::unique_ptr<Simulation> read_checkpoint(const std::string& out_dir, int threads = 0, const std::string& checkpoint_file = "");

/// FNV-1a hash of every particle's position, velocity and spin in id order: equal hashes, equal states.
std::uint64_t particle_state_hash(const dem::World& world);

/// The progress line's rate, steps per second of wall clock over about the last minute: `previous` (0 before the
/// first line) moved towards `recent`, the rate since the last line, by `since_s` / max(since_s, min(elapsed_s, 60)),
/// elapsed_s being the time since the run (or resumed leg) began. The first line gives `recent`.
double progress_rate(double previous, double recent, double since_s, double elapsed_s);

/// Exit code of the dipper command for a result: 0 completed, 3 diverged, 130 interrupted.
int exit_code(const RunResult& result);

}  // namespace dipper::scenario
