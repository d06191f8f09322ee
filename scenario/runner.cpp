#include "scenario/runner.h"

#include "core/errors.h"
#include "core/files.h"
#include "core/state_io.h"
#include "dem/output.h"
#include "coupling/mixed_bed.h"
#include "scenario/keys.h"
#include "scenario/detail/json.h"
#include "scenario/simulation.h"
#include "scenario/sweep.h"
#include "scenario/wear_results.h"
#include "wear/calibration.h"
#include "wear/wear_output.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <unistd.h>

namespace dipper::scenario {

namespace fs = std::filesystem;
using detail::json_escape;
using detail::json_number;

namespace {

constexpr const char* kCheckpointMagic = "dipper-checkpoint 9";

/// The checkpoint's "run" section: the scenario as it was read, and the thread count (same threads, same bits).
struct RunHeader {
    std::string text, source, base_dir;
    std::int32_t threads = 1;

    template <class IO>
    void fields(IO& io)
    {
        io.tag("run");
        io(text, source, base_dir, threads);
    }
};

/// The entries of each ParaView series (time, file), in the order all_series() gives them.
using SeriesEntries = std::vector<std::vector<std::pair<double, std::string>>>;

volatile std::sig_atomic_t g_signal = 0;
extern "C" void on_signal(int signal) { g_signal = signal; }

/// Catches SIGINT and SIGTERM for the life of a run, so that the loop can checkpoint and stop.
class SignalGuard {
public:
    SignalGuard()
    {
        g_signal = 0;
        struct sigaction action {};
        action.sa_handler = on_signal;
        sigemptyset(&action.sa_mask);
        sigaction(SIGINT, &action, &old_int_);
        sigaction(SIGTERM, &action, &old_term_);
    }
    ~SignalGuard()
    {
        sigaction(SIGINT, &old_int_, nullptr);
        sigaction(SIGTERM, &old_term_, nullptr);
    }
    SignalGuard(const SignalGuard&) = delete;
    SignalGuard& operator=(const SignalGuard&) = delete;

private:
    struct sigaction old_int_ {}, old_term_ {};
};

std::string numbered(const std::string& stem, int index)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "_%06d.vtp", index);
    return stem + buffer;
}

std::string clock_text(double seconds)
{
    if (!std::isfinite(seconds) || seconds < 0.0) return "?";
    const long s = std::lround(seconds);
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
    return buffer;
}

/// One run in its output folder: the world, its pours, the outputs and their schedule.
class Run {
public:
    Run(Scenario scenario, std::string dir, const RunOptions& options)
        : scenario_(std::move(scenario)), dir_(std::move(dir)), options_(options)
    {
        if (options_.threads > 0) scenario_.threads = options_.threads;
    }

    /// t = 0: the folder, the world with its fills, and the first outputs.
    void start_fresh()
    {
        std::error_code error;
        fs::create_directories(dir_, error);
        if (error) throw InputError(concat("cannot create output folder '", dir_, "': ", error.message()));
        for (const char* stale : {"checkpoint.bin", "checkpoint.prev.bin", "checkpoint.next.bin", "summary.json"})
            fs::remove(fs::path(dir_) / stale, error);
        {
            std::ofstream copy = open_for_writing(dir_ + "/scenario.yaml");
            copy << scenario_.text;
            finish_writing(copy, dir_ + "/scenario.yaml");
        }
        adopt(std::make_unique<Simulation>(scenario_));
        pile_ = model_->pile();
        if (options_.progress)
            for (const std::string& w : model_->warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
        if (options_.progress && (pile_.spheres_left_out > 0 || pile_.rocks_left_out > 0))
            std::fprintf(stderr, "dipper: pile %s: %zu spheres and %zu rocks placed; %zu spheres and %zu rocks left out %s\n",
                         scenario_.pile.c_str(), pile_.spheres, pile_.rocks, pile_.spheres_left_out, pile_.rocks_left_out,
                         scenario_.pile_region ? concat("outside pile_region or where the dipper stands; ", held_bodies(),
                                                        " of those placed held along the cuts").c_str()
                                               : "where the dipper stands");
        open_outputs(false, 0);
        write_row();
        write_snapshot();
        next_csv_s_ = scenario_.output.csv_interval_s;
        next_vtk_s_ = scenario_.output.vtk_interval_s > 0.0 ? scenario_.output.vtk_interval_s : scenario_.duration_s;
        next_checkpoint_s_ = scenario_.output.checkpoint_interval_s > 0.0 ? scenario_.output.checkpoint_interval_s
                                                                           : std::numeric_limits<double>::infinity();
    }

    /// Continues from a checkpoint written by checkpoint().
    void start_from(StateReader& in)
    {
        adopt(std::make_unique<Simulation>(scenario_, 0, in));
        walls_ = all_walls();
        std::uint64_t csv_bytes = 0;
        SeriesEntries entries(1 + walls_.size() + (sim_ ? 1 + sim_->wear().size() : 0));
        output_fields(in, wall_seconds_before_, steps_before_, csv_bytes, entries);
        in.finish();
        open_outputs(true, csv_bytes);
        std::size_t k = 0;
        particles_pvd_->restore(entries[k++]);
        for (const auto& w : wall_pvd_) {
            if (w) w->restore(entries[k]);
            ++k;
        }
        if (sim_) {
            if (rocks_pvd_) rocks_pvd_->restore(entries[k]);
            ++k;
            for (const auto& w : wear_pvd_) w->restore(entries[k++]);
        }
    }

    /// The checkpoint's "outputs" section, listed once for writing and reading: the output schedule, the wall
    /// clock and steps so far, the pile, the CSV's length and each ParaView series' entries.
    template <class IO>
    void output_fields(IO& io, double& wall_s, std::uint64_t& steps, std::uint64_t& csv_bytes, SeriesEntries& series)
    {
        io.tag("outputs");
        io(next_csv_s_, next_vtk_s_, next_checkpoint_s_, snapshot_index_, wall_s, steps, pile_, csv_bytes);
        for (auto& entries : series) {
            std::size_t n = entries.size();
            io(n);
            if constexpr (IO::reading) {
                if (n > io.left()) io.fail("too many snapshot entries");
                entries.resize(n);
            }
            for (auto& [t, file] : entries) io(t, file);
        }
    }

    RunResult loop()
    {
        SignalGuard guard;
        const auto start = std::chrono::steady_clock::now();
        last_progress_ = start;
        const std::uint64_t first_step = world_->step_count();
        const bool terminal = isatty(fileno(stderr)) != 0;
        double end_s = scenario_.duration_s;
        const double dt = world_->step_s();
        RunResult result;
        // the run ends at the first step that reaches duration_s (within a millionth of a step)
        const auto reached = [&](double t) { return model_->reached(t); };
        // a shovel run may end after a number of passes: 1 s after the last one's door opened
        const std::size_t passes = scenario_.shovel ? static_cast<std::size_t>(scenario_.shovel->passes) : 0;
        const auto end_after_passes = [&] {
            if (passes > 0 && sim_->passes().size() >= passes)
                end_s = std::min(end_s, sim_->passes()[passes - 1].dump_s + 1.0);
        };
        end_after_passes();  // a resumed run may have done its passes already
        if (reached(end_s)) {
            // a run resumed from its last checkpoint: that checkpoint followed the last row of probes.csv
            last_row_step_ = world_->step_count();
            result.message = concat("the run had already ended at t = ", world_->time_s(), " s; its end outputs are written again");
        }
        if (options_.stop_after_s > 0.0 && reached(options_.stop_after_s) && !reached(end_s))
            throw InputError(concat("--stop-after ", options_.stop_after_s, " s: the run is already at t = ", world_->time_s(),
                                    " s; give a later time"));
        require_reasonable_step_count(end_s - world_->time_s(), dt);
        // this leg's wall clock by phase (summary.json) counts from here
        phases_before_ = world_->phase_seconds();
        rebuilds_before_ = world_->rebuild_count();
        if (sim_) {
            rigid_seconds_before_ = sim_->coupled().rigid_seconds();
            surface_seconds_before_ = sim_->coupled().surface_seconds();
        }
        try {
            while (!reached(end_s)) {
                model_->step();
                if (sim_) end_after_passes();
                // each schedule moves past now; an interval too short to move it is refused before the run
                const auto advance = [&](double& next, double interval) {
                    for (int k = 0; reached(next); ++k) {
                        if (k > 1000 || !(next + interval > next))
                            throw InputError(concat("an output interval of ", interval, " s cannot keep up with the step of ", dt,
                                                    " s at t = ", next, " s"));
                        next += interval;
                    }
                };
                if (reached(next_csv_s_)) {
                    write_row();
                    advance(next_csv_s_, scenario_.output.csv_interval_s);
                }
                if (reached(next_vtk_s_) || reached(end_s)) {
                    write_snapshot();
                    advance(next_vtk_s_, scenario_.output.vtk_interval_s > 0.0 ? scenario_.output.vtk_interval_s : end_s);
                }
                if (reached(next_checkpoint_s_)) {
                    advance(next_checkpoint_s_, scenario_.output.checkpoint_interval_s);
                    checkpoint();
                }
                if (options_.progress) progress(start, first_step, terminal, false);
                const bool caller_stops = options_.on_step && !options_.on_step(world_->time_s(), world_->step_count()) && !reached(end_s);
                if (g_signal != 0 || caller_stops || (options_.stop_after_s > 0.0 && reached(options_.stop_after_s) && !reached(end_s))) {
                    checkpoint();
                    result.status = RunStatus::interrupted;
                    result.stopped_by_signal = g_signal != 0;
                    result.message = g_signal != 0 ? concat("stopped by signal ", static_cast<int>(g_signal))
                                     : caller_stops ? concat("stopped by the caller at t = ", world_->time_s(), " s")
                                                    : concat("stopped at t = ", world_->time_s(), " s as asked");
                    break;
                }
            }
            if (result.status == RunStatus::completed) {
                if (scenario_.output.csv_interval_s > 0.0 && last_row_step_ != world_->step_count()) write_row();
                checkpoint();
                if (!scenario_.output.pile_file.empty())
                    coupling::save_state(sim_->coupled(), dir_ + "/" + scenario_.output.pile_file, scenario_.output.pile_cut_above_m);
            }
        } catch (const SimulationError& e) {
            result.status = RunStatus::diverged;
            result.message = in_scenario_keys(e.what());
        }
        if (options_.progress) progress(start, first_step, terminal, true);
        if (sim_) wear_results_.finish(scenario_, *sim_, dir_, result.status == RunStatus::completed, result.message);
        result.time_s = world_->time_s();
        result.steps = world_->step_count();
        write_summary(result, start);
        if (!wear_results_.error().empty()) throw InputError(wear_results_.error());
        return result;
    }

private:
    /// The model the run steps; world_ and sim_ point into it.
    void adopt(std::unique_ptr<Simulation> model)
    {
        model_ = std::move(model);
        world_ = &model_->world();
        sim_ = model_->co_simulation();
    }

    /// The walls that outputs list: all of them, less the hulls of rocks.
    std::vector<int> all_walls() const
    {
        if (sim_) return sim_->listed_walls();
        std::vector<int> walls;
        for (std::size_t w = 0; w < world_->wall_count(); ++w) walls.push_back(static_cast<int>(w));
        return walls;
    }

    void open_outputs(bool resuming, std::uint64_t csv_bytes)
    {
        walls_ = all_walls();
        particles_pvd_ = std::make_unique<dem::PvdCollection>(dir_ + "/particles.pvd");
        wall_pvd_.clear();
        for (int w : walls_) {
            if (world_->is_mesh(w))
                wall_pvd_.push_back(std::make_unique<dem::PvdCollection>(dir_ + "/wall_" + world_->wall_name(w) + ".pvd"));
            else
                wall_pvd_.push_back(nullptr);
        }
        if (sim_) {
            if (!sim_->coupled().rocks().empty()) rocks_pvd_ = std::make_unique<dem::PvdCollection>(dir_ + "/rocks.pvd");
            for (const coupling::WearPart& w : sim_->wear())
                wear_pvd_.push_back(std::make_unique<dem::PvdCollection>(dir_ + "/wear_" + w.part + ".pvd"));
        }
        const std::string csv_path = dir_ + "/probes.csv";
        if (resuming) {
            std::error_code error;
            if (!fs::exists(csv_path) || fs::file_size(csv_path) < csv_bytes)
                throw InputError(concat("'", csv_path, "' is shorter than at the checkpoint; it cannot be continued"));
            fs::resize_file(csv_path, csv_bytes, error);
            if (error) throw InputError(concat("cannot trim '", csv_path, "': ", error.message()));
            csv_.open(csv_path, std::ios::app);
            if (!csv_) throw InputError(concat("cannot append to '", csv_path, "'"));
            csv_.precision(10);
            return;
        }
        csv_ = open_for_writing(csv_path);
        csv_ << "time_s,step,particles,mass_kg,kinetic_energy_J,pair_contacts,wall_contacts,max_overlap_ratio";
        for (int w : walls_)
            for (const char* axis : {"x", "y", "z"}) csv_ << ",force_" << world_->wall_name(w) << "_" << axis << "_N";
        for (const RegionProbe& r : scenario_.regions) csv_ << "," << r.name << "_mass_kg";
        if (scenario_.repose) csv_ << ",repose_angle_deg";
        if (sim_) {
            csv_ << ",rocks,rock_kinetic_energy_J,rock_contacts";
            if (sim_->has_shovel())
                csv_ << ",bucket_mass_kg,fill_factor,crowd_force_N,hoist_force_N,dig_force_N,interface_force_N,interface_force_without_lip_N,swing_deg,door_deg,"
                        "handle_angle_deg,crowd_extension_m,tooth_tip_x_m,tooth_tip_y_m,tooth_tip_z_m";
            for (const coupling::WearPart& w : sim_->wear()) csv_ << ",wear_" << w.part << "_m3";
            if (scenario_.dynamic_domain.enabled) csv_ << ",frozen_spheres,frozen_rocks";
        }
        csv_ << ",wall_s_per_step,wall_clock_s\n";
        finish_writing(csv_, csv_path);
    }

    double region_mass_kg(const RegionProbe& r) const
    {
        const dem::ParticleStore& p = world_->particles();
        double mass = 0.0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const Vec3& x = p.position_m[i];
            if (x.x >= r.min_m.x && x.x <= r.max_m.x && x.y >= r.min_m.y && x.y <= r.max_m.y && x.z >= r.min_m.z && x.z <= r.max_m.z)
                mass += p.mass_kg[i];
        }
        return mass;
    }

    /// The repose probe's fit now, from the spheres and the rocks on the pile's surface; empty while the
    /// window holds no slope to fit.
    std::optional<dem::ReposeFit> repose_fit() const
    {
        try {
            return dem::fit_repose_angle(world_->particles(), scenario_.repose->window, scenario_.repose->where,
                                         sim_ ? sim_->rock_surface_points() : std::vector<Vec3>{});
        } catch (const InputError&) {
            return std::nullopt;
        }
    }
    /// The repose probe's angle now; NaN while the window holds no slope to fit.
    double repose_angle_deg() const
    {
        const std::optional<dem::ReposeFit> fit = repose_fit();
        return fit ? fit->angle_deg : std::numeric_limits<double>::quiet_NaN();
    }

    void write_row()
    {
        const dem::World& w = *world_;
        csv_ << w.time_s() << ',' << w.step_count() << ',' << w.particles().size() << ',' << w.total_mass_kg() << ','
             << w.kinetic_energy_J() << ',' << w.pair_contact_count() << ',' << w.wall_contact_count() << ','
             << w.max_overlap_ratio();
        for (int k : walls_) {
            const Vec3 f = w.wall_force_N(k);
            csv_ << ',' << f.x << ',' << f.y << ',' << f.z;
        }
        for (const RegionProbe& r : scenario_.regions) csv_ << ',' << region_mass_kg(r);
        if (scenario_.repose) csv_ << ',' << repose_angle_deg();
        if (sim_) {
            const rigid::RigidWorld& rw = sim_->rigid();
            csv_ << ',' << sim_->coupled().rocks().size() << ',' << rw.kinetic_energy_J() << ',' << rw.contact_point_count();
            if (sim_->has_shovel()) {
                const coupling::BucketContents b = sim_->bucket();
                const rigid::ShovelReading& r = sim_->reading();
                csv_ << ',' << b.mass_kg << ',' << b.fill_factor << ',' << r.crowd_force_filtered_N << ',' << r.hoist_force_filtered_N << ','
                     << r.dig_force_filtered_N << ',' << norm(sim_->interface_force_N()) << ','
                     << norm(sim_->interface_force_N() - sim_->lip_force_N()) << ',' << r.swing_deg << ',' << r.door_deg << ',' << r.handle_angle_deg << ','
                     << r.crowd_extension_m << ',' << r.tooth_tip_m.x << ',' << r.tooth_tip_m.y << ',' << r.tooth_tip_m.z;
            }
            for (const coupling::WearPart& part : sim_->wear()) csv_ << ',' << part.surface->total_volume_m3();
            if (scenario_.dynamic_domain.enabled)
                csv_ << ',' << sim_->dynamic_domain().frozen_spheres() << ',' << sim_->dynamic_domain().frozen_rocks();
        }
        const double now = wall_seconds_now();
        const std::uint64_t steps = w.step_count() - row_step_;
        csv_ << ',' << (row_step_ != ~0ull && steps > 0 ? (now - row_wall_s_) / static_cast<double>(steps) : 0.0) << ',' << now << '\n';
        row_step_ = w.step_count();
        row_wall_s_ = now;
        finish_writing(csv_, dir_ + "/probes.csv");
        last_row_step_ = w.step_count();
    }

    void write_snapshot()
    {
        const std::string file = numbered("particles", snapshot_index_);
        dem::write_particles_vtp(*world_, dir_ + "/" + file);
        particles_pvd_->add(world_->time_s(), file);
        for (std::size_t w = 0; w < wall_pvd_.size(); ++w) {
            if (!wall_pvd_[w]) continue;
            const std::string name = "wall_" + world_->wall_name(walls_[w]);
            const std::string mesh_file = numbered(name, snapshot_index_);
            dem::write_mesh_vtp(world_->mesh_wall(walls_[w]), dir_ + "/" + mesh_file);
            wall_pvd_[w]->add(world_->time_s(), mesh_file);
        }
        if (rocks_pvd_) {
            const std::string rock_file = numbered("rocks", snapshot_index_);
            sim_->write_rocks_vtp(dir_ + "/" + rock_file);
            rocks_pvd_->add(world_->time_s(), rock_file);
        }
        if (sim_)
            for (std::size_t k = 0; k < sim_->wear().size(); ++k) {
                const coupling::WearPart& w = sim_->wear()[k];
                const std::string wear_file = numbered("wear_" + w.part, snapshot_index_);
                Mat3 r;
                Vec3 o;
                sim_->wear_pose(w, r, o);
                wear::write_wear_vtp(*w.surface, dir_ + "/" + wear_file, wear_tonnage_t(scenario_, *sim_, k),
                                     scenario_.wear[k].smoothing_iterations, r, o);
                wear_pvd_[k]->add(world_->time_s(), wear_file);
            }
        ++snapshot_index_;
    }

    double wall_seconds_now() const
    {
        return wall_seconds_before_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start_).count();
    }

    void checkpoint()
    {
        StateWriter out;
        RunHeader header{scenario_.text, scenario_.source, scenario_.base_dir, world_->threads()};
        header.fields(out);
        model_->write_state(out);
        double wall_s = wall_seconds_now();
        std::uint64_t steps = world_->step_count();
        csv_.flush();
        auto csv_bytes = static_cast<std::uint64_t>(csv_.tellp());
        SeriesEntries series;
        const auto add = [&](const dem::PvdCollection* c) { series.push_back(c ? c->entries() : SeriesEntries::value_type{}); };
        add(particles_pvd_.get());
        for (const auto& w : wall_pvd_) add(w.get());
        if (sim_) {
            add(rocks_pvd_.get());
            for (const auto& w : wear_pvd_) add(w.get());
        }
        output_fields(out, wall_s, steps, csv_bytes, series);
        // the new file first, then the old one becomes the previous: a good checkpoint always exists
        const fs::path dir(dir_);
        out.save((dir / "checkpoint.next.bin").string(), kCheckpointMagic);
        std::error_code error;
        if (fs::exists(dir / "checkpoint.bin")) fs::rename(dir / "checkpoint.bin", dir / "checkpoint.prev.bin", error);
        fs::rename(dir / "checkpoint.next.bin", dir / "checkpoint.bin", error);
        if (error) throw InputError(concat("cannot move the checkpoint into place in '", dir_, "': ", error.message()));
    }

    /// A run of more than kMaxSteps steps is a mistake in a stiffness, a radius or the step, not a job: it is
    /// refused with what sets the step, before the first one (it would run for months, the progress line's ETA
    /// the only sign).
    void require_reasonable_step_count(double span_s, double dt) const
    {
        constexpr double kMaxSteps = 1e9;
        const double steps = span_s / dt;
        if (!(steps > kMaxSteps)) return;
        std::string cause;
        if (scenario_.step_s > 0.0) {
            cause = concat("time.step_s = ", dt, " s");
        } else if (world_->step_setting_particle() < world_->particles().size()) {
            const std::size_t i = world_->step_setting_particle();
            const dem::ParticleStore& p = world_->particles();
            const dem::Material& m = world_->materials().material(p.material[i]);
            cause = concat("the default step ", dt, " s, set by particle ", p.id[i], " (radius ", p.radius_m[i], " m, material '",
                           m.name, "', ", p.mass_kg[i], " kg, stiffest contact ", world_->stiffest_contact_N_per_m(i),
                           " N/m: check its radius, the material's Young's modulus and the C_norm of its pairs)");
        } else {
            cause = concat("a step of ", dt, " s");
        }
        throw InputError(concat(scenario_.source, ": ", span_s, " s of simulated time is ", steps, " steps at ", cause,
                                "; a run takes at most ", kMaxSteps, " steps"));
    }

    void progress(std::chrono::steady_clock::time_point start, std::uint64_t first_step, bool terminal, bool last)
    {
        const auto now = std::chrono::steady_clock::now();
        const double since = std::chrono::duration<double>(now - last_progress_).count();
        const double interval = terminal ? 0.5 : scenario_.output.progress_interval_s;
        if (!last && since < interval) return;
        last_progress_ = now;
        // The rate of the last minute or so (each line's rate weighed in by the time it covers), not the average
        // since the start: a pile that settles or a dig that begins can slow a long run several times over, and
        // the ETA must follow.
        const double elapsed = std::chrono::duration<double>(now - start).count();
        const std::uint64_t step = world_->step_count();
        if (progress_step_ < first_step) progress_step_ = first_step;
        const double recent = since > 0.0 ? static_cast<double>(step - progress_step_) / since : 0.0;
        progress_rate_ = progress_rate(progress_rate_, recent, since, elapsed);
        progress_step_ = step;
        const double rate = progress_rate_;
        const double t = world_->time_s(), end = scenario_.duration_s;
        const double left_steps = std::max(0.0, (end - t) / world_->step_s());
        const double eta = rate > 0.0 ? left_steps / rate : -1.0;
        char line[256];
        std::snprintf(line, sizeof line, "t = %.4g / %.4g s (%3.0f%%)  %.0f steps/s  %.3g particle-steps/s  ETA %s", t, end,
                      100.0 * std::min(1.0, t / end), rate, rate * static_cast<double>(world_->particles().size()),
                      clock_text(eta).c_str());
        if (terminal) std::fprintf(stderr, "\r%-100s%s", line, last ? "\n" : "");
        else std::fprintf(stderr, "%s\n", line);
        std::fflush(stderr);
    }

    void write_summary(const RunResult& result, std::chrono::steady_clock::time_point start)
    {
        const dem::World& w = *world_;
        const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double steps = static_cast<double>(w.step_count() - steps_before_);
        const char* status = result.status == RunStatus::completed ? "completed"
                             : result.status == RunStatus::interrupted ? "interrupted" : "diverged";
        std::ofstream out = open_for_writing(dir_ + "/summary.json");
        out.precision(10);
        char hash[32];
        std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(particle_state_hash(w)));
        out << "{\n  \"name\": \"" << json_escape(scenario_.name) << "\",\n  \"status\": \"" << status << "\",\n"
            << "  \"message\": \"" << json_escape(result.message) << "\",\n"
            << "  \"time_s\": " << json_number(w.time_s()) << ",\n  \"duration_s\": " << scenario_.duration_s << ",\n"
            << "  \"steps\": " << w.step_count() << ",\n  \"step_s\": " << json_number(w.step_s()) << ",\n"
            << "  \"threads\": " << w.threads() << ",\n  \"particles\": " << w.particles().size() << ",\n"
            << "  \"mass_kg\": " << json_number(w.total_mass_kg()) << ",\n  \"kinetic_energy_J\": " << json_number(w.kinetic_energy_J()) << ",\n"
            << "  \"wall_forces_N\": {";
        for (std::size_t k = 0; k < walls_.size(); ++k) {
            const Vec3 f = w.wall_force_N(walls_[k]);
            out << (k ? ", " : "") << "\"" << json_escape(w.wall_name(walls_[k])) << "\": [" << json_number(f.x) << ", "
                << json_number(f.y) << ", " << json_number(f.z) << "]";
        }
        out << "},\n  \"region_mass_kg\": {";
        for (std::size_t k = 0; k < scenario_.regions.size(); ++k)
            out << (k ? ", " : "") << "\"" << json_escape(scenario_.regions[k].name) << "\": " << json_number(region_mass_kg(scenario_.regions[k]));
        out << "}";
        if (scenario_.repose) {
            // the angle and the surface it was fitted to: each bin's centre along the slope, its top, and
            // whether it lies on the slope (in the fit); null while there is no slope
            const std::optional<dem::ReposeFit> fit = repose_fit();
            out << ",\n  \"repose_angle_deg\": " << json_number(fit ? fit->angle_deg : std::numeric_limits<double>::quiet_NaN())
                << ",\n  \"repose_fit\": ";
            if (fit) {
                auto list = [&](const auto& values) {
                    out << '[';
                    for (std::size_t k = 0; k < values.size(); ++k) out << (k ? ", " : "") << json_number(static_cast<double>(values[k]));
                    out << ']';
                };
                out << "{\"slope\": " << json_number(fit->slope) << ", \"intercept_m\": " << json_number(fit->intercept_m)
                    << ", \"rms_residual_m\": " << json_number(fit->rms_residual_m) << ", \"along\": \"" << scenario_.repose->window.along
                    << "\",\n    \"bin_centre_m\": ";
                list(fit->bin_centre_m);
                out << ",\n    \"surface_m\": ";
                list(fit->surface_m);
                out << ",\n    \"fitted\": ";
                list(fit->fitted);
                out << '}';
            } else {
                out << "null";
            }
        }
        if (!scenario_.pile.empty())
            out << ",\n  \"pile\": {\"spheres\": " << pile_.spheres << ", \"rocks\": " << pile_.rocks << ", \"spheres_left_out\": "
                << pile_.spheres_left_out << ", \"rocks_left_out\": " << pile_.rocks_left_out << ", \"held\": " << held_bodies() << "}";
        out << ",\n  \"wall_clock_s\": " << wall_s << ",\n  \"steps_per_s\": " << (wall_s > 0 ? steps / wall_s : 0.0)
            << ",\n  \"particle_steps_per_s\": "
            << (wall_s > 0 ? steps * static_cast<double>(w.particles().size()) / wall_s : 0.0) << ",\n"
            << "  \"state_hash\": \"" << hash << "\"";
        {
            // where this leg's wall clock went: the DEM's phases, Bullet's steps and the coupled surfaces' moves;
            // "other" is the rest (outputs, probes, the machine's control, serial bookkeeping)
            const dem::PhaseSeconds& p = w.phase_seconds();
            const double rigid = sim_ ? sim_->coupled().rigid_seconds() - rigid_seconds_before_ : 0.0;
            const double surface = sim_ ? sim_->coupled().surface_seconds() - surface_seconds_before_ : 0.0;
            const double pairs = p.pair_forces - phases_before_.pair_forces, walls = p.wall_forces - phases_before_.wall_forces;
            const double search = p.neighbour_search - phases_before_.neighbour_search, kicks = p.integration - phases_before_.integration;
            out << ",\n  \"wall_clock_by_phase_s\": {\"sphere_pairs\": " << json_number(pairs) << ", \"walls_and_bodies\": "
                << json_number(walls) << ", \"of_it_sphere_rock\": " << json_number(p.convex_forces - phases_before_.convex_forces)
                << ", \"neighbour_search\": " << json_number(search) << ", \"integration\": " << json_number(kicks)
                << ", \"rigid_bodies\": " << json_number(rigid) << ", \"surface_motion\": " << json_number(surface)
                << ", \"other\": " << json_number(wall_s - pairs - walls - search - kicks - rigid - surface) << "}"
                << ",\n  \"neighbour_rebuilds\": " << w.rebuild_count() - rebuilds_before_;
        }
        if (sim_) write_rigid_summary(out);
        out << "\n}\n";
        finish_writing(out, dir_ + "/summary.json");
    }

    void write_rigid_summary(std::ostream& out) const
    {
        const coupling::CoSimulation& r = *sim_;
        out << ",\n  \"rocks\": " << r.coupled().rocks().size() << ",\n  \"rock_kinetic_energy_J\": " << json_number(r.rigid().kinetic_energy_J());
        out << ",\n  \"runaways_caught\": " << r.coupled().runaways_caught() << ",\n  \"guarded_coupling_steps\": "
            << r.coupled().guarded_steps();
        if (r.has_shovel()) {
            const coupling::BucketContents b = r.bucket();
            out << ",\n  \"bucket_mass_kg\": " << json_number(b.mass_kg) << ",\n  \"fill_factor\": " << json_number(b.fill_factor)
                << ",\n  \"passes\": [";
            for (std::size_t k = 0; k < r.passes().size(); ++k) {
                const coupling::PassRecord& p = r.passes()[k];
                out << (k ? "," : "") << "\n    {\"pass\": " << k + 1 << ", \"start_s\": " << json_number(p.start_s)
                    << ", \"dig_start_s\": " << json_number(p.dig_start_s) << ", \"dig_end_s\": " << json_number(p.dig_end_s) << ", \"dump_s\": " << json_number(p.dump_s)
                    << ", \"mass_kg\": " << json_number(p.mass_kg) << ", \"fill_factor\": " << json_number(p.fill_factor)
                    << ", \"mean_dig_force_N\": " << json_number(p.mean_dig_force_N)
                    << ", \"peak_dig_force_N\": " << json_number(p.peak_dig_force_N)
                    << ", \"mean_interface_force_N\": " << json_number(p.mean_interface_force_N)
                    << ", \"peak_interface_force_N\": " << json_number(p.peak_interface_force_N)
                    << ", \"mean_interface_force_without_lip_N\": " << json_number(p.mean_interface_force_without_lip_N)
                    << ", \"peak_interface_force_without_lip_N\": " << json_number(p.peak_interface_force_without_lip_N) << "}";
            }
            out << (r.passes().empty() ? "]" : "\n  ]");
        }
        out << ",\n  \"tonnage_t\": " << json_number(r.tonnage_t()) << ",\n  \"wear\": ";
        wear_results_.write_json(out, scenario_, r);
    }

    Scenario scenario_;
    std::string dir_;
    RunOptions options_;
    std::unique_ptr<Simulation> model_;
    dem::World* world_ = nullptr;             ///< model_'s DEM world
    coupling::CoSimulation* sim_ = nullptr;   ///< model_'s co-simulation: rocks, shovel and wear; null for spheres and walls only
    WearResults wear_results_;  ///< the wear surfaces' outputs at the end
    std::vector<int> walls_;             ///< the walls outputs list
    std::unique_ptr<dem::PvdCollection> particles_pvd_;
    std::vector<std::unique_ptr<dem::PvdCollection>> wall_pvd_;
    std::unique_ptr<dem::PvdCollection> rocks_pvd_;
    std::vector<std::unique_ptr<dem::PvdCollection>> wear_pvd_;
    std::ofstream csv_;
    double next_csv_s_ = 0.0, next_vtk_s_ = 0.0, next_checkpoint_s_ = 0.0;
    int snapshot_index_ = 0;
    double wall_seconds_before_ = 0.0;
    std::uint64_t steps_before_ = 0, last_row_step_ = ~0ull, row_step_ = ~0ull;
    dem::PhaseSeconds phases_before_;
    double rigid_seconds_before_ = 0.0, surface_seconds_before_ = 0.0;
    std::uint64_t rebuilds_before_ = 0;
    coupling::LoadedState pile_;  ///< what the scenario's pile placed and left out
    /// The bodies held fixed (pile_region's layer along the cuts).
    std::size_t held_bodies() const { return sim_ ? sim_->dynamic_domain().held_bodies() : 0; }
    double row_wall_s_ = 0.0;
    std::chrono::steady_clock::time_point run_start_ = std::chrono::steady_clock::now(), last_progress_;
    std::uint64_t progress_step_ = 0;  ///< the step of the last progress line
    double progress_rate_ = 0.0;       ///< steps per second of wall clock over about the last minute
};

}  // namespace

std::uint64_t particle_state_hash(const dem::World& world)
{
    const dem::ParticleStore& p = world.particles();
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return p.id[a] < p.id[b]; });
    std::uint64_t hash = kFnvOffset;
    for (std::size_t i : order) {
        hash = fnv1a(&p.id[i], sizeof p.id[i], hash);
        hash = fnv1a(&p.position_m[i], sizeof(Vec3), hash);
        hash = fnv1a(&p.velocity_m_per_s[i], sizeof(Vec3), hash);
        hash = fnv1a(&p.angular_velocity_rad_per_s[i], sizeof(Vec3), hash);
    }
    return hash;
}

RunResult run_scenario(const Scenario& scenario, const std::string& out_dir, const RunOptions& options)
{
    Run run(scenario, out_dir, options);
    run.start_fresh();
    return run.loop();
}

namespace {

/// A checkpoint opened and its run header read: the reader stands at the model's state.
struct OpenCheckpoint {
    std::unique_ptr<StateReader> in;
    Scenario scenario;
    int threads = 1;
};

OpenCheckpoint open_checkpoint(const std::string& out_dir, const std::string& checkpoint_file)
{
    const fs::path dir(out_dir);
    const std::string path = checkpoint_file.empty() ? (dir / "checkpoint.bin").string() : checkpoint_file;
    if (!checkpoint_file.empty() && fs::is_directory(checkpoint_file))
        throw InputError(concat("--from ", checkpoint_file, " is a folder; give a checkpoint file, such as ",
                                (fs::path(checkpoint_file) / "checkpoint.prev.bin").string()));
    if (!fs::exists(path)) {
        std::string hint;
        if (fs::exists(dir / "checkpoint.next.bin") || fs::exists(dir / "checkpoint.prev.bin"))
            hint = concat("; try --from ", fs::exists(dir / "checkpoint.next.bin") ? (dir / "checkpoint.next.bin").string()
                                                                                   : (dir / "checkpoint.prev.bin").string());
        throw InputError(concat("no checkpoint '", path, "' to resume from", hint));
    }
    OpenCheckpoint c;
    try {
        c.in = std::make_unique<StateReader>(path, kCheckpointMagic);
    } catch (const InputError& e) {
        const bool prev = checkpoint_file.empty() && fs::exists(dir / "checkpoint.prev.bin");
        throw InputError(concat(e.what(), prev ? concat("; the previous checkpoint is kept: dipper resume ", out_dir, " --from ",
                                                          (dir / "checkpoint.prev.bin").string())
                                               : std::string()));
    }
    StateReader& in = *c.in;
    RunHeader header;
    header.fields(in);
    c.threads = header.threads;
    if (c.threads < 1 || c.threads > 1024) in.fail(concat("a thread count of ", c.threads, "; expected 1 to 1024"));
    c.scenario = parse_scenario(header.text, header.source, header.base_dir);
    return c;
}

/// The scenario with time.duration_s moved later to `until` (YAML text of a number), for a resumed run that
/// should go on past its end; the output folder's scenario.yaml becomes the new text. Only the end moves, so the
/// run goes on bit for bit as one that had the later end from the start.
Scenario with_later_end(const Scenario& scenario, const std::string& until, const std::string& out_dir)
{
    char* end = nullptr;
    const double until_s = std::strtod(until.c_str(), &end);
    if (until.empty() || *end != '\0' || !std::isfinite(until_s))
        throw InputError(concat("--until needs a time in seconds; got '", until, "'"));
    if (!(until_s > scenario.duration_s))
        throw InputError(concat("--until ", until, " s: the run ends at time.duration_s = ", scenario.duration_s,
                                " s already; give a later time (--stop-after stops a run earlier)"));
    if (scenario.shovel && scenario.shovel->passes > 0)
        throw InputError(concat("--until ", until, " s: this run ends after its ", scenario.shovel->passes,
                                " passes (shovel.passes), not at a time"));
    const std::string text = concat("# dipper resume --until ", until, ": time.duration_s moved from ", scenario.duration_s,
                                    " s to ", until, " s (the scenario as it runs on, comments dropped)\n",
                                    with_values(scenario.text, {{"time.duration_s", until, "--until: "}}, scenario.source));
    Scenario later = parse_scenario(text, scenario.source, scenario.base_dir);
    std::ofstream copy = open_for_writing(out_dir + "/scenario.yaml");
    copy << text;
    finish_writing(copy, out_dir + "/scenario.yaml");
    return later;
}

}  // namespace

RunResult resume_run(const std::string& out_dir, const RunOptions& options, const std::string& checkpoint_file)
{
    OpenCheckpoint c = open_checkpoint(out_dir, checkpoint_file);
    RunOptions o = options;
    if (o.threads <= 0) o.threads = c.threads;  // same thread count, same bits
    if (!o.until_s.empty()) c.scenario = with_later_end(c.scenario, o.until_s, out_dir);
    Run run(std::move(c.scenario), out_dir, o);
    run.start_from(*c.in);
    return run.loop();
}

std::unique_ptr<Simulation> read_checkpoint(const std::string& out_dir, int threads, const std::string& checkpoint_file)
{
    OpenCheckpoint c = open_checkpoint(out_dir, checkpoint_file);
    return std::make_unique<Simulation>(std::move(c.scenario), threads > 0 ? threads : c.threads, *c.in);
}

double progress_rate(double previous, double recent, double since_s, double elapsed_s)
{
    if (!(previous > 0.0)) return recent;
    const double span = std::max(since_s, std::min(elapsed_s, 60.0));
    return span > 0.0 ? previous + since_s / span * (recent - previous) : previous;
}

int exit_code(const RunResult& result)
{
    switch (result.status) {
    case RunStatus::completed: return 0;
    case RunStatus::diverged: return 3;
    case RunStatus::interrupted: return 130;
    }
    return 1;
}

}  // namespace dipper::scenario
