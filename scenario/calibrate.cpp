#include "scenario/calibrate.h"

#include "core/errors.h"
#include "core/files.h"
#include "scenario/run_limits.h"
#include "scenario/sweep.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace dipper::scenario {

namespace fs = std::filesystem;

ReposeCalibration search_repose(const std::function<double(double, double, int)>& angle_of, const ReposeSearch& s)
{
    require_positive(s.tolerance_deg, "tolerance_deg", "repose calibration");
    require_in_range(s.target_deg, 1.0, 89.0, "target_deg", "repose calibration");
    if (!(s.friction_max > s.friction_min && s.friction_min >= 0.0))
        throw InputError(concat("repose calibration: friction range [", s.friction_min, ", ", s.friction_max, "] is empty"));
    if (s.max_runs_per_rolling < 2) throw InputError("repose calibration: at least 2 runs per rolling friction");
    if (s.seeds < 1 || s.seeds > 100) throw InputError(concat("repose calibration: seeds per trial must be 1 to 100; got ", s.seeds));
    ReposeCalibration c;
    for (const double rolling : s.rolling_frictions) {
        const auto run = [&](double mu) {
            ReposeRun r{mu, rolling, 0.0, 0.0, {}};
            for (int k = 0; k < s.seeds; ++k) r.seed_angles_deg.push_back(angle_of(mu, rolling, k));
            for (const double a : r.seed_angles_deg) r.angle_deg += a / s.seeds;
            if (s.seeds > 1) {
                double sum2 = 0.0;
                for (const double a : r.seed_angles_deg) sum2 += (a - r.angle_deg) * (a - r.angle_deg);
                r.angle_sd_deg = std::sqrt(sum2 / (s.seeds - 1));
            }
            c.runs.push_back(r);
            return r;
        };
        ReposeRun lo = run(s.friction_min), hi = run(s.friction_max);
        const double target = s.target_deg;
        const auto hit = [&](const ReposeRun& r) { return std::abs(r.angle_deg - target) <= s.tolerance_deg; };
        if (hit(lo) || hit(hi)) {
            c.matches.push_back(hit(lo) ? lo : hi);
            continue;
        }
        if (!(lo.angle_deg < target && hi.angle_deg > target)) {
            c.notes.push_back(concat("rolling friction ", rolling, ": the angle runs from ", lo.angle_deg, " to ", hi.angle_deg,
                                     " deg over friction ", s.friction_min, " to ", s.friction_max, "; ", target,
                                     " deg is not in between"));
            continue;
        }
        bool found = false;
        for (int k = 2; k < s.max_runs_per_rolling && !found; ++k) {
            // regula falsi, kept off the ends so that a flat stretch still halves the interval
            double mu = lo.friction + (target - lo.angle_deg) * (hi.friction - lo.friction) / (hi.angle_deg - lo.angle_deg);
            const double margin = 0.1 * (hi.friction - lo.friction);
            mu = std::clamp(mu, lo.friction + margin, hi.friction - margin);
            const ReposeRun r = run(mu);
            if (hit(r)) {
                c.matches.push_back(r);
                found = true;
            } else if (r.angle_deg < target) {
                lo = r;
            } else {
                hi = r;
            }
        }
        if (!found)
            c.notes.push_back(concat("rolling friction ", rolling, ": ", s.max_runs_per_rolling, " runs narrowed friction to [", lo.friction,
                                     ", ", hi.friction, "] (", lo.angle_deg, " to ", hi.angle_deg, " deg) without a run within ",
                                     s.tolerance_deg, " deg of ", target));
    }
    return c;
}

namespace {

std::string number(double v)
{
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", v);
    return b;
}

std::string read_text(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw InputError(concat("cannot open scenario file '", path, "'"));
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

ReposeCalibration calibrate_repose(const std::string& file, const std::string& a, const std::string& b, const ReposeSearch& search,
                                   const std::string& out_dir, const RunOptions& options)
{
    const Scenario base = load_scenario(file);
    if (!base.repose) throw InputError(concat(file, ": no probes.repose; the calibration fits the angle that probe measures"));
    // side walls that hold the pile by friction bias the angle the calibration fits: said before the runs
    const std::vector<std::string> wall_warnings = repose_wall_warnings(base, build_world(base)->materials());
    for (const std::string& w : wall_warnings) std::fprintf(stderr, "dipper: warning: %s\n", w.c_str());
    // the pair's entry in materials.pairs, which the trials change
    const std::string text = read_text(file);
    const YAML::Node pairs = YAML::Load(text)["materials"]["pairs"];
    int index = -1;
    for (std::size_t k = 0; pairs && pairs.IsSequence() && k < pairs.size(); ++k) {
        const YAML::Node m = pairs[k]["materials"];
        if (!m || !m.IsSequence() || m.size() != 2) continue;
        const std::string x = m[0].Scalar(), y = m[1].Scalar();
        if ((x == a && y == b) || (x == b && y == a)) index = static_cast<int>(k);
    }
    if (index < 0)
        throw InputError(concat(file, ": materials.pairs has no entry for ", a, "-", b, "; add {materials: [", a, ", ", b,
                                "], friction: ..., rolling_friction: ...} so the calibration can vary it"));
    std::error_code error;
    fs::create_directories(out_dir, error);
    if (error) throw InputError(concat("cannot create '", out_dir, "': ", error.message()));

    Sweep trial;
    trial.source = file;
    trial.base_text = text;
    trial.base_source = file;
    trial.base_dir = fs::absolute(file).parent_path().string();
    const std::string key = concat("materials.pairs[", index, "].");
    int count = 0;
    const auto angle_of = [&](double friction, double rolling, int seed_index) {
        trial.parameters = {{key + "friction", {number(friction)}}, {key + "rolling_friction", {number(rolling)}},
                            {"seed", {std::to_string(base.seed + static_cast<std::uint64_t>(seed_index))}}};
        char name[48];
        if (search.seeds == 1) std::snprintf(name, sizeof name, "run_%03d", count);
        else std::snprintf(name, sizeof name, "run_%03d_seed_%d", count, seed_index);
        if (seed_index + 1 == search.seeds) ++count;
        const std::string dir = (fs::path(out_dir) / name).string();
        RunOptions o = options;
        const RunResult r = run_scenario(trial.variant_scenario(0), dir, o);
        if (r.status != RunStatus::completed)
            throw SimulationError(concat("repose calibration, friction ", friction, ", rolling friction ", rolling, ": the run in ",
                                         dir, " did not complete: ", r.message));
        const std::string summary = read_text(dir + "/summary.json");
        std::smatch m;
        if (!std::regex_search(summary, m, std::regex("\"repose_angle_deg\": ([-0-9.eE+]+)")))
            throw SimulationError(concat("repose calibration: the run in ", dir, " left no pile slope to fit (see its summary.json)"));
        const double angle = std::stod(m[1]);
        if (options.progress)
            std::fprintf(stderr, "calibrate repose: friction %.4g, rolling friction %.4g, seed %llu: %.2f deg\n", friction, rolling,
                         static_cast<unsigned long long>(base.seed + static_cast<std::uint64_t>(seed_index)), angle);
        return angle;
    };
    ReposeCalibration c = search_repose(angle_of, search);
    for (auto w = wall_warnings.rbegin(); w != wall_warnings.rend(); ++w) c.notes.insert(c.notes.begin(), "warning: " + *w);

    const std::string csv_path = (fs::path(out_dir) / "calibration.csv").string();
    std::ofstream csv = open_for_writing(csv_path);
    csv << "run,friction,rolling_friction,repose_angle_deg,angle_sd_deg,seed_angles_deg\n";
    for (std::size_t k = 0; k < c.runs.size(); ++k) {
        const ReposeRun& r = c.runs[k];
        csv << k << ',' << r.friction << ',' << r.rolling_friction << ',' << r.angle_deg << ',' << r.angle_sd_deg << ',';
        for (std::size_t q = 0; q < r.seed_angles_deg.size(); ++q) csv << (q ? ";" : "") << r.seed_angles_deg[q];
        csv << '\n';
    }
    finish_writing(csv, csv_path);
    const std::string md_path = (fs::path(out_dir) / "calibration.md").string();
    std::ofstream md = open_for_writing(md_path);
    md << "# Repose calibration of " << file << "\n\nTarget " << search.target_deg << " deg within " << search.tolerance_deg
       << " deg, varying the " << a << "-" << b << " pair";
    if (search.seeds > 1)
        md << "; each trial is the mean of " << search.seeds << " runs with seeds " << base.seed << " to " << base.seed + static_cast<std::uint64_t>(search.seeds - 1)
           << " (sd: their standard deviation; the mean's standard error is sd / sqrt(" << search.seeds << "))";
    md << ".\n\n| friction | rolling friction | angle [deg] | sd [deg] | each seed [deg] |\n| --- | --- | --- | --- | --- |\n";
    for (const ReposeRun& r : c.runs) {
        md << "| " << number(r.friction) << " | " << number(r.rolling_friction) << " | " << number(r.angle_deg) << " | " << number(r.angle_sd_deg) << " | ";
        for (std::size_t q = 0; q < r.seed_angles_deg.size(); ++q) md << (q ? ", " : "") << number(r.seed_angles_deg[q]);
        md << " |\n";
    }
    md << "\n## Pairs that hit the target\n\n";
    if (c.matches.empty()) md << "None.\n";
    for (const ReposeRun& r : c.matches)
        md << "- friction " << number(r.friction) << " with rolling friction " << number(r.rolling_friction) << ": " << number(r.angle_deg)
           << " deg" << (search.seeds > 1 ? concat(" (sd ", number(r.angle_sd_deg), " deg over ", search.seeds, " seeds)") : std::string()) << "\n";
    if (c.matches.size() > 1)
        md << "\nMore than one pair hits the target: sliding and rolling friction trade off against each other, so the repose "
              "angle alone does not fix both (the thesis' warning). Choose with a second measurement (flow rate, bulk density, "
              "a measured flow profile).\n";
    for (const std::string& n : c.notes) md << "\n" << n << "\n";
    finish_writing(md, md_path);
    return c;
}

}  // namespace dipper::scenario
