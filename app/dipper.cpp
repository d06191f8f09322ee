// dipper: runs scenario files.
//
//   dipper run FILE [--out DIR] [--threads N] [--stop-after S] [--quiet]
//   dipper check FILE...
//   dipper resume DIR [--from CHECKPOINT] [--threads N] [--stop-after S] [--until S] [--quiet]
//   dipper sweep FILE [--out DIR] [--threads N] [--quiet]     (under mpirun: variants spread over ranks)
//   dipper report DIR      (report.md and PNG figures from summary.json and probes.csv)
//   dipper keys            (every scenario key as a Markdown table)
#include "core/errors.h"
#include "scenario/calibrate.h"
#include "scenario/keys.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/sweep.h"

#ifdef DIPPER_HAVE_MPI
#include <mpi.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace dipper;
using namespace dipper::scenario;

namespace {

constexpr const char* kUsage =
    "usage: dipper run FILE [--out DIR] [--threads N] [--stop-after SECONDS] [--quiet]\n"
    "       dipper check FILE...   (scenario or sweep files)\n"
    "       dipper resume DIR [--from CHECKPOINT] [--threads N] [--stop-after SECONDS] [--until SECONDS] [--quiet]\n"
    "       dipper sweep FILE [--out DIR] [--threads N] [--quiet]   (mpirun -np N dipper sweep ... spreads it)\n"
    "       dipper calibrate repose FILE [--target DEG] [--tolerance DEG] [--pair A,B] [--rolling R1,R2,...]\n"
    "                              [--seeds N] [--out DIR] [--threads N] [--quiet]\n"
    "       dipper report DIR      (report.md with figures, also written after run and resume)\n"
    "       dipper keys\n";

[[noreturn]] void usage(const std::string& message)
{
    std::fprintf(stderr, "dipper: %s\n%s", message.c_str(), kUsage);
    std::exit(2);
}

struct Options {
    std::vector<std::string> positional;
    std::string out, from;
    RunOptions run;
    ReposeSearch repose;
    std::string pair_a = "ore", pair_b = "ore";
};

double number_option(const std::string& option, const std::string& v)
{
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !std::isfinite(x)) usage(option + " needs a number; got '" + v + "'");
    return x;
}

/// The commands that read options, and the options each takes (as the usage lists them); any other is an error,
/// not ignored.
const std::map<std::string, std::vector<std::string>>& command_options()
{
    static const std::map<std::string, std::vector<std::string>> table{
        {"check", {}},
        {"run", {"--out", "--threads", "--stop-after", "--quiet"}},
        {"resume", {"--from", "--threads", "--stop-after", "--until", "--quiet"}},
        {"sweep", {"--out", "--threads", "--quiet"}},
        {"calibrate", {"--target", "--tolerance", "--pair", "--rolling", "--seeds", "--out", "--threads", "--quiet"}},
        {"report", {}}};
    return table;
}

Options parse_options(int argc, char** argv, int first, const std::string& command)
{
    Options o;
    const std::vector<std::string>& allowed = command_options().at(command);
    for (int a = first; a < argc; ++a) {
        const std::string arg = argv[a];
        if (!arg.empty() && arg[0] == '-' && std::find(allowed.begin(), allowed.end(), arg) == allowed.end()) {
            std::string takes;
            for (const std::string& option : allowed) takes += (takes.empty() ? "" : ", ") + option;
            usage(concat(command, " does not take ", arg, "; it takes ", takes.empty() ? "no options" : takes));
        }
        const auto value = [&]() -> std::string {
            if (a + 1 >= argc) usage(arg + " needs a value");
            return argv[++a];
        };
        if (arg == "--out") o.out = value();
        else if (arg == "--from") o.from = value();
        else if (arg == "--threads") {
            const std::string v = value();
            char* end = nullptr;
            const long n = std::strtol(v.c_str(), &end, 10);
            if (v.empty() || *end != '\0' || n < 1 || n > 1024) usage("--threads needs a whole number from 1 to 1024; got '" + v + "'");
            o.run.threads = static_cast<int>(n);
        } else if (arg == "--stop-after") {
            const std::string v = value();
            char* end = nullptr;
            o.run.stop_after_s = std::strtod(v.c_str(), &end);
            if (v.empty() || *end != '\0' || !(o.run.stop_after_s > 0.0)) usage("--stop-after needs seconds > 0; got '" + v + "'");
        } else if (arg == "--until") {
            o.run.until_s = value();
        } else if (arg == "--target") {
            o.repose.target_deg = number_option(arg, value());
        } else if (arg == "--tolerance") {
            o.repose.tolerance_deg = number_option(arg, value());
        } else if (arg == "--pair") {
            const std::string v = value();
            const auto comma = v.find(',');
            if (comma == std::string::npos || comma == 0 || comma + 1 == v.size()) usage("--pair needs two materials A,B; got '" + v + "'");
            o.pair_a = v.substr(0, comma);
            o.pair_b = v.substr(comma + 1);
        } else if (arg == "--rolling") {
            std::string v = value() + ",";
            o.repose.rolling_frictions.clear();
            for (std::size_t at = 0, comma; (comma = v.find(',', at)) != std::string::npos; at = comma + 1)
                o.repose.rolling_frictions.push_back(number_option(arg, v.substr(at, comma - at)));
        } else if (arg == "--seeds") {
            const std::string v = value();
            char* end = nullptr;
            const long n = std::strtol(v.c_str(), &end, 10);
            if (v.empty() || *end != '\0' || n < 1 || n > 100) usage("--seeds needs a whole number from 1 to 100; got '" + v + "'");
            o.repose.seeds = static_cast<int>(n);
        } else if (arg == "--quiet") o.run.progress = false;
        else if (!arg.empty() && arg[0] == '-') usage("unknown option " + arg);
        else o.positional.push_back(arg);
    }
    return o;
}

/// What a finished run prints: status, the summary's main numbers, and where the files are.
void report(const RunResult& result, const std::string& dir)
{
    std::ifstream in(dir + "/summary.json");
    std::stringstream text;
    text << in.rdbuf();
    const char* status = result.status == RunStatus::completed ? "completed"
                         : result.status == RunStatus::interrupted ? "interrupted" : "DIVERGED";
    std::printf("dipper: run %s at t = %.6g s after %llu steps\n", status, result.time_s,
                static_cast<unsigned long long>(result.steps));
    if (!result.message.empty()) std::printf("  %s\n", result.message.c_str());
    std::printf("summary (%s/summary.json):\n%s", dir.c_str(), text.str().c_str());
    const bool checkpointed = std::filesystem::exists(dir + "/checkpoint.bin");
    std::printf("files: %s/particles.pvd (ParaView), %s/probes.csv%s%s\n", dir.c_str(), dir.c_str(),
                checkpointed ? ", " : "", checkpointed ? (dir + "/checkpoint.bin").c_str() : "");
    if (result.status == RunStatus::interrupted && checkpointed) std::printf("continue with: dipper resume %s\n", dir.c_str());
    if (result.status == RunStatus::diverged)
        std::printf("the files written up to the failure are kept in %s; the last checkpoint (if any) can be resumed after "
                    "changing nothing, or the scenario rerun with a smaller time.step_s\n", dir.c_str());
}

/// True if the file is a sweep file (its top level has the key dipper_sweep).
bool is_sweep_file(const std::string& path)
{
    std::ifstream in(path);
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("dipper_sweep:", 0) == 0) return true;
    return false;
}

/// Writes DIR/report.md and its figures with report.py (Debian's python3 and matplotlib). A missing
/// Python is a warning, not a failure of the run.
int make_report(const std::string& dir)
{
    std::string script;
    for (const char* candidate : {DIPPER_REPORT_SCRIPT_INSTALLED, DIPPER_REPORT_SCRIPT_SOURCE})
        if (std::filesystem::exists(candidate)) {
            script = candidate;
            break;
        }
    const char* python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    if (script.empty()) {
        std::fprintf(stderr, "dipper: report.py not found; no report written\n");
        return 1;
    }
    const std::string command = std::string(python) + " '" + script + "' '" + dir + "'";
    const int rc = std::system(command.c_str());
    if (rc != 0) std::fprintf(stderr, "dipper: the report could not be written (%s returned %d)\n", command.c_str(), rc);
    return rc == 0 ? 0 : 1;
}

int print_keys()
{
    std::printf("| key | type | default | meaning |\n| --- | --- | --- | --- |\n");
    for (const KeySpec& k : scenario_keys())
        std::printf("| `%s` | %s | %s | %s |\n", k.path.c_str(), k.type.c_str(),
                    k.default_value.empty() ? "" : ("`" + k.default_value + "`").c_str(), k.description.c_str());
    return 0;
}

/// Runs a sweep; under mpirun (OpenMPI sets OMPI_COMM_WORLD_SIZE) the variants are dealt out to the
/// ranks in turn, and rank 0 writes the table once all are done.
int sweep(const Options& o)
{
    const Sweep sw = load_sweep(o.positional[0]);
    const std::string dir = o.out.empty() ? "out/" + std::filesystem::path(o.positional[0]).stem().string() : o.out;
    int rank = 0, ranks = 1;
#ifdef DIPPER_HAVE_MPI
    const bool under_mpi = std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMI_SIZE") != nullptr;
    if (under_mpi) {
        MPI_Init(nullptr, nullptr);
        MPI_Comm_rank(MPI_COMM_WORLD, &rank);
        MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    }
#endif
    const std::size_t n = sw.variants().size();
    if (rank == 0) std::printf("dipper sweep: %zu variants into %s on %d process%s\n", n, dir.c_str(), ranks, ranks == 1 ? "" : "es");
    int failed = 0, stopped = 0;
    std::string error;
    try {
        const SweepOutcome outcome = run_sweep_variants(sw, dir, o.run, rank, ranks);
        failed = outcome.failed;
        stopped = outcome.stopped ? 1 : 0;
    } catch (const std::exception& e) {
        error = e.what();
        failed = 1;
    }
#ifdef DIPPER_HAVE_MPI
    if (under_mpi) {
        int total = 0, any_stopped = 0;
        MPI_Allreduce(&failed, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
        MPI_Allreduce(&stopped, &any_stopped, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
        failed = total;
        stopped = any_stopped;
    }
#endif
    if (!error.empty()) std::fprintf(stderr, "dipper: rank %d: %s\n", rank, error.c_str());
    if (stopped != 0) {
        if (rank == 0)
            std::printf("dipper sweep: stopped by a signal; the variants run so far are in %s (an interrupted one "
                        "continues with dipper resume %s/variant_NNN), the others were not started, and no table was "
                        "written\n",
                        dir.c_str(), dir.c_str());
#ifdef DIPPER_HAVE_MPI
        if (under_mpi) MPI_Finalize();
#endif
        return 130;
    }
    if (rank == 0 && error.empty()) {
        write_sweep_table(sw, dir);
        make_report(dir);
        std::printf("dipper sweep: %zu variants, %d did not complete; table: %s/sweep.csv\n", n, failed, dir.c_str());
    }
#ifdef DIPPER_HAVE_MPI
    if (under_mpi) MPI_Finalize();
#endif
    return failed == 0 ? 0 : 3;
}

}  // namespace

int main(int argc, char** argv)
{
    if (argc < 2) usage("no command given");
    const std::string command = argv[1];
    if (command == "--help" || command == "-h" || command == "help") {
        std::printf("%s", kUsage);
        return 0;
    }
    try {
        if (command == "keys") {
            if (argc > 2) usage(concat("keys takes no arguments; got '", argv[2], "'"));
            return print_keys();
        }
        if (command_options().count(command) == 0) usage("unknown command '" + command + "'");
        const Options o = parse_options(argc, argv, 2, command);
        if (command == "check") {
            if (o.positional.empty()) usage("check needs at least one scenario file");
            for (const std::string& file : o.positional) {
                if (is_sweep_file(file)) {
                    const Sweep sw = load_sweep(file);  // every variant is parsed and checked
                    std::printf("%s: ok: sweep of %zu variant%s\n", file.c_str(), sw.variants().size(), sw.variants().size() == 1 ? "" : "s");
                    continue;
                }
                const Scenario s = load_scenario(file);
                for (const std::string& w : check_scenario(s)) std::fprintf(stderr, "warning: %s\n", w.c_str());
                double fill = 0.0, pour = 0.0;
                for (const auto& f : s.fills) fill += f.mass_kg;
                for (const auto& p : s.pours) pour += p.mass_kg;
                std::printf("%s: ok: '%s', %.6g s, %zu walls, %.6g kg filled, %.6g kg poured, %zu materials\n", file.c_str(),
                            s.name.c_str(), s.duration_s, s.planes.size() + s.meshes.size(), fill, pour, s.materials.size());
            }
            return 0;
        }
        if (command == "run") {
            if (o.positional.size() != 1) usage("run needs exactly one scenario file");
            const Scenario s = load_scenario(o.positional[0]);
            const std::string dir = o.out.empty() ? "out/" + s.name : o.out;
            const RunResult r = run_scenario(s, dir, o.run);
            report(r, dir);
            make_report(dir);
            return exit_code(r);
        }
        if (command == "resume") {
            if (o.positional.size() != 1) usage("resume needs exactly one output folder");
            const RunResult r = resume_run(o.positional[0], o.run, o.from);
            report(r, o.positional[0]);
            make_report(o.positional[0]);
            return exit_code(r);
        }
        if (command == "report") {
            if (o.positional.size() != 1) usage("report needs exactly one output folder");
            return make_report(o.positional[0]);
        }
        if (command == "sweep") {
            if (o.positional.size() != 1) usage("sweep needs exactly one sweep file");
            return sweep(o);
        }
        if (command == "calibrate") {
            if (o.positional.size() != 2 || o.positional[0] != "repose") usage("calibrate needs 'repose' and one scenario file");
            const std::string dir = o.out.empty() ? "out/calibrate_repose" : o.out;
            RunOptions quiet_runs = o.run;
            const ReposeCalibration c = calibrate_repose(o.positional[1], o.pair_a, o.pair_b, o.repose, dir, quiet_runs);
            std::printf("dipper calibrate repose: %zu runs, target %.4g +- %.4g deg\n", c.runs.size(), o.repose.target_deg,
                        o.repose.tolerance_deg);
            for (const ReposeRun& r : c.matches)
                std::printf("  hit: friction %.4g, rolling friction %.4g -> %.2f deg (sd %.2f deg over %d seeds)\n", r.friction,
                            r.rolling_friction, r.angle_deg, r.angle_sd_deg, o.repose.seeds);
            for (const std::string& n : c.notes) std::printf("  %s\n", n.c_str());
            if (c.matches.size() > 1)
                std::printf("  %zu pairs hit the target: the repose angle alone does not fix sliding and rolling friction\n", c.matches.size());
            std::printf("table: %s/calibration.csv, %s/calibration.md\n", dir.c_str(), dir.c_str());
            return c.matches.empty() ? 3 : 0;
        }
        usage("unknown command '" + command + "'");
    } catch (const InputError& e) {
        std::fprintf(stderr, "dipper: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "dipper: %s\n", e.what());
        return 1;
    }
}
