// Scenario -> co-simulation: the settings of coupling::CoSimulation from a scenario's keys, the fills with
// rocks and the wear surfaces with their measured points and sections checked against the part.
#include "coupling/mixed_bed.h"
#include "scenario/scenario.h"
#include "wear/calibration.h"

namespace dipper::scenario {

std::unique_ptr<coupling::CoSimulation> build_co_simulation(const Scenario& s, std::unique_ptr<dem::World> dem)
{
    coupling::CoSimulationSettings settings;
    settings.coupling = s.coupling;
    settings.rock_pairs = s.rock_pairs;
    settings.dynamic_domain = s.dynamic_domain;
    for (const FillSpec& f : s.fills) settings.rocks = settings.rocks || !f.rocks.empty();
    std::unique_ptr<coupling::CoSimulation> sim;
    try {
        sim = std::make_unique<coupling::CoSimulation>(std::move(dem), settings);
    } catch (const InputError& e) {
        throw InputError(concat(s.source, ": ", e.what()));
    }
    if (!s.shovel) return sim;
    const ShovelSpec& sh = *s.shovel;
    coupling::ShovelSettings shovel;
    shovel.dipper.rake_angle_deg = sh.rake_angle_deg;
    shovel.dipper.element_size_m = sh.element_size_m;
    shovel.dipper.wear_bars = sh.wear_bars == "transverse" ? meshes::WearBars::Transverse
                              : sh.wear_bars == "diagonal" ? meshes::WearBars::Diagonal
                                                           : meshes::WearBars::None;
    if (sh.motion == "default_cycle") {
        shovel.cycle = coupling::ShovelCycle::loading;
    } else if (sh.motion == "dig_and_return") {
        shovel.cycle = coupling::ShovelCycle::dig_and_return;
        shovel.passes = sh.passes > 0 ? sh.passes : 3;
    } else {
        shovel.cycle = coupling::ShovelCycle::curves;
        shovel.curves = rigid::MotionCurves::from_csv(sh.motion);  // errors name the file and line
    }
    shovel.advance_per_pass_m = sh.advance_per_pass_m;
    shovel.dig_speed_factor = sh.dig_speed_factor;
    shovel.start_s = sh.start_s;
    shovel.position_m = sh.position_m;
    shovel.heading_deg = sh.heading_deg;
    shovel.material = sh.material;
    shovel.bulk_density_kg_per_m3 = sh.bulk_density_kg_per_m3;
    try {
        sim->add_shovel(shovel);
    } catch (const InputError& e) {
        throw InputError(concat(sh.where, ": ", e.what()));
    }
    return sim;
}

void fill_rocks(const Scenario& s, coupling::CoSimulation& sim)
{
    const dem::MaterialTable& table = sim.dem().materials();
    for (std::size_t k = 0; k < s.fills.size(); ++k) {
        const FillSpec& f = s.fills[k];
        if (f.rocks.empty()) continue;
        coupling::MixedDistribution d;
        d.spheres = f.sizes.classes[0];
        d.rocks = f.rocks;
        d.elongation_max = f.rock_elongation_max;
        d.rock_point_count = f.rock_points;
        try {
            const dem::MaterialIndex sphere = table.index_of(f.material);
            const dem::MaterialIndex rock = table.index_of("rock");
            const coupling::MixedMaterials m{sphere, rock, sim.rigid().material_index("rock"), table.material(sphere).density_kg_per_m3};
            // as a sphere fill does, the mixed fill keeps clear of the dipper and door where they stand at t = 0
            coupling::fill_mixed(sim.coupled(), f.min_m, f.max_m, d, m, f.mass_kg, s.seed * 1000003ull + k, 20000,
                                 [&sim](const Vec3& c, double r) { return sim.clear_of_machine(c, r); });
        } catch (const InputError& e) {
            throw InputError(concat(f.where, ": ", e.what()));
        }
    }
}

void add_wear(const Scenario& s, coupling::CoSimulation& sim)
{
    for (const WearSpec& spec : s.wear) {
        const std::size_t k = sim.add_wear(spec.part, wear::WearLaw::from_name(spec.law, spec.constant, spec.where));
        const meshes::TriangleMesh& mesh = sim.wear()[k].surface->mesh();
        if (!spec.measured_file.empty())
            for (const wear::MeasuredPoint& p : wear::read_measured_points(spec.measured_file)) {
                const double d = wear::locate_on_surface(mesh, p.position_m).distance_m;
                if (d > kMeasuredPointTolerance_m)
                    throw InputError(concat(p.source, ": measured point '", p.id, "' at (", p.position_m.x, ", ", p.position_m.y, ", ",
                                            p.position_m.z, ") m is ", d, " m from the surface of '", spec.part,
                                            "' (in the part's own frame); expected within ", kMeasuredPointTolerance_m, " m"));
            }
        for (const WearSectionSpec& section : spec.sections)
            for (const auto& [arc, q] : wear::section_points(section.points_m, section.spacing_m)) {
                const double d = wear::locate_on_surface(mesh, q).distance_m;
                if (d > kMeasuredPointTolerance_m)
                    throw InputError(concat(section.where, ": section '", section.name, "' passes (", q.x, ", ", q.y, ", ", q.z, ") m, ",
                                            arc, " m along it, ", d, " m from the surface of '", spec.part,
                                            "' (in the part's own frame); expected within ", kMeasuredPointTolerance_m, " m"));
            }
    }
}

double wear_tonnage_t(const Scenario& s, const coupling::CoSimulation& sim, std::size_t k)
{
    return s.wear[k].tonnage_t > 0.0 ? s.wear[k].tonnage_t : sim.tonnage_t();
}

}  // namespace dipper::scenario
