// dipper._dipper: the library as seen from Python (docs/python.md). The scenario layer's Simulation and runner
// are bound, not re-implemented: a step taken here is the command's step, bit for bit. The state is read
// through read-only NumPy views of dipper's own arrays where they are contiguous (the spheres, the wear
// surfaces) and through copies where they are not (the rocks live in Bullet).
#include "core/errors.h"
#include "scenario/run_limits.h"
#include "scenario/runner.h"
#include "scenario/scenario.h"
#include "scenario/simulation.h"
#include "scenario/sweep.h"

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Python.h>

#include <cstdio>
#include <exception>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;

namespace dipper {
namespace {

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 is three packed doubles");

/// A read-only view of `data` (rows of `columns` values of T, `row_bytes` apart); `owner` keeps it alive.
template <class T>
py::array view(const T* data, std::size_t rows, std::size_t columns, std::size_t row_bytes, py::handle owner)
{
    std::vector<py::ssize_t> shape{static_cast<py::ssize_t>(rows)}, strides{static_cast<py::ssize_t>(row_bytes)};
    if (columns > 0) {
        shape.push_back(static_cast<py::ssize_t>(columns));
        strides.push_back(static_cast<py::ssize_t>(sizeof(T)));
    }
    static const T empty{};
    py::array a(py::dtype::of<T>(), shape, strides, rows > 0 ? data : &empty, owner);
    a.attr("setflags")(py::arg("write") = false);
    return a;
}

py::array vec3_view(const std::vector<Vec3>& v, py::handle owner)
{
    return view(v.empty() ? nullptr : &v[0].x, v.size(), 3, sizeof(Vec3), owner);
}

template <class T>
py::array scalar_view(const std::vector<T>& v, py::handle owner)
{
    return view(v.data(), v.size(), 0, sizeof(T), owner);
}

py::array vec3_copy(const std::vector<Vec3>& v)
{
    py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
    auto m = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < v.size(); ++i) {
        m(static_cast<py::ssize_t>(i), 0) = v[i].x;
        m(static_cast<py::ssize_t>(i), 1) = v[i].y;
        m(static_cast<py::ssize_t>(i), 2) = v[i].z;
    }
    return std::move(a);
}

py::array mat3_copy(const Mat3& r)
{
    py::array_t<double> a({py::ssize_t{3}, py::ssize_t{3}});
    auto m = a.mutable_unchecked<2>();
    for (py::ssize_t i = 0; i < 3; ++i)
        for (py::ssize_t j = 0; j < 3; ++j) m(i, j) = r.m[i][j];
    return std::move(a);
}

std::string hex(std::uint64_t v)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(v));
    return buffer;
}

const char* status_name(scenario::RunStatus s)
{
    switch (s) {
    case scenario::RunStatus::completed: return "completed";
    case scenario::RunStatus::interrupted: return "interrupted";
    case scenario::RunStatus::diverged: return "diverged";
    }
    return "unknown";
}

std::vector<scenario::KeyValue> key_values(const std::vector<std::pair<std::string, std::string>>& values)
{
    std::vector<scenario::KeyValue> out;
    for (const auto& [key, value] : values) out.push_back({key, value, ""});
    return out;
}

/// The runner's options with a Python callable as its on_step: called with the GIL held every `every` steps;
/// an exception in it stops the run (with a checkpoint) and is raised again once the run has returned.
struct StepCallback {
    py::object callable;
    std::uint64_t every = 1;
    std::exception_ptr error;

    scenario::RunOptions options(int threads, double stop_after, bool progress)
    {
        scenario::RunOptions o;
        o.threads = threads;
        o.stop_after_s = stop_after;
        o.progress = progress;
        if (!callable.is_none())
            o.on_step = [this](double t, std::uint64_t steps) {
                if (steps % every != 0) return true;
                py::gil_scoped_acquire gil;
                try {
                    const py::object r = callable(t, steps);
                    return r.is_none() || r.cast<bool>();
                } catch (...) {
                    error = std::current_exception();
                    return false;
                }
            };
        return o;
    }
};

py::dict run_result(const scenario::RunResult& r)
{
    py::dict d;
    d["status"] = status_name(r.status);
    d["message"] = r.message;
    d["time_s"] = r.time_s;
    d["steps"] = r.steps;
    d["exit_code"] = scenario::exit_code(r);
    return d;
}

/// A run or resume with the GIL released; the callback's exception, if any, raised once it has returned.
template <class Leg>
py::dict run_leg(py::object on_step, std::uint64_t every, int threads, double stop_after, bool progress, Leg leg)
{
    StepCallback callback{std::move(on_step), every > 0 ? every : 1, nullptr};
    const scenario::RunOptions o = callback.options(threads, stop_after, progress);
    scenario::RunResult r;
    {
        py::gil_scoped_release release;
        r = leg(o);
    }
    if (callback.error) std::rethrow_exception(callback.error);
    return run_result(r);
}

/// Steps a simulation `n` times or to a time with the GIL released, looking for Ctrl-C every few steps.
template <class Done>
void step_while(scenario::Simulation& sim, Done done)
{
    py::gil_scoped_release release;
    for (std::uint64_t k = 1; !done(); ++k) {
        sim.step();
        if (k % 16 == 0) {
            py::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        }
    }
}

py::dict pass_dict(const coupling::PassRecord& p, std::size_t k)
{
    py::dict d;
    d["pass"] = k + 1;
    d["start_s"] = p.start_s;
    d["dig_start_s"] = p.dig_start_s;
    d["dig_end_s"] = p.dig_end_s;
    d["dump_s"] = p.dump_s;
    d["mass_kg"] = p.mass_kg;
    d["fill_factor"] = p.fill_factor;
    d["mean_dig_force_N"] = p.mean_dig_force_N;
    d["peak_dig_force_N"] = p.peak_dig_force_N;
    d["mean_interface_force_N"] = p.mean_interface_force_N;
    d["peak_interface_force_N"] = p.peak_interface_force_N;
    d["mean_interface_force_without_lip_N"] = p.mean_interface_force_without_lip_N;
    d["peak_interface_force_without_lip_N"] = p.peak_interface_force_without_lip_N;
    return d;
}

}  // namespace
}  // namespace dipper

PYBIND11_MODULE(_dipper, m)
{
    using namespace dipper;
    using scenario::Scenario;
    using scenario::Simulation;
    m.doc() = "dipper's C++ library (use the dipper package, not this module)";

    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    static py::exception<SimulationError> simulation_error(m, "SimulationError", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            input_error(e.what());
        } catch (const SimulationError& e) {
            simulation_error(e.what());
        }
    });

    py::class_<Scenario>(m, "Scenario")
        .def_readonly("name", &Scenario::name)
        .def_readonly("source", &Scenario::source)
        .def_readonly("text", &Scenario::text)
        .def_readonly("base_dir", &Scenario::base_dir)
        .def_readonly("seed", &Scenario::seed)
        .def_readonly("threads", &Scenario::threads)
        .def_readonly("duration_s", &Scenario::duration_s)
        .def_readonly("step_s", &Scenario::step_s)
        .def("check", [](const Scenario& s) { return scenario::check_scenario(s); });

    m.def("load_scenario",
          [](const std::string& path, const std::vector<std::pair<std::string, std::string>>& values) {
              Scenario s = scenario::load_scenario(path);
              if (values.empty()) return s;
              return scenario::parse_scenario(scenario::with_values(s.text, key_values(values), path), path, s.base_dir);
          },
          py::arg("path"), py::arg("values") = std::vector<std::pair<std::string, std::string>>{});
    m.def("parse_scenario",
          [](const std::string& text, const std::string& source, const std::string& base_dir,
             const std::vector<std::pair<std::string, std::string>>& values) {
              const std::string t = values.empty() ? text : scenario::with_values(text, key_values(values), source);
              return scenario::parse_scenario(t, source, base_dir);
          },
          py::arg("text"), py::arg("source"), py::arg("base_dir"), py::arg("values") = std::vector<std::pair<std::string, std::string>>{});

    m.def("run",
          [](const Scenario& s, const std::string& out_dir, int threads, double stop_after, py::object on_step, std::uint64_t every,
             bool progress) {
              return run_leg(std::move(on_step), every, threads, stop_after, progress,
                             [&](const scenario::RunOptions& o) { return scenario::run_scenario(s, out_dir, o); });
          },
          py::arg("scenario"), py::arg("out_dir"), py::arg("threads") = -1, py::arg("stop_after") = 0.0, py::arg("on_step") = py::none(),
          py::arg("every") = 1, py::arg("progress") = false);
    m.def("resume",
          [](const std::string& out_dir, int threads, double stop_after, py::object on_step, std::uint64_t every, bool progress,
             const std::string& checkpoint_file) {
              return run_leg(std::move(on_step), every, threads, stop_after, progress,
                             [&](const scenario::RunOptions& o) { return scenario::resume_run(out_dir, o, checkpoint_file); });
          },
          py::arg("out_dir"), py::arg("threads") = -1, py::arg("stop_after") = 0.0, py::arg("on_step") = py::none(), py::arg("every") = 1,
          py::arg("progress") = false, py::arg("checkpoint_file") = "");

    py::class_<Simulation, std::unique_ptr<Simulation>>(m, "Simulation")
        .def(py::init([](const Scenario& s, int threads) { return std::make_unique<Simulation>(s, threads); }), py::arg("scenario"),
             py::arg("threads") = 0)
        .def_static("from_checkpoint",
                    [](const std::string& out_dir, int threads, const std::string& file) { return scenario::read_checkpoint(out_dir, threads, file); },
                    py::arg("out_dir"), py::arg("threads") = 0, py::arg("checkpoint_file") = "")
        .def_property_readonly("scenario", [](const Simulation& s) { return s.scenario(); })
        .def_property_readonly("time_s", &Simulation::time_s)
        .def_property_readonly("step_count", [](const Simulation& s) { return s.world().step_count(); })
        .def_property_readonly("step_s", [](const Simulation& s) { return s.world().step_s(); })
        .def_property_readonly("threads", [](const Simulation& s) { return s.world().threads(); })
        .def("state_hash", [](const Simulation& s) { return hex(scenario::particle_state_hash(s.world())); })
        .def("step",
             [](Simulation& s, std::uint64_t n) {
                 std::uint64_t k = 0;
                 step_while(s, [&] { return k++ >= n; });
             },
             py::arg("n") = 1)
        .def("run_until", [](Simulation& s, double t) { step_while(s, [&] { return s.reached(t); }); }, py::arg("t_s"))
        .def_property_readonly("material_names",
                               [](const Simulation& s) {
                                   std::vector<std::string> names;
                                   const dem::MaterialTable& t = s.world().materials();
                                   for (std::size_t k = 0; k < t.size(); ++k) names.push_back(t.material(static_cast<dem::MaterialIndex>(k)).name);
                                   return names;
                               })
        .def("spheres",
             [](py::object self) {
                 const dem::ParticleStore& p = self.cast<const Simulation&>().world().particles();
                 py::dict d;
                 d["id"] = scalar_view(p.id, self);
                 d["position_m"] = vec3_view(p.position_m, self);
                 d["velocity_m_per_s"] = vec3_view(p.velocity_m_per_s, self);
                 d["angular_velocity_rad_per_s"] = vec3_view(p.angular_velocity_rad_per_s, self);
                 d["radius_m"] = scalar_view(p.radius_m, self);
                 d["mass_kg"] = scalar_view(p.mass_kg, self);
                 d["material"] = scalar_view(p.material, self);
                 return d;
             })
        .def("rocks",
             [](const Simulation& s) {
                 py::dict d;
                 const coupling::CoSimulation* sim = s.co_simulation();
                 const std::size_t n = sim ? sim->coupled().rocks().size() : 0;
                 std::vector<Vec3> x(n), v(n), w(n);
                 py::array_t<double> rotation({static_cast<py::ssize_t>(n), py::ssize_t{3}, py::ssize_t{3}});
                 py::array_t<double> mass(static_cast<py::ssize_t>(n)), size(static_cast<py::ssize_t>(n));
                 auto r = rotation.mutable_unchecked<3>();
                 auto mm = mass.mutable_unchecked<1>();
                 auto sz = size.mutable_unchecked<1>();
                 for (std::size_t k = 0; k < n; ++k) {
                     const coupling::RockRecord& rock = sim->coupled().rocks()[k];
                     const rigid::BodyState b = sim->rigid().state(rock.body);
                     x[k] = b.position_m;
                     v[k] = b.velocity_m_per_s;
                     w[k] = b.angular_velocity_rad_per_s;
                     const auto i = static_cast<py::ssize_t>(k);
                     for (py::ssize_t a = 0; a < 3; ++a)
                         for (py::ssize_t c = 0; c < 3; ++c) r(i, a, c) = b.rotation.m[a][c];
                     mm(i) = sim->rigid().mass_kg(rock.body);
                     sz(i) = rock.shape.equivalent_diameter_m();
                 }
                 d["position_m"] = vec3_copy(x);
                 d["rotation"] = rotation;
                 d["velocity_m_per_s"] = vec3_copy(v);
                 d["angular_velocity_rad_per_s"] = vec3_copy(w);
                 d["mass_kg"] = mass;
                 d["equivalent_diameter_m"] = size;
                 return d;
             })
        .def("machine",
             [](const Simulation& s) -> py::object {
                 const coupling::CoSimulation* sim = s.co_simulation();
                 if (!sim || !sim->has_shovel()) return py::none();
                 const rigid::ShovelReading& r = sim->reading();
                 const coupling::BucketContents b = sim->bucket();
                 py::dict d;
                 d["crowd_force_N"] = r.crowd_force_N;
                 d["hoist_force_N"] = r.hoist_force_N;
                 d["dig_force_N"] = r.dig_force_N;
                 d["crowd_force_filtered_N"] = r.crowd_force_filtered_N;
                 d["hoist_force_filtered_N"] = r.hoist_force_filtered_N;
                 d["dig_force_filtered_N"] = r.dig_force_filtered_N;
                 d["rope_tension_N"] = std::vector<double>{r.rope_tension_N[0], r.rope_tension_N[1]};
                 d["rope_length_m"] = std::vector<double>{r.rope_length_m[0], r.rope_length_m[1]};
                 d["crowd_extension_m"] = r.crowd_extension_m;
                 d["handle_angle_deg"] = r.handle_angle_deg;
                 d["swing_deg"] = r.swing_deg;
                 d["door_deg"] = r.door_deg;
                 d["rake_angle_deg"] = r.rake_angle_deg;
                 d["tooth_tip_m"] = std::vector<double>{r.tooth_tip_m.x, r.tooth_tip_m.y, r.tooth_tip_m.z};
                 d["heel_m"] = std::vector<double>{r.heel_m.x, r.heel_m.y, r.heel_m.z};
                 const Vec3 f = sim->interface_force_N(), lip = sim->lip_force_N();
                 d["interface_force_N"] = std::vector<double>{f.x, f.y, f.z};
                 d["lip_force_N"] = std::vector<double>{lip.x, lip.y, lip.z};
                 d["bucket_mass_kg"] = b.mass_kg;
                 d["fill_factor"] = b.fill_factor;
                 d["bucket_spheres"] = b.spheres;
                 d["bucket_rocks"] = b.rocks;
                 return std::move(d);
             })
        .def("passes",
             [](const Simulation& s) {
                 py::list l;
                 if (const coupling::CoSimulation* sim = s.co_simulation())
                     for (std::size_t k = 0; k < sim->passes().size(); ++k) l.append(pass_dict(sim->passes()[k], k));
                 return l;
             })
        .def("wear",
             [](py::object self) {
                 const Simulation& s = self.cast<const Simulation&>();
                 py::list l;
                 const coupling::CoSimulation* sim = s.co_simulation();
                 if (!sim) return l;
                 for (std::size_t k = 0; k < sim->wear().size(); ++k) {
                     const coupling::WearPart& w = sim->wear()[k];
                     const wear::WearSurface& surface = *w.surface;
                     const meshes::TriangleMesh& mesh = surface.mesh();
                     const int smoothing = s.scenario().wear[k].smoothing_iterations;
                     py::dict d;
                     d["part"] = w.part;
                     d["law"] = s.scenario().wear[k].law;
                     d["tonnage_t"] = scenario::wear_tonnage_t(s.scenario(), *sim, k);
                     d["vertices_m"] = vec3_view(mesh.vertices_m(), self);
                     const auto& t = mesh.triangles();
                     d["triangles"] = view(t.empty() ? nullptr : t[0].data(), t.size(), 3, sizeof t[0], self);
                     d["triangle_volume_m3"] = scalar_view(surface.triangle_volume_m3(), self);
                     d["triangle_depth_m"] = py::array(py::cast(surface.triangle_depth_m()));
                     d["node_depth_m"] = py::array(py::cast(surface.node_depth_m(smoothing)));
                     d["volume_m3"] = surface.total_volume_m3();
                     Mat3 r;
                     Vec3 o;
                     sim->wear_pose(w, r, o);
                     d["rotation"] = mat3_copy(r);
                     d["origin_m"] = std::vector<double>{o.x, o.y, o.z};
                     py::dict regions;
                     for (const auto& [name, volume] : sim->wear_by_region(w)) regions[py::str(name)] = volume;
                     d["volume_by_region_m3"] = regions;
                     const std::vector<std::string> plates = sim->plate_names(w);
                     if (!plates.empty()) {
                         d["plate_names"] = plates;
                         d["triangle_plate"] = scalar_view(sim->triangle_plates(w), self);
                     }
                     l.append(d);
                 }
                 return l;
             })
        .def("wall_forces",
             [](const Simulation& s) {
                 py::dict d;
                 const dem::World& w = s.world();
                 const coupling::CoSimulation* sim = s.co_simulation();
                 std::vector<int> walls;
                 if (sim) walls = sim->listed_walls();
                 else
                     for (std::size_t k = 0; k < w.wall_count(); ++k) walls.push_back(static_cast<int>(k));
                 for (int k : walls) {
                     const Vec3 f = w.wall_force_N(k);
                     d[py::str(w.wall_name(k))] = std::vector<double>{f.x, f.y, f.z};
                 }
                 return d;
             })
        .def("kinetic_energy_J", [](const Simulation& s) { return s.world().kinetic_energy_J(); })
        .def("total_mass_kg", [](const Simulation& s) { return s.world().total_mass_kg(); });

    m.def("particle_state_hash", [](const Simulation& s) { return hex(scenario::particle_state_hash(s.world())); });
}
